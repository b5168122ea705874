//! `[[spawn]]` regions: a rate within one particle of rate x time when there is room, a
//! count, a time window, materials and velocities, and the distributions of radii.

use crate::common;

use tinydem::engine::Simulation;

fn sim(spawn: &str, extra: &str, attempts: u32) -> Simulation {
    common::simulate(
        &format!(
            "[geometry]\nradius_min = 0.001\nradius_max = 0.002\n\
             [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
             [simulation]\ntimestep = 1e-4\nmax_particles = 100000\nspawn_attempts = {attempts}\n\
             {extra}\n{spawn}"
        ),
        0,
    )
}

#[test]
fn a_rate_is_kept_to_within_one_particle() {
    let mut s = sim(
        "[[spawn]]\nmin = [-0.5, -0.5, -0.5]\nmax = [0.5, 0.5, 0.5]\nrate = 3000.0\nstart = 0.01\n",
        "",
        50,
    );
    for step in 0..500 {
        let t = s.time;
        s.step().unwrap();
        let expected = (3000.0 * (t + 1e-4 - 0.01)).max(0.0);
        let n = s.particles.len() as f64;
        assert!(
            (n - expected).abs() <= 1.0,
            "step {step}: {n} particles, rate x time = {expected}"
        );
    }
    assert_eq!(s.spawned(), vec![s.particles.len() as u64]);
}

#[test]
fn a_count_in_a_time_window_with_its_material_and_velocity() {
    let mut s = sim(
        "[[spawn]]\nmin = [-0.5, -0.5, -0.5]\nmax = [0.5, 0.5, 0.5]\ncount = 120\nstart = 0.002\nstop = 0.004\n\
         material = \"b\"\nvelocity = [0.0, 1.0, 0.0]\n\
         [[spawn]]\nmin = [-0.5, -0.5, -0.5]\nmax = [0.5, 0.5, 0.5]\nrate = 1e4\nstop = 0.003\n",
        "[[materials]]\nname = \"a\"\n[[materials]]\nname = \"b\"\ndensity = 3000.0\n",
        50,
    );
    for _ in 0..100 {
        let t = s.time;
        let before = s.spawned();
        s.step().unwrap();
        let after = s.spawned();
        if !(0.002 - 1e-12..0.004).contains(&t) {
            assert_eq!(
                after[0], before[0],
                "region 1 outside its window at t = {t}"
            );
        }
        if t >= 0.003 {
            assert_eq!(after[1], before[1], "region 2 after its stop at t = {t}");
        }
    }
    // 50 attempts a step into an empty metre cube: the count is reached in three steps.
    assert_eq!(s.spawned(), vec![120, 30]);
    let p = &s.particles;
    for k in 0..p.len() {
        let first = p.material[k] == 1;
        assert_eq!(p.v[k].y, if first { 1.0 } else { 0.0 });
        assert!(first || p.v[k].z == -1.0, "the default velocity");
    }
}

/// Mean and standard deviation of the radii of `s`.
fn stats(s: &Simulation) -> (f64, f64, usize) {
    let r = &s.particles.radius;
    let n = r.len() as f64;
    let mean = r.iter().sum::<f64>() / n;
    let var = r.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt(), r.len())
}

fn drawn(radius: &str) -> Simulation {
    let mut s = sim(
        &format!(
            "[[spawn]]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 1.0]\ncount = 4000\nradius = {radius}\n"
        ),
        "",
        5000,
    );
    while s.particles.len() < 4000 {
        s.step().unwrap();
    }
    s
}

#[test]
fn radii_follow_their_distribution() {
    // Uniform in [1.2, 1.8] mm: mean 1.5, deviation 0.6 / sqrt(12).
    let (mean, std, n) = stats(&drawn(
        "{ distribution = \"uniform\", min = 0.0012, max = 0.0018 }",
    ));
    let sem = |std: f64| 4.0 * std / (n as f64).sqrt();
    assert!((mean - 0.0015).abs() < sem(std), "uniform mean {mean}");
    assert!(
        (std / (0.0006 / 12f64.sqrt()) - 1.0).abs() < 0.05,
        "uniform std {std}"
    );
    // Normal 1.5 +- 0.1 mm, far inside its bounds.
    let (mean, std, _) = stats(&drawn(
        "{ distribution = \"normal\", mean = 0.0015, std = 0.0001 }",
    ));
    assert!((mean - 0.0015).abs() < sem(std), "normal mean {mean}");
    assert!((std / 0.0001 - 1.0).abs() < 0.05, "normal std {std}");
    // Log-normal with mean 1.4 mm and deviation 0.1 mm.
    let s = drawn("{ distribution = \"lognormal\", mean = 0.0014, std = 0.0001 }");
    let (mean, std, _) = stats(&s);
    assert!((mean - 0.0014).abs() < sem(std), "lognormal mean {mean}");
    assert!((std / 0.0001 - 1.0).abs() < 0.05, "lognormal std {std}");
    assert!(
        s.particles
            .radius
            .iter()
            .all(|&r| (0.001..=0.002).contains(&r))
    );
    // A table: three small for each large one.
    let s = drawn("{ distribution = \"table\", radii = [0.001, 0.002], weights = [3.0, 1.0] }");
    let large = s.particles.radius.iter().filter(|&&r| r == 0.002).count() as f64;
    let share = large / 4000.0;
    assert!(
        (share - 0.25).abs() < 4.0 * (0.25f64 * 0.75 / 4000.0).sqrt(),
        "{share}"
    );
    assert!(s.particles.radius.iter().all(|&r| r == 0.001 || r == 0.002));
}

/// Whether spawning is over, for `[simulation] until`'s kinetic energy: once every region is
/// past its stop or its count, or N_max is reached; the spawn box tries until N_max.
#[test]
fn spawning_is_over_past_every_regions_stop_or_count() {
    let spawning = |s: &Simulation| s.frame_state(&s.thermo()).spawning;
    let region = "[[spawn]]\nmin = [-0.5, -0.5, -0.5]\nmax = [0.5, 0.5, 0.5]\n";
    let mut s = sim(
        &format!("{region}count = 20\n{region}rate = 1000.0\nstop = 0.005\n"),
        "",
        50,
    );
    assert!(spawning(&s));
    for _ in 0..49 {
        s.step().unwrap();
    }
    // The count is made at once; the rate's region runs until t = 0.005.
    assert_eq!(s.spawned()[0], 20);
    assert!(spawning(&s), "t = {}", s.time);
    s.step().unwrap();
    assert!(!spawning(&s), "t = {}", s.time);
    // The box spawner goes on until max_particles.
    let mut s = common::simulate(
        "[geometry]\nradius_min = 0.001\nradius_max = 0.002\nspawn_min = [-0.5, -0.5, -0.5]\n\
         spawn_max = [0.5, 0.5, 0.5]\n[simulation]\nmax_particles = 30\nspawn_attempts = 50\n",
        0,
    );
    assert!(spawning(&s));
    s.step().unwrap();
    assert_eq!(s.particles.len(), 30);
    assert!(!spawning(&s));
}

#[test]
fn a_region_that_cannot_place_its_grains_is_reported() {
    // A flat region on the floor: every try overlaps it.
    let t = tempfile::tempdir().unwrap();
    std::fs::write(
        t.path().join("s.toml"),
        "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
         [[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 1.0 }\n\
         [[clumps]]\nname = \"dimer\"\nspheres = [[-0.002, 0.0, 0.0, 0.002], [0.002, 0.0, 0.0, 0.002]]\n\
         [[spawn]]\nmin = [-0.03, -0.03, 0.0]\nmax = [0.03, 0.03, 0.0]\nclump = \"dimer\"\ncount = 10\n\
         [[spawn]]\nmin = [-0.03, -0.03, 0.05]\nmax = [0.03, 0.03, 0.06]\ncount = 5\n\
         [simulation]\nframes = 2\nsteps_per_frame = 50\n",
    )
    .unwrap();
    for quiet in [true, false] {
        let mut args = vec!["run", "s.toml", "--overwrite"];
        if quiet {
            args.push("-q");
        }
        let o = common::tinydem(&args, t.path());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(
            err.contains("warning: [[spawn]] #1 made 0 of 10 clumps: its tries overlapped a wall"),
            "{err}"
        );
        // The second region made its five.
        assert!(!err.contains("[[spawn]] #2"), "{err}");
    }
    // max_particles stops a region short: said so.
    let mut sim = common::simulate(
        "[geometry]\nradius_min = 0.001\nradius_max = 0.002\n\
         [simulation]\nmax_particles = 20\n\
         [[spawn]]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.05]\ncount = 50\n",
        0,
    );
    for _ in 0..10 {
        sim.step().unwrap();
    }
    assert_eq!(
        sim.spawn_shortfalls(),
        vec!["[[spawn]] #1 made 20 of 50 particles: [simulation] max_particles = 20 was reached"]
    );
}

#[test]
fn a_volume_fraction_fills_its_box_with_that_share_of_grains() {
    // As LIGGGHTS's insert/pack with volumefraction_region: uniform radii in [2, 3] mm,
    // E[R^3] = (3^4 - 2^4) / 4 mm^3, in a 5 cm box to 0.2 of its volume: 367 grains.
    let text = "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
                [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
                [simulation]\nmax_particles = 100000\nspawn_attempts = 1000\n\
                [[spawn]]\nmin = [0.0, 0.0, 0.0]\nmax = [0.05, 0.05, 0.05]\nvolume_fraction = 0.2\n";
    let mut s = common::simulate(text, 0);
    assert_eq!(s.scenario.spawn[0].count, Some(367));
    for _ in 0..20 {
        s.step().unwrap();
    }
    let p = &s.particles;
    assert_eq!(p.len(), 367);
    let solid: f64 = p
        .radius
        .iter()
        .map(|r| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
        .sum();
    let fraction = solid / 0.05f64.powi(3);
    assert!((fraction - 0.2).abs() < 0.01, "{fraction}");
    // Of clumps: the template's volume (mass over density) times the mean cube of the scale.
    let dimers = "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
                  [[clumps]]\nname = \"dimer\"\nspheres = [[-0.002, 0.0, 0.0, 0.002], [0.002, 0.0, 0.0, 0.002]]\n\
                  [[spawn]]\nmin = [0.0, 0.0, 0.0]\nmax = [0.05, 0.05, 0.05]\nclump = \"dimer\"\nvolume_fraction = 0.1\n";
    let s = common::simulate(dimers, 0);
    let t = &s.scenario.clumps[0];
    let expected = 0.1 * 0.05f64.powi(3) / (t.mass / 1000.0);
    assert_eq!(s.scenario.spawn[0].count, Some(expected.round() as u64));
}
