//! Bounded memory: the cell grid is hashed, so particles flying apart cost no more memory
//! than particles staying close. (One test in this binary, so that the process's peak
//! resident memory is its own.)

use std::path::Path;

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::model::particles::{Particle, Particles};
use tinydem::scenario::Scenario;
use tinydem::tools::bench::proc_status_bytes;

fn pair(speed: f64) -> Simulation {
    let s = Scenario::parse(
        "[geometry]\nradius_min = 0.005\nradius_max = 0.005\n[kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\nmax_particles = 0\n",
        Path::new("s.toml"),
    )
    .unwrap();
    // Along the space diagonal, so that their bounding box grows in all three directions
    // (a regular grid over it would need ~10^15 cells).
    let diagonal = DVec3::ONE.normalize();
    let p = |x: f64, v: f64| Particle {
        x: x * diagonal,
        radius: 0.005,
        v: v * diagonal,
        q: DQuat::IDENTITY,
        w: DVec3::ZERO,
        tag: 0,
        material: 0,
        fixed: false,
        body: None,
        ..Particle::default()
    };
    // Two pairs of neighbours (listed, so not "lonely": each pair's lists are rebuilt every
    // half skin of travel), 1 mm apart within a pair.
    let particles: Particles = [
        p(-0.006, -speed),
        p(-0.017, -speed),
        p(0.006, speed),
        p(0.017, speed),
    ]
    .into_iter()
    .collect();
    Simulation::from_parts(s, Mesh::default(), particles).unwrap()
}

#[test]
fn particles_flying_apart_to_a_kilometre_keep_memory_flat() {
    // Close: two particles at rest, same number of steps.
    let steps = 7_000;
    let mut close = pair(0.0);
    for _ in 0..steps {
        close.step().unwrap();
    }
    let before = proc_status_bytes("VmHWM:");
    assert!(before > 0, "needs /proc (Linux)");
    // Apart: 1 km/s each way; after the run they are more than 1 km apart.
    let mut apart = pair(1000.0);
    for _ in 0..steps {
        apart.step().unwrap();
    }
    let d = apart.particles.x[0].distance(apart.particles.x[2]);
    assert!(d > 2_000.0, "distance {d} m");
    assert!(apart.rebuilds() > 1000, "lists were rebuilt as they moved");
    let after = proc_status_bytes("VmHWM:");
    let growth = after.saturating_sub(before);
    assert!(growth < 1 << 20, "peak memory grew by {growth} bytes");
}
