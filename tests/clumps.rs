//! Clumps of rigidly joined spheres (issue 28) in the step: a dumbbell at rest on a plane
//! and on an incline, collisions that conserve momentum and angular momentum, a clump of
//! one sphere as that sphere, bodies removed whole, checkpoints and thread counts.

use crate::common;

use glam::{DQuat, DVec3};
use tinydem::engine::records::Partner;
use tinydem::engine::{Overlap, Simulation};
use tinydem::model::particles::Particles;
use tinydem::scenario::Scenario;

const R: f64 = 0.005;
const G: f64 = 9.81;
/// The dumbbell: two spheres of radius R, 1.4 R apart (along the body's x axis).
const DIMER: &str =
    "[[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, 0.005], [0.007, 0.0, 0.0, 0.005]]\n";

/// A scenario without spawning, gravity `g`, friction `mu`, with `extra` TOML lines.
fn text(g: DVec3, mu: f64, extra: &str) -> String {
    format!(
        "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
         [material]\ndensity = 1000.0\nyoungs_modulus = 1e6\npoisson_ratio = 0.3\n\
         restitution = 0.3\nfriction_sliding = {mu}\nfriction_rolling = 0.0\n\
         [kinetics]\ngravity = [{}, {}, {}]\n\
         [simulation]\nmax_particles = 0\nspawn_attempts = 0\n{DIMER}{extra}",
        g.x, g.y, g.z
    )
}

fn sim(text: &str) -> Simulation {
    Simulation::new(common::scenario(text)).unwrap()
}

fn run_for(s: &mut Simulation, seconds: f64) {
    let steps = (seconds / s.scenario.simulation.timestep) as u64;
    for _ in 0..steps {
        s.step().unwrap();
    }
}

const PLANE: &str = "[[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 1.0 }\n";

#[test]
fn a_dumbbell_dropped_flat_rests_on_both_spheres_each_carrying_half_its_weight() {
    let mut s = sim(&text(DVec3::new(0.0, 0.0, -G), 0.5, PLANE));
    let motion = (
        DVec3::new(0.0, 0.0, R + 0.002),
        DQuat::IDENTITY,
        DVec3::ZERO,
        DVec3::ZERO,
    );
    let id = s.add_clump(0, 1.0, motion, Overlap::Refused).unwrap();
    assert_eq!(id, 0);
    assert_eq!(s.particles.len(), 2);
    run_for(&mut s, 0.5);
    let body = &s.particles.bodies.list[0];
    assert!(
        body.v.length() < 1e-6 && body.w.length() < 1e-4,
        "still moving: {} {}",
        body.v,
        body.w
    );
    let weight = body.mass * G;
    let contacts = s.contact_network();
    assert_eq!(contacts.len(), 2, "{contacts:?}");
    for c in &contacts {
        assert!(matches!(c.with, Partner::Face(_)));
        let share = c.f_n.z / weight;
        assert!(
            (share - 0.5).abs() < 1e-3,
            "sphere {} carries {share} of the weight",
            c.id
        );
    }
    // Flat: both spheres at the same height, the body's axis horizontal.
    let (a, b) = (s.particles.x[0], s.particles.x[1]);
    assert!((a.z - b.z).abs() < 1e-9, "{a} {b}");
    // The body's mass is that of the union (overlaps once), less than two spheres'.
    let sphere = 4.0 / 3.0 * std::f64::consts::PI * R.powi(3) * 1000.0;
    let lens = std::f64::consts::PI / 12.0 * (4.0 * R + 0.007) * (2.0 * R - 0.007).powi(2);
    let union = 2.0 * sphere - 1000.0 * lens;
    assert!(
        (body.mass / union - 1.0).abs() < 1e-3,
        "{} vs {union}",
        body.mass
    );
}

/// A dumbbell lying along the slope of a plane inclined by `angle` under friction 0.5
/// (friction angle 26.6 deg): how far it slid in 0.3 s.
fn slide_on_incline(angle: f64) -> f64 {
    let g = DVec3::new(G * angle.sin(), 0.0, -G * angle.cos());
    let mut s = sim(&text(g, 0.5, PLANE));
    let motion = (
        DVec3::new(0.0, 0.0, R),
        DQuat::IDENTITY,
        DVec3::ZERO,
        DVec3::ZERO,
    );
    s.add_clump(0, 1.0, motion, Overlap::Refused).unwrap();
    run_for(&mut s, 0.05); // settle
    let start = s.particles.bodies.list[0].x;
    run_for(&mut s, 0.3);
    (s.particles.bodies.list[0].x - start).x
}

#[test]
fn a_dumbbell_on_an_incline_stays_below_the_friction_angle_and_slides_above() {
    let below = slide_on_incline(20f64.to_radians());
    assert!(below.abs() < 1e-5, "slid {below} m at 20 deg");
    let above = slide_on_incline(35f64.to_radians());
    // Sliding from the start at g (sin - mu cos) = 1.61 m/s^2: from t = 0.05 to 0.35 s.
    let a = G * (35f64.to_radians().sin() - 0.5 * 35f64.to_radians().cos());
    let expected = 0.5 * a * (0.35f64.powi(2) - 0.05f64.powi(2));
    assert!(
        (above / expected - 1.0).abs() < 0.05,
        "slid {above} m at 35 deg, expected {expected}"
    );
}

/// Total momentum and angular momentum about the origin of the bodies.
fn momenta(p: &Particles) -> (DVec3, DVec3) {
    p.bodies
        .list
        .iter()
        .fold((DVec3::ZERO, DVec3::ZERO), |(m, l), b| {
            let spin = b.q * (b.inertia * (b.q.inverse() * b.w));
            (m + b.mass * b.v, l + b.x.cross(b.mass * b.v) + spin)
        })
}

#[test]
fn clump_collisions_conserve_momentum_and_angular_momentum() {
    let extra = "[[clumps]]\nname = \"tri\"\nspheres = [[0.0, 0.0, 0.0, 0.005], [0.008, 0.0, 0.0, 0.005], [0.004, 0.0069282, 0.0, 0.005]]\n";
    let mut s = sim(&text(DVec3::ZERO, 0.5, extra));
    let turn = |a: f64| DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), a);
    let bodies = [
        (
            0,
            DVec3::new(0.0, 0.0, 0.0),
            turn(0.3),
            DVec3::new(0.5, 0.1, 0.0),
            DVec3::new(0.0, 20.0, 5.0),
        ),
        (
            1,
            DVec3::new(0.03, 0.004, 0.002),
            turn(1.3),
            DVec3::new(-0.5, 0.0, 0.05),
            DVec3::new(10.0, 0.0, -8.0),
        ),
        (
            0,
            DVec3::new(0.015, -0.03, 0.001),
            turn(2.3),
            DVec3::new(0.0, 0.6, 0.0),
            DVec3::new(-5.0, 3.0, 30.0),
        ),
    ];
    for (t, x, q, v, w) in bodies {
        s.add_clump(t, 1.0, (x, q, v, w), Overlap::Refused).unwrap();
    }
    let (m0, l0) = momenta(&s.particles);
    let mut touched = 0;
    for _ in 0..4000 {
        s.step().unwrap();
        touched = touched.max(s.contact_count());
    }
    assert!(touched > 0, "the clumps never met");
    let (m1, l1) = momenta(&s.particles);
    assert!(
        (m1 - m0).length() <= 1e-12 * m0.length(),
        "momentum {m0} -> {m1}"
    );
    assert!(
        (l1 - l0).length() <= 1e-12 * l0.length(),
        "angular momentum {l0} -> {l1}"
    );
}

#[test]
fn a_clump_of_one_sphere_moves_as_that_sphere_bit_for_bit() {
    let one = "[[clumps]]\nname = \"one\"\nspheres = [[0.001, 0.0, 0.0, 0.005]]\n";
    let run = |clump: bool| {
        let mut s = sim(&text(
            DVec3::new(1.0, 0.0, -G),
            0.5,
            &format!("{PLANE}{one}"),
        ));
        let (x, v, w) = (
            DVec3::new(0.0, 0.0, 0.008),
            DVec3::new(0.2, 0.0, 0.0),
            DVec3::new(0.0, 30.0, 0.0),
        );
        if clump {
            s.add_clump(1, 1.0, (x, DQuat::IDENTITY, v, w), Overlap::Refused)
                .unwrap();
        } else {
            s.add_particles(&[common::sphere(R, x, v, w)], Overlap::Refused)
                .unwrap();
        }
        run_for(&mut s, 0.2);
        s.particles
    };
    let (clump, sphere) = (run(true), run(false));
    assert!(clump.bodies.is_empty());
    assert_eq!(clump, sphere);
}

/// A box with 60 dimers and 40 triangles poured in, 1,500 steps.
const POUR: &str = "[geometry]\nradius_min = 0.004\nradius_max = 0.006\n\
[simulation]\nmax_particles = 1000\nframes = 3\nsteps_per_frame = 500\n\
[output]\ncheckpoint_every = 1\n\
[[meshes]]\nshape = { type = \"box\", min = [-0.03, -0.03, 0.0], max = [0.03, 0.03, 0.2], open = [\"+z\"] }\n\
[[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.005], normal = [1.0, 0.0, 1.0], size = 0.02 }\n\
[[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, 0.005], [0.007, 0.0, 0.0, 0.005]]\n\
[[clumps]]\nname = \"tri\"\nspheres = [[0.0, 0.0, 0.0, 0.005], [0.008, 0.0, 0.0, 0.005], [0.004, 0.0069282, 0.0, 0.005]]\n\
[[spawn]]\nmin = [-0.02, -0.02, 0.02]\nmax = [0.02, 0.02, 0.15]\nclump = \"dimer\"\nscale = { min = 0.9, max = 1.1 }\ncount = 60\n\
[[spawn]]\nmin = [-0.02, -0.02, 0.02]\nmax = [0.02, 0.02, 0.15]\nclump = \"tri\"\ncount = 40\n\
[[spawn]]\nmin = [-0.02, -0.02, 0.02]\nmax = [0.02, 0.02, 0.15]\ncount = 30\n";

fn frames(dir: &std::path::Path) -> Vec<Vec<u8>> {
    (0..=3)
        .map(|k| std::fs::read(dir.join(format!("output/particles{k:06}.csv"))).unwrap())
        .collect()
}

#[test]
fn clump_runs_give_the_same_frames_on_one_and_two_threads() {
    let t = tempfile::tempdir().unwrap();
    std::fs::write(t.path().join("pour.toml"), POUR).unwrap();
    let mut runs = Vec::new();
    for threads in ["1", "2"] {
        let out = common::tinydem(
            &["run", "pour.toml", "--threads", threads, "--overwrite"],
            t.path(),
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        runs.push(frames(t.path()));
    }
    assert_eq!(runs[0], runs[1]);
    let last = String::from_utf8(runs[0][3].clone()).unwrap();
    let rows: Vec<&str> = last.lines().collect();
    assert!(rows[0].ends_with(",id,material,clump"), "{}", rows[0]);
    let clumps: Vec<i64> = rows[1..]
        .iter()
        .map(|r| r.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(clumps.iter().filter(|&&c| c == 0).count(), 60);
    assert_eq!(clumps.iter().filter(|&&c| c == 1).count(), 40);
    assert_eq!(clumps.iter().filter(|&&c| c == -1).count(), 30);
    // analyze fits piles of clumps on their spheres (reads run.toml's templates).
    let out = common::tinydem(&["analyze", "output", "--repose"], t.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A frame read back as the input of a run is its first frame, to the byte.
    std::fs::write(t.path().join("last.csv"), &runs[0][3]).unwrap();
    let cut = POUR.find("[[spawn]]").unwrap();
    let again = POUR[..cut]
        .replace("max_particles = 1000", "max_particles = 0")
        .replace("[output]\n", "[output]\ndir = \"again\"\n")
        + "[input]\nparticles = \"last.csv\"\n";
    std::fs::write(t.path().join("again.toml"), again).unwrap();
    let out = common::tinydem(&["run", "again.toml"], t.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let first = std::fs::read(t.path().join("again/particles000000.csv")).unwrap();
    assert_eq!(String::from_utf8(first).unwrap(), last);
}

#[test]
fn a_snapshot_of_clumps_resumes_bit_for_bit() {
    let mut a = Simulation::new(common::scenario(POUR)).unwrap();
    for _ in 0..700 {
        a.step().unwrap();
    }
    let bytes = tinydem::engine::records::encode(&a.snapshot().unwrap(), 7);
    let snapshot = tinydem::engine::records::decode(&bytes, Some(7)).unwrap();
    assert_eq!(snapshot.particles, a.particles);
    let mut b = Simulation::restore(common::scenario(POUR), snapshot).unwrap();
    for _ in 0..500 {
        a.step().unwrap();
        b.step().unwrap();
    }
    assert!(a.particles.bodies.len() == 100);
    assert_eq!(a.particles, b.particles);
}

#[test]
fn a_clump_whose_centre_enters_an_outlet_is_removed_whole() {
    let outlet = "[[outlets]]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, -0.02]\n";
    let mut s = sim(&text(DVec3::new(0.0, 0.0, -G), 0.5, outlet));
    let down = DVec3::new(0.0, 0.0, -1.0);
    s.add_clump(
        0,
        1.0,
        (DVec3::ZERO, DQuat::from_rotation_y(1.2), down, DVec3::ZERO),
        Overlap::Refused,
    )
    .unwrap();
    s.add_particles(
        &[common::sphere(
            R,
            DVec3::new(0.1, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::ZERO,
        )],
        Overlap::Refused,
    )
    .unwrap();
    let mass = s.particles.bodies.list[0].mass;
    run_for(&mut s, 0.05);
    assert_eq!(s.particles.len(), 1);
    assert!(s.particles.bodies.is_empty());
    assert_eq!(s.removed.count(), 1);
    assert_eq!(s.removed.outlets[0].mass, mass);
    assert_eq!(s.thermo().particles, 1);
}

#[test]
fn clumps_meeting_across_a_periodic_side_keep_their_shape_and_momenta() {
    let domain = "[domain]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.05]\nperiodic = [true, false, false]\n";
    let mut s = sim(&text(DVec3::ZERO, 0.5, domain));
    let tilt = DQuat::from_rotation_z(0.7);
    let (v, w) = (DVec3::new(0.8, 0.0, 0.0), DVec3::new(0.0, 5.0, -3.0));
    s.add_clump(
        0,
        1.0,
        (DVec3::new(0.03, 0.0, 0.0), tilt, v, w),
        Overlap::Refused,
    )
    .unwrap();
    s.add_clump(
        0,
        1.0,
        (DVec3::new(-0.035, 0.002, 0.0), tilt.inverse(), -v, -w),
        Overlap::Refused,
    )
    .unwrap();
    let (m0, l0) = momenta(&s.particles);
    let mut touched = 0;
    for _ in 0..3000 {
        s.step().unwrap();
        touched = touched.max(s.contact_count());
    }
    assert!(touched > 0, "the clumps never met across the side");
    let p = &s.particles;
    // Each sphere is where its body puts it, up to a whole period along x.
    for (b, body) in p.bodies.list.iter().enumerate() {
        for (k, &i) in p.bodies.members(b).iter().enumerate() {
            let d = p.x[i as usize] - body.sphere_state(k).0;
            let periods = d.x / 0.1;
            assert!(
                (periods - periods.round()).abs() < 1e-9 && d.y == 0.0 && d.z == 0.0,
                "{d}"
            );
        }
    }
    // Momentum is kept; angular momentum about the origin is not defined across the side,
    // but the spin and the momentum along y and z are what they were at the start.
    let (m1, _) = momenta(p);
    assert!(
        (m1 - m0).length() <= 1e-12 * v.length() * p.bodies.list[0].mass,
        "{m0} -> {m1}"
    );
    let _ = l0;
    // Frames put the bodies' centres back into the box.
    let out = s.particles_in_domain();
    assert!(
        out.bodies
            .list
            .iter()
            .all(|b| b.x.x >= -0.05 && b.x.x < 0.05)
    );
}

/// Every reference case with its particles read as clumps of one sphere (a `clump` column
/// of 0 and a one-sphere template): the same particles, bit for bit, after every step of
/// the case.
#[test]
fn the_reference_cases_with_one_sphere_clumps_give_the_same_bits() {
    let t = tempfile::tempdir().unwrap();
    let root = common::data("reference");
    let mut cases = 0;
    for entry in std::fs::read_dir(&root).unwrap() {
        let dir = entry.unwrap().path();
        let Ok(text) = std::fs::read_to_string(dir.join("scenario.toml")) else {
            continue;
        };
        let plain = common::scenario_at(&text, &dir.join("scenario.toml"));
        let Some(input) = plain.particles.clone() else {
            continue;
        };
        let rows: Vec<String> = std::fs::read_to_string(&input)
            .unwrap()
            .lines()
            .map(String::from)
            .collect();
        let csv = t.path().join(format!(
            "{}.csv",
            dir.file_name().unwrap().to_string_lossy()
        ));
        let mut clumped_rows = vec![format!("{},clump", rows[0])];
        clumped_rows.extend(
            rows[1..]
                .iter()
                .filter(|r| !r.trim().is_empty())
                .map(|r| format!("{r},0")),
        );
        std::fs::write(&csv, clumped_rows.join("\n") + "\n").unwrap();
        let r = plain.geometry.radius_min;
        let clumped =
            format!("{text}\n[[clumps]]\nname = \"one\"\nspheres = [[0.0, 0.0, 0.0, {r}]]\n")
                .replace(
                    &format!(
                        "particles = \"{}\"",
                        input.file_name().unwrap().to_string_lossy()
                    ),
                    &format!("particles = {:?}", csv.display().to_string()),
                );
        let clumped = common::scenario_at(&clumped, &dir.join("scenario.toml"));
        assert_eq!(clumped.particles.as_deref(), Some(csv.as_path()));
        let steps = plain.simulation.frames * plain.simulation.steps_per_frame;
        let (mut a, mut b) = (
            Simulation::new(plain).unwrap(),
            Simulation::new(clumped).unwrap(),
        );
        assert_eq!(a.particles, b.particles, "{}", dir.display());
        for _ in 0..steps {
            a.step().unwrap();
            b.step().unwrap();
        }
        assert_eq!(a.particles, b.particles, "{}", dir.display());
        cases += 1;
    }
    assert!(cases >= 5, "{cases} reference cases");
}

#[test]
fn a_clump_crossing_the_sheared_side_of_a_lees_edwards_box_stays_whole() {
    let domain = "[domain]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.05]\nperiodic = [true, true, true]\n\
                  lees_edwards = { velocity = 0.5, shear_axis = \"x\", gradient_axis = \"z\" }\n";
    let mut s = sim(&text(DVec3::ZERO, 0.5, domain));
    let v = DVec3::new(0.0, 0.0, 1.0);
    let q = DQuat::from_rotation_y(0.8);
    s.add_clump(
        0,
        1.0,
        (DVec3::new(0.0, 0.0, 0.04), q, v, DVec3::new(0.0, 3.0, 0.0)),
        Overlap::Refused,
    )
    .unwrap();
    let mut straddled = false;
    for _ in 0..200 {
        s.step().unwrap();
        let p = &s.particles;
        let body = &p.bodies.list[0];
        for (k, &i) in p.bodies.members(0).iter().enumerate() {
            let (at, velocity) = body.sphere_state(k);
            let (d, dv) = (p.x[i as usize] - at, p.v[i as usize] - velocity);
            // The sphere is its place's image: n periods along z, n offsets along x (and
            // whole periods), moving n shear velocities faster along x.
            let n = (d.z / 0.1).round();
            assert!((d.z - n * 0.1).abs() < 1e-12 && d.y.abs() < 1e-12, "{d}");
            // The offset of the step's images: at its start.
            let t = s.time - s.scenario.simulation.timestep;
            let offset = (0.5 * t).rem_euclid(0.1);
            let along = (d.x - n * offset) / 0.1;
            assert!((along - along.round()).abs() < 1e-9, "{d} offset {offset}");
            assert!(
                (dv - DVec3::new(n * 0.5, 0.0, 0.0)).length() < 1e-12,
                "{dv} n {n}"
            );
            straddled |= n != 0.0;
        }
    }
    assert!(straddled, "no sphere was wrapped across the sheared side");
}

#[test]
fn a_clump_frozen_by_one_of_its_spheres_holds_still_under_a_falling_grain() {
    let mut s = sim(&text(DVec3::new(0.0, 0.0, -G), 0.5, ""));
    let q = DQuat::from_rotation_z(0.3);
    s.add_clump(
        0,
        1.0,
        (DVec3::ZERO, q, DVec3::ZERO, DVec3::ZERO),
        Overlap::Refused,
    )
    .unwrap();
    // A sphere dropped onto the clump's first sphere.
    let at = s.particles.x[0] + DVec3::new(0.0, 0.0, 3.0 * R);
    s.add_particles(
        &[common::sphere(R, at, DVec3::ZERO, DVec3::ZERO)],
        Overlap::Refused,
    )
    .unwrap();
    // Fixing its second sphere fixes the clump whole.
    s.fix_particles(&[1], true).unwrap();
    assert_eq!(s.particles.fixed, [true, true, false]);
    let by_id = |p: &Particles| p.iter_by_id().map(|e| e.1).collect::<Vec<_>>();
    let before = (s.particles.bodies.list[0].clone(), by_id(&s.particles));
    run_for(&mut s, 0.1);
    let body = &s.particles.bodies.list[0];
    assert_eq!(*body, before.0, "the fixed clump moved");
    let after = by_id(&s.particles);
    assert_eq!(after[..2], before.1[..2]);
    assert!(
        after[..2]
            .iter()
            .all(|p| p.v == DVec3::ZERO && p.w == DVec3::ZERO)
    );
    // The sphere came to rest on it.
    let z = after[2].x.z;
    assert!((z - (at.z - R)).abs() < 0.1 * R, "the sphere at {z}");
    assert!(after[2].v.length() < 1e-3);
    // Freed, it falls with the sphere on it.
    s.fix_particles(&[0], false).unwrap();
    run_for(&mut s, 0.05);
    let drop = before.0.x.z - s.particles.bodies.list[0].x.z;
    assert!(
        (drop - 0.5 * G * 0.05 * 0.05).abs() < 0.05 * drop,
        "fell {drop}"
    );
}

#[test]
fn a_fixed_box_holds_the_clumps_whose_centre_it_holds() {
    let dir = tempfile::tempdir().unwrap();
    // Two dimers of a particle file: one centred in the box, one above it; and the fixed
    // column of the frames.
    let rows = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,clump\n\
                0.0,0.0,0.0,0.0085,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,0.0,0.0,0\n\
                0.0,0.0,0.05,0.0085,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,0.0,0.0,0\n";
    std::fs::write(dir.path().join("two.csv"), rows).unwrap();
    let fixed = "[input]\nparticles = \"two.csv\"\n\
                 [[fixed]]\nmin = [-0.01, -0.01, -0.01]\nmax = [0.01, 0.01, 0.01]\n";
    let text = text(DVec3::new(0.0, 0.0, -G), 0.5, fixed);
    let scenario = common::scenario_at(&text, &dir.path().join("scenario.toml"));
    let mut s = Simulation::new(scenario).unwrap();
    assert_eq!(s.particles.fixed, [true, true, false, false]);
    let held = s.particles.bodies.list[0].clone();
    run_for(&mut s, 0.1);
    assert_eq!(s.particles.bodies.list[0], held);
    // The other fell onto it and rests there.
    let other = &s.particles.bodies.list[1];
    assert!(other.x.z < 0.04 && other.x.z > 0.005, "{}", other.x.z);
    let mut csv = Vec::new();
    tinydem::io::csv::write_particles(&mut csv, &s.particles, Default::default()).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert!(rows[0].ends_with(",fixed,clump"), "{}", rows[0]);
    assert!(
        rows[1].ends_with(",1,0") && rows[2].ends_with(",0,0"),
        "{csv}"
    );
}

#[test]
fn a_stage_keeps_the_clump_templates_of_the_run_it_continues() {
    let mut a = Simulation::new(common::scenario(POUR)).unwrap();
    for _ in 0..300 {
        a.step().unwrap();
    }
    let snapshot = a.snapshot().unwrap();
    let no_spawn = |text: &str| text[..text.find("[[spawn]]").unwrap()].to_string();
    // Another template added after the run's: carried.
    let more = no_spawn(POUR)
        + "[[clumps]]\nname = \"rod\"\nspheres = [[0.0, 0.0, 0.0, 0.005], [0.005, 0.0, 0.0, 0.005], [0.01, 0.0, 0.0, 0.005]]\n";
    let (b, _) = Simulation::stage(common::scenario(&more), snapshot.clone()).unwrap();
    assert_eq!(b.particles.bodies.len(), a.particles.bodies.len());
    // The dimer made longer, or the templates swapped: refused, naming the clump.
    let longer = no_spawn(POUR).replace("[0.007, 0.0, 0.0, 0.005]", "[0.008, 0.0, 0.0, 0.005]");
    let swapped = {
        let (dimer, tri) = (
            POUR.find("[[clumps]]\nname = \"dimer\"").unwrap(),
            POUR.find("[[clumps]]\nname = \"tri\"").unwrap(),
        );
        let end = POUR.find("[[spawn]]").unwrap();
        format!("{}{}{}", &POUR[..dimer], &POUR[tri..end], &POUR[dimer..tri])
    };
    for text in [longer, swapped] {
        let err = Simulation::stage(common::scenario(&text), snapshot.clone())
            .err()
            .expect("refused");
        let err = format!("{err:#}");
        assert!(
            err.contains("is of template 0 of the run it continues")
                && err.contains("add new ones after them"),
            "{err}"
        );
    }
}

#[test]
fn a_clump_whose_spheres_would_take_ids_past_the_largest_is_refused() {
    let t = tempfile::tempdir().unwrap();
    std::fs::write(
        t.path().join("p.csv"),
        "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,id,clump\n\
         0,0,0,0.003,0,0,0,1,0,0,0,0,0,0,4611686018427387903,0\n",
    )
    .unwrap();
    std::fs::write(
        t.path().join("s.toml"),
        "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
         [[clumps]]\nname = \"dimer\"\nspheres = [[-0.001, 0.0, 0.0, 0.002], [0.001, 0.0, 0.0, 0.002]]\n\
         [input]\nparticles = \"p.csv\"\n[simulation]\nmax_particles = 0\n",
    )
    .unwrap();
    let o = common::tinydem(&["run", "s.toml", "-q"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("p.csv"), "{err}");
    assert!(
        err.contains("row 1: the clump of id 4611686018427387903 takes the ids 4611686018427387903 to 4611686018427387904"),
        "{err}"
    );
}

#[test]
fn analyze_counts_clumps_as_their_bodies_as_the_log_does() {
    // Each frame holds a row per clump, R its bounding radius: taken as a sphere of that
    // radius, the kinetic energy came out 2.5 times the log's and the packing above 0.8.
    let t = tempfile::tempdir().unwrap();
    std::fs::write(
        t.path().join("s.toml"),
        "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
         [material]\nfriction_sliding = 0.3\nrestitution = 0.3\n\
         [[meshes]]\nshape = { type = \"box\", min = [-0.025, -0.025, 0.0], max = [0.025, 0.025, 0.2], open = [\"+z\"] }\n\
         [[clumps]]\nname = \"dimer\"\nspheres = [[-0.0012, 0.0, 0.0, 0.002], [0.0012, 0.0, 0.0, 0.002]]\n\
         [[spawn]]\nmin = [-0.022, -0.022, 0.01]\nmax = [0.022, 0.022, 0.19]\nclump = \"dimer\"\ncount = 1000\n\
         [simulation]\nmax_particles = 2000\nframes = 4\nsteps_per_frame = 2500\n",
    )
    .unwrap();
    let o = common::tinydem(&["run", "s.toml", "-o", "out", "-q"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = common::tinydem(&["analyze", "out", "--csv", "a.csv"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = |file: &str| -> Vec<Vec<String>> {
        let text = std::fs::read_to_string(t.path().join(file)).unwrap();
        text.lines()
            .map(|l| l.split(',').map(String::from).collect())
            .collect()
    };
    let (analyzed, log) = (table("a.csv"), table("out/log.csv"));
    let at = |rows: &[Vec<String>], name: &str| rows[0].iter().position(|h| h == name).unwrap();
    for frame in 1..=4 {
        let (a, l) = (&analyzed[frame + 1], &log[frame + 1]);
        assert_eq!(a[at(&analyzed, "particles")], l[at(&log, "particles")]);
        let ke = |row: &[String], c: usize| row[c].parse::<f64>().unwrap();
        let (ka, kl) = (
            ke(a, at(&analyzed, "kinetic_energy")),
            ke(l, at(&log, "kinetic_energy")),
        );
        assert!(
            (ka / kl - 1.0).abs() < 1e-5,
            "frame {frame}: {ka} against the log's {kl}"
        );
    }
    // The packing fraction against a count: the clumps' volumes (mass over density) whose
    // centres lie in a box clear of the walls, the floor and the surface by two lengths
    // of a dimer, over the box's volume (measured: 0.578 against 0.605).
    let last = &analyzed[5];
    let phi: f64 = last[at(&analyzed, "packing_fraction")].parse().unwrap();
    let frame = std::fs::read_to_string(t.path().join("out/particles000004.csv")).unwrap();
    let centres: Vec<[f64; 3]> = (frame.lines().skip(1))
        .map(|l| {
            let v: Vec<f64> = l.split(',').take(3).map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let surface = centres.iter().map(|c| c[2]).fold(0.0, f64::max);
    let (side, lo, hi) = (0.025 - 0.0128, 0.0128, surface - 0.0128);
    assert!(hi > lo + 0.01, "the bed is {surface} m deep");
    let volume = Scenario::load(&t.path().join("out/run.toml"))
        .unwrap()
        .clumps[0]
        .mass
        / 1000.0;
    let counted = (centres.iter())
        .filter(|c| c[0].abs() < side && c[1].abs() < side && (lo..hi).contains(&c[2]))
        .count() as f64
        * volume;
    let expected = counted / (4.0 * side * side * (hi - lo));
    assert!(
        (phi - expected).abs() < 0.06,
        "packing fraction {phi}, counted {expected}"
    );
    let z: f64 = last[at(&analyzed, "coordination")].parse().unwrap();
    assert!((2.0..8.0).contains(&z), "coordination {z}");
}
