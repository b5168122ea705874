//! The reference trajectories computed with the original TinyDEM program
//! (`tests/data/reference`, copied from `shared/reference`) must be matched under the rule
//! of their README: |actual - expected| <= tol[f] * (1 + |expected|) for every compared
//! frame f, particle i and column c.

use crate::common;

use tinydem::engine::Simulation;
use tinydem::io::csv::{frame_name, load_particles};
use tinydem::model::particles::Particle;
use tinydem::scenario::Scenario;

fn column(p: &Particle, c: &str) -> f64 {
    match c {
        "x" => p.x.x,
        "y" => p.x.y,
        "z" => p.x.z,
        "R" => p.radius,
        "vx" => p.v.x,
        "vy" => p.v.y,
        "vz" => p.v.z,
        "q0" => p.q.w,
        "q1" => p.q.x,
        "q2" => p.q.y,
        "q3" => p.q.z,
        "wx" => p.w.x,
        "wy" => p.w.y,
        "wz" => p.w.z,
        _ => panic!("unknown column {c}"),
    }
}

/// Runs one case and returns the worst error / tolerance over all compared values.
fn check_case(case: &str) -> f64 {
    let dir = common::data(&format!("reference/{case}"));
    let spec: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("compare.json")).unwrap()).unwrap();
    let columns: Vec<String> = spec["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    let tols = spec["tolerance_per_frame"].as_array().unwrap();
    let scenario = Scenario::load(&dir.join("scenario.toml")).unwrap();
    let steps = scenario.simulation.steps_per_frame;
    assert_eq!(scenario.simulation.frames as usize + 1, tols.len());
    let mut sim = Simulation::new(scenario).unwrap();
    let mut worst = 0.0f64;
    for (f, tol) in tols.iter().enumerate() {
        if f > 0 {
            for _ in 0..steps {
                sim.step().unwrap();
            }
        }
        let Some(tol) = tol.as_f64() else { continue };
        let expected = load_particles(&dir.join("expected").join(frame_name(f as u64))).unwrap();
        assert_eq!(
            expected.len(),
            sim.particles.len(),
            "{case} frame {f}: particle count"
        );
        for (i, (e, (_, a))) in expected.iter().zip(sim.particles.iter_by_id()).enumerate() {
            for c in &columns {
                let (e, a) = (column(&e, c), column(&a, c));
                let err = (a - e).abs() / (1.0 + e.abs()) / tol;
                assert!(
                    err <= 1.0,
                    "{case} frame {f} particle {i} column {c}: {a:.17e} vs expected {e:.17e} ({err:.3} x tolerance)"
                );
                worst = worst.max(err);
            }
        }
    }
    worst
}

macro_rules! reference_case {
    ($name:ident) => {
        #[test]
        fn $name() {
            let worst = check_case(stringify!($name));
            eprintln!("{}: worst error / tolerance {worst:.3e}", stringify!($name));
        }
    };
}

reference_case!(headon);
reference_case!(oblique_spin);
reference_case!(floor_slide);
reference_case!(floor_twist);
reference_case!(primitives);
reference_case!(drag);
reference_case!(small_pile);
