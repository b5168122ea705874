//! Cohesion (simplified JKR): a pull k_c A over the contact area. A resting pair settles at
//! the overlap where the Hertz force balances the pull; a grain hangs under a ceiling while
//! its weight is below the analytic pull-off force, and falls when it is above.

use crate::common;

use std::f64::consts::PI;

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};

const R: f64 = 0.005;
const E: f64 = 1e6;
const NU: f64 = 0.3;
const KC: f64 = 2e3; // J/m^3

fn grain(x: DVec3) -> Particle {
    Particle {
        x,
        radius: R,
        v: DVec3::ZERO,
        q: DQuat::IDENTITY,
        w: DVec3::ZERO,
        tag: 0,
        material: 0,
        fixed: false,
        body: None,
        ..Particle::default()
    }
}

fn sim(g: f64, mesh: Option<&str>, particles: Vec<Particle>) -> Simulation {
    let s = common::scenario(&format!(
        "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
         [material]\nyoungs_modulus = {E}\npoisson_ratio = {NU}\ncohesion = {KC}\n\
         [kinetics]\ngravity = [0.0, 0.0, {}]\n\
         [simulation]\ntimestep = 2e-6\nmax_particles = 0\nspawn_attempts = 0\n",
        -g
    ));
    let mesh = mesh.map_or_else(Mesh::default, |t| {
        Mesh::parse_off(t, "ceiling", &s.geometry.mesh_radii).unwrap()
    });
    Simulation::from_parts(s, mesh, particles.into_iter().collect::<Particles>()).unwrap()
}

/// The root of `f` in [lo, hi] (f changes sign there), by bisection.
fn root(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) > 0.0) == (f(lo) > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn a_resting_pair_settles_where_hertz_balances_the_pull() {
    // Two equal spheres: E* = E / (2 (1 - nu^2)), R* = R / 2, the contact circle of their
    // lens a^2 = R delta - delta^2 / 4.
    let e_star = E / (2.0 * (1.0 - NU * NU));
    let net = |d: f64| {
        4.0 / 3.0 * e_star * (R / 2.0).sqrt() * d.powf(1.5) - KC * PI * (R * d - d * d / 4.0)
    };
    let delta = root(net, 1e-12, R);
    let mut s = sim(
        0.0,
        None,
        vec![
            grain(DVec3::new(-R + 1e-7, 0.0, 0.0)),
            grain(DVec3::new(R - 1e-7, 0.0, 0.0)),
        ],
    );
    for _ in 0..100_000 {
        s.step().unwrap();
    }
    let x = &s.particles.x;
    let overlap = 2.0 * R - (x[1] - x[0]).length();
    assert!(
        (overlap / delta - 1.0).abs() < 1e-3,
        "overlap {overlap} m, balance of Hertz and the pull at {delta} m"
    );
}

/// A ceiling (a rectangle facing down at z = 0).
const CEILING: &str = "OFF\n4 1 0\n-1 -1 0\n-1 1 0\n1 1 0\n1 -1 0\n4 0 1 2 3\n";

#[test]
fn a_grain_hangs_below_its_pull_off_force_and_falls_above_it() {
    // Sphere on a rigid plane: E* = E / (1 - nu^2), the cut circle a^2 = 2 R delta - delta^2.
    let e_star = E / (1.0 - NU * NU);
    let hertz = |d: f64| 4.0 / 3.0 * e_star * R.sqrt() * d.powf(1.5);
    let pull = |d: f64| KC * PI * (2.0 * R * d - d * d);
    // Pull-off: the largest net pull over the overlap (where its derivative vanishes).
    let slope = |d: f64| KC * PI * (2.0 * R - 2.0 * d) - 2.0 * e_star * R.sqrt() * d.sqrt();
    let d_max = root(slope, 1e-12, R);
    let pull_off = pull(d_max) - hertz(d_max);
    let m = Inertia::mass(R, 1000.0);
    assert!(pull_off > 0.0 && d_max < 0.5 * R);
    for (share, holds) in [(0.9, true), (1.1, false)] {
        let g = share * pull_off / m;
        // Start at rest where it would hang: the root on the stiff side of the maximum.
        let delta = if holds {
            root(|d| pull(d) - hertz(d) - m * g, d_max, R)
        } else {
            d_max
        };
        let mut s = sim(
            g,
            Some(CEILING),
            vec![grain(DVec3::new(0.0, 0.0, -(R - delta)))],
        );
        for _ in 0..50_000 {
            s.step().unwrap();
        }
        let z = s.particles.x[0].z;
        if holds {
            let overlap = R + z;
            assert!(
                (overlap / delta - 1.0).abs() < 1e-3,
                "at {share} of the pull-off force: overlap {overlap} vs {delta}"
            );
        } else {
            let v = s.particles.v[0].z;
            assert!(
                z < -R - 1e-5 && v < 0.0,
                "at {share} of the pull-off force it should fall: z = {z}, v = {v}"
            );
        }
    }
}
