//! Heat transfer against theory: two grains relaxing to their mean temperature, a chain of
//! grains between a hot and a cold wall, the heat content of a flowing bed kept to the bit,
//! and the same bits on any number of threads.

use crate::common;

use std::f64::consts::PI;

use glam::DVec3;
use tinydem::engine::Simulation;
use tinydem::io::inputs;
use tinydem::model::particles::{Particle, Particles};

/// A simulation of `particles` (at their temperatures) in the scenario `text`.
fn simulation(text: &str, particles: Vec<Particle>) -> Simulation {
    let s = common::scenario(text);
    let mut input = inputs::read(&s).unwrap();
    let mut p = Particles::default();
    p.activate("T");
    particles.into_iter().for_each(|q| p.push(q));
    input.particles = p;
    Simulation::from_inputs(s, input).unwrap()
}

/// A fixed grain of material `material`, radius `r`, at `x`, at temperature `t`.
fn grain(material: u16, r: f64, x: f64, t: f64) -> Particle {
    Particle {
        material,
        fixed: true,
        temperature: t,
        ..common::sphere(r, DVec3::X * x, DVec3::ZERO, DVec3::ZERO)
    }
}

/// m c of a grain of radius `r`, density `rho`, capacity `c`.
fn mc(r: f64, rho: f64, c: f64) -> f64 {
    4.0 / 3.0 * PI * r.powi(3) * rho * c
}

/// H = 2 k_eff sqrt(R* δ) (Batchelor & O'Brien).
fn conductance(k1: f64, k2: f64, r_star: f64, delta: f64) -> f64 {
    2.0 * (2.0 * k1 * k2 / (k1 + k2)) * (r_star * delta).sqrt()
}

const TWO: &str = "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
    [[materials]]\nname = \"glass\"\ndensity = 2500.0\nthermal_conductivity = 2.0\nheat_capacity = 800.0\n\
    [[materials]]\nname = \"resin\"\ndensity = 1500.0\nthermal_conductivity = 0.5\nheat_capacity = 1200.0\n\
    [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
    [simulation]\ntimestep = 1e-5\nthermal_time_scale = 1e4\nmax_particles = 0\n";

#[test]
fn two_grains_relax_to_their_mean_temperature_at_the_rate_of_their_conductance() {
    let (r1, r2, delta) = (0.005, 0.004, 2e-5);
    let mut sim = simulation(
        TWO,
        vec![
            grain(0, r1, 0.0, 400.0),
            grain(1, r2, r1 + r2 - delta, 300.0),
        ],
    );
    let (c1, c2) = (mc(r1, 2500.0, 800.0), mc(r2, 1500.0, 1200.0));
    let h = conductance(2.0, 0.5, r1 * r2 / (r1 + r2), delta);
    let rate = h * (1.0 / c1 + 1.0 / c2);
    let dt = 1e-5 * 1e4;
    let (start, _) = sim.heat_content();
    let mean = (c1 * 400.0 + c2 * 300.0) / (c1 + c2);
    let steps = 4000;
    for _ in 0..steps {
        sim.step().unwrap();
        assert_eq!(
            sim.heat_content().0,
            start,
            "conduction keeps the content to the bit"
        );
    }
    let t = |k: u64| {
        let p = &sim.particles;
        p.temperature[p.id_order()[k as usize]]
    };
    let difference = t(0) - t(1);
    let measured = (100.0 / difference).ln() / (steps as f64 * dt);
    assert!(
        (measured / rate - 1.0).abs() < 0.005,
        "rate {measured} against {rate} (1/s)"
    );
    let now = (c1 * t(0) + c2 * t(1)) / (c1 + c2);
    assert!(
        (now - mean).abs() < 1e-9 * mean,
        "mean {now} against {mean}"
    );
}

/// N fixed grains in a row along x between a plane held at `hot` (x = 0) and one held at
/// `cold`, overlapping each other by `delta` and the planes by `delta_w`.
fn chain(n: usize, delta: f64, delta_w: f64, scale: f64) -> (Simulation, Vec<f64>) {
    let r = 0.005;
    let pitch = 2.0 * r - delta;
    let x: Vec<f64> = (0..n).map(|k| r - delta_w + k as f64 * pitch).collect();
    let end = x[n - 1] + r - delta_w;
    let plane = |at: f64, nx: f64, t: f64| {
        format!(
            "[[meshes]]\nshape = {{ type = \"plane\", point = [{at}, 0.0, 0.0], normal = [{nx}, 0.0, 0.0], size = 0.05 }}\nmaterial = \"copper\"\ntemperature = {t}\n"
        )
    };
    let text = format!(
        "[geometry]\nradius_min = {r}\nradius_max = {r}\n\
         [[materials]]\nname = \"grain\"\ndensity = 2500.0\nthermal_conductivity = 1.0\nheat_capacity = 800.0\ninitial_temperature = 300.0\n\
         [[materials]]\nname = \"copper\"\nthermal_conductivity = 400.0\n\
         {}{}\
         [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\ntimestep = 1e-6\nthermal_time_scale = {scale}\nmax_particles = 0\n",
        plane(0.0, 1.0, 400.0),
        plane(end, -1.0, 300.0),
    );
    let grains = x.iter().map(|&x| grain(0, r, x, 300.0)).collect();
    (simulation(&text, grains), x)
}

#[test]
fn a_chain_between_a_hot_and_a_cold_wall_carries_the_flux_of_its_resistances_in_series() {
    let (n, delta, delta_w, r) = (5, 2e-5, 1e-5, 0.005);
    let h_pair = conductance(1.0, 1.0, r / 2.0, delta);
    let h_wall = conductance(1.0, 400.0, r, delta_w);
    let resistance = 2.0 / h_wall + (n - 1) as f64 / h_pair;
    let flux = 100.0 / resistance;
    // Thermal step: a tenth of the fastest grain's m c / ΣH.
    let tau = mc(r, 2500.0, 800.0) / (h_wall + h_pair);
    let dt = 0.1 * tau;
    let (mut sim, _) = chain(n, delta, delta_w, dt / 1e-6);
    // Steady after some tens of the chain's time constants (n² m c / H).
    let settle = (40.0 * (n * n) as f64 * mc(r, 2500.0, 800.0) / h_pair / dt) as usize;
    for _ in 0..settle {
        sim.step().unwrap();
    }
    sim.take_wall_heat();
    let steps = 100;
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let heat = sim.take_wall_heat();
    let watts: Vec<f64> = heat.iter().map(|q| q / (steps as f64 * dt)).collect();
    // Files: the main mesh (none), the hot plane (heat leaves it), the cold one.
    assert_eq!(watts[0], 0.0);
    assert!(
        (-watts[1] / flux - 1.0).abs() < 0.005,
        "{watts:?} against {flux} W"
    );
    assert!(
        (watts[2] / flux - 1.0).abs() < 0.005,
        "{watts:?} against {flux} W"
    );
    // The temperatures fall linearly in the resistance met from the hot wall.
    let p = &sim.particles;
    for (k, i) in p.id_order().into_iter().enumerate() {
        let met = 1.0 / h_wall + k as f64 / h_pair;
        let expected = 400.0 - flux * met;
        let t = p.temperature[i];
        assert!(
            (t - expected).abs() < 0.005 * 100.0,
            "grain {k}: {t} K against {expected} K"
        );
    }
}

/// A bed poured into a box from two regions at different temperatures.
const BED: &str = "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
    [[materials]]\nname = \"grain\"\ndensity = 2500.0\nyoungs_modulus = 1e7\n\
    thermal_conductivity = 5.0\nheat_capacity = 800.0\ninitial_temperature = 300.0\n\
    [[meshes]]\nshape = { type = \"box\", min = [-0.02, -0.02, 0.0], max = [0.02, 0.02, 0.1], open = [\"+z\"] }\n\
    [[spawn]]\nmin = [-0.018, -0.018, 0.01]\nmax = [0.0, 0.018, 0.06]\ncount = 150\ntemperature = 500.0\n\
    [[spawn]]\nmin = [0.0, -0.018, 0.01]\nmax = [0.018, 0.018, 0.06]\ncount = 150\n\
    [simulation]\ntimestep = 1e-5\nthermal_time_scale = 1000.0\nmax_particles = 300\n";

#[test]
fn a_flowing_bed_keeps_its_heat_content_to_the_bit_on_any_number_of_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut sim = simulation(BED, vec![]);
            while sim.particles.len() < 300 {
                sim.step().unwrap();
            }
            let (content, joules) = sim.heat_content();
            assert!(joules > 0.0);
            for step in 1..10_000 {
                sim.step().unwrap();
                assert_eq!(sim.heat_content().0, content, "step {step}");
            }
            sim.snapshot().unwrap()
        })
    };
    let (one, two) = (run(1), run(2));
    let p = &one.particles;
    assert_eq!(p.len(), 300);
    assert!(
        p.temperature.iter().any(|&t| t > 300.5 && t < 499.5),
        "heat flowed"
    );
    assert_eq!(one.particles, two.particles);
}

/// The error of a scenario given as text.
fn refused(text: &str) -> String {
    let path = common::data("inline.toml");
    let e = tinydem::scenario::Scenario::parse(text, &path).expect_err("refused");
    format!("{e:#}")
}

#[test]
fn bad_heat_keys_are_refused_naming_the_key() {
    let m = "[[materials]]\nname = \"a\"\n";
    for (text, key) in [
        (format!("{m}thermal_conductivity = -1.0\n"), "thermal_conductivity = -1"),
        (format!("{m}heat_capacity = -5.0\n"), "heat_capacity = -5"),
        (format!("{m}initial_temperature = -3.0\n"), "initial_temperature = -3 K"),
        ("[kinetics]\nambient_temperature = -1.0\n".into(), "ambient_temperature = -1 K"),
        (
            "[simulation]\nthermal_time_scale = 0.0\n".into(),
            "thermal_time_scale = 0",
        ),
        (
            "[simulation]\nconduction_model = \"fourier\"\n".into(),
            "conduction_model = \"fourier\"",
        ),
        (
            "[[spawn]]\nmin = [0.0, 0.0, 0.0]\nmax = [0.1, 0.1, 0.1]\ncount = 1\ntemperature = -2.0\n"
                .into(),
            "temperature = -2 K",
        ),
    ] {
        let e = refused(&text);
        assert!(e.contains(key), "{text}: {e}");
    }
    // Grains of a material that conducts need its heat capacity (a wall's material not).
    let text = "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
        [[materials]]\nname = \"sand\"\nthermal_conductivity = 1.0\n\
        [simulation]\nmax_particles = 0\n";
    let e = Simulation::new(common::scenario(text))
        .err()
        .expect("refused");
    assert!(
        format!("{e:#}").contains("material \"sand\" has no heat_capacity"),
        "{e:#}"
    );
}

#[test]
fn a_temperature_column_is_read_checked_and_written() {
    let t = tempfile::tempdir().unwrap();
    let header = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,T";
    let row = |t: &str| format!("0.0,0.0,0.01,0.003,0,0,0,1,0,0,0,0,0,0,{t}");
    std::fs::write(
        t.path().join("p.csv"),
        format!("{header}\n{}\n", row("NaN")),
    )
    .unwrap();
    let scenario = "[geometry]\nradius_min = 0.003\nradius_max = 0.003\n\
        [material]\nthermal_conductivity = 1.0\nheat_capacity = 800.0\ninitial_temperature = 300.0\n\
        [input]\nparticles = \"p.csv\"\n[simulation]\nmax_particles = 0\nframes = 1\nsteps_per_frame = 10\n";
    std::fs::write(t.path().join("s.toml"), scenario).unwrap();
    let o = common::tinydem(&["run", "s.toml"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("p.csv:2"), "{err}");
    std::fs::write(
        t.path().join("p.csv"),
        format!("{header}\n{}\n", row("351.5")),
    )
    .unwrap();
    let o = common::tinydem(&["run", "s.toml"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let frame = std::fs::read_to_string(t.path().join("output/particles000001.csv")).unwrap();
    let mut lines = frame.lines();
    let columns: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = columns.iter().position(|c| *c == "T").expect("a T column");
    let value: f64 = lines
        .next()
        .unwrap()
        .split(',')
        .nth(at)
        .unwrap()
        .parse()
        .unwrap();
    // One grain alone: its content unchanged, its temperature that of the file's.
    assert!((value - 351.5).abs() < 1e-9, "{value}");
    let log = std::fs::read_to_string(t.path().join("output/log.csv")).unwrap();
    assert!(
        log.lines()
            .next()
            .unwrap()
            .contains("T_mean,T_min,T_max,heat_content")
    );
}

#[test]
fn check_prints_the_thermal_step_refuses_an_overshooting_one_and_warns_of_idle_keys() {
    let t = tempfile::tempdir().unwrap();
    let text = |scale: f64| {
        format!(
            "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
             [material]\nthermal_conductivity = 5.0\nheat_capacity = 800.0\n\
             [simulation]\ntimestep = 1e-5\nthermal_time_scale = {scale}\n"
        )
    };
    std::fs::write(t.path().join("s.toml"), text(1000.0)).unwrap();
    let o = common::tinydem(&["check", "s.toml"], t.path());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("thermal step           1.000000e-2 s (f = 1000;"),
        "{out}"
    );
    assert!(!out.contains("warning"), "{out}");
    std::fs::write(t.path().join("s.toml"), text(1e8)).unwrap();
    let o = common::tinydem(&["run", "s.toml"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("exceeds the grains' thermal time scale"),
        "{err}"
    );
    let idle = "[material]\ninitial_temperature = 400.0\n[kinetics]\nambient_temperature = 290.0\n";
    std::fs::write(t.path().join("s.toml"), idle).unwrap();
    let o = common::tinydem(&["check", "s.toml"], t.path());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("warning: material \"default\" initial_temperature, [kinetics] ambient_temperature set, but no material conducts heat"),
        "{out}"
    );
}

#[test]
fn temperatures_are_rendered_and_coarse_grained_into_a_field() {
    let t = tempfile::tempdir().unwrap();
    let text = BED.replace(
        "max_particles = 300\n",
        "max_particles = 300\nframes = 2\nsteps_per_frame = 400\n",
    ) + "[output]\ncontacts = true\n";
    std::fs::write(t.path().join("bed.toml"), text).unwrap();
    let o = common::tinydem(&["run", "bed.toml", "--output", "out"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    log_matches_the_frame(&t.path().join("out"), 2);
    let o = common::tinydem(
        &[
            "render",
            "out/particles000002.csv",
            "--color",
            "temperature",
        ],
        t.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(t.path().join("out/particles000002.png").exists());
    let o = common::tinydem(
        &["analyze", "out", "--fields", "--spacing", "0.01"],
        t.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(t.path().join("out/fields000002.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (at, rho) = (
        header
            .iter()
            .position(|c| *c == "temperature")
            .expect("a temperature column"),
        header.iter().position(|c| *c == "density").unwrap(),
    );
    let mut seen = 0;
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        if v[rho] > 100.0 {
            assert!(v[at] > 299.0 && v[at] < 501.0, "{line}");
            seen += 1;
        }
    }
    assert!(seen > 10, "{seen} points in the bed");
    // A run without heat has no temperatures to colour by: said plainly.
    std::fs::write(
        t.path().join("cold.toml"),
        "[simulation]\nframes = 1\nsteps_per_frame = 10\nmax_particles = 5\n",
    )
    .unwrap();
    let o = common::tinydem(&["run", "cold.toml", "--output", "cold"], t.path());
    assert!(o.status.success());
    let o = common::tinydem(
        &[
            "render",
            "cold/particles000001.csv",
            "--color",
            "temperature",
        ],
        t.path(),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("no temperatures (a T column)"),
        "{err}"
    );
}

/// One free grain (no contacts) of radius 3 mm, glass-like, at 400 K, with the material
/// keys `extra` and the `[kinetics]` keys `kinetics`.
fn alone(extra: &str, kinetics: &str) -> (Simulation, f64) {
    let text = format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.003\n\
         [material]\ndensity = 2500.0\nheat_capacity = 800.0\n{extra}\n\
         [kinetics]\ngravity = [0.0, 0.0, 0.0]\n{kinetics}\n\
         [simulation]\ntimestep = 1e-5\nthermal_time_scale = 1e4\nmax_particles = 0\n"
    );
    let grain = Particle {
        temperature: 400.0,
        ..common::sphere(0.003, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO)
    };
    (simulation(&text, vec![grain]), mc(0.003, 2500.0, 800.0))
}

#[test]
fn a_grain_cools_to_its_surroundings_and_warms_by_its_source_at_the_rates_they_give() {
    let (r, dt, steps) = (0.003, 0.1, 2000);
    let area = 4.0 * PI * r * r;
    // Newton's cooling: T - T_inf falls as exp(-h A t / (m c)).
    let (mut sim, c) = alone(
        "surface_heat_transfer = 20.0",
        "ambient_temperature = 300.0",
    );
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let rate = 20.0 * area / c;
    let expected = 300.0 + 100.0 * (-rate * steps as f64 * dt).exp();
    let t = sim.particles.temperature[0];
    assert!(
        (t - 300.0) / (expected - 300.0) - 1.0 < 0.005,
        "{t} K against {expected} K"
    );
    assert!(
        (t - 300.0) / (expected - 300.0) - 1.0 > -0.005,
        "{t} K against {expected} K"
    );
    // A source q_V warms it by q_V V t / (m c).
    let (mut sim, c) = alone("heat_source = 1e4", "");
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let volume = 4.0 / 3.0 * PI * r.powi(3);
    let expected = 400.0 + 1e4 * volume * steps as f64 * dt / c;
    let t = sim.particles.temperature[0];
    assert!(
        (t - expected).abs() < 1e-9 * expected,
        "{t} K against {expected} K"
    );
}

/// The columns of a CSV text by name, each a column of numbers.
fn columns(text: &str) -> std::collections::HashMap<String, Vec<f64>> {
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut out: std::collections::HashMap<String, Vec<f64>> =
        names.iter().map(|n| (n.clone(), Vec::new())).collect();
    for line in lines {
        for (name, v) in names.iter().zip(line.split(',')) {
            out.get_mut(name)
                .unwrap()
                .push(v.parse().unwrap_or(f64::NAN));
        }
    }
    out
}

/// `log.csv`'s temperatures and heat content at frame `k` of the bed (`BED`'s material) are
/// those counted from the frame's `T` and `R` columns.
fn log_matches_the_frame(out: &std::path::Path, k: usize) {
    let log = columns(&std::fs::read_to_string(out.join("log.csv")).unwrap());
    let frame =
        columns(&std::fs::read_to_string(out.join(format!("particles{k:06}.csv"))).unwrap());
    let (t, r) = (&frame["T"], &frame["R"]);
    let mean = t.iter().sum::<f64>() / t.len() as f64;
    let content: f64 = t
        .iter()
        .zip(r)
        .map(|(t, r)| mc(*r, 2500.0, 800.0) * t)
        .sum();
    let (min, max) = (
        t.iter().copied().fold(f64::INFINITY, f64::min),
        t.iter().copied().fold(0.0, f64::max),
    );
    let at = |name: &str| log[name][k];
    assert!(
        (at("T_mean") - mean).abs() < 1e-9 * mean,
        "{} against {mean}",
        at("T_mean")
    );
    assert_eq!((at("T_min"), at("T_max")), (min, max));
    assert!(
        (at("heat_content") - content).abs() < 1e-9 * content,
        "{} against {content}",
        at("heat_content")
    );
    assert!(min < max, "heat flowed: {min} .. {max}");
}
