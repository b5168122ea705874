//! Fixed particles: held in place and at rest whatever acts on them (`[[fixed]]` boxes, the
//! `fixed` column of a particle file, `Simulation::fix_particles` as Python's `freeze`),
//! while they push on the others with their material.

use crate::common;

use glam::DVec3;
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::io::csv::{Extra, read_particles, write_particles};
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};

const R: f64 = 0.005;
const RHO: f64 = 1000.0;
const E: f64 = 1e6;
const NU: f64 = 0.3;
const G: f64 = 9.81;
/// The grains of the floor.
const FLOOR: usize = 81;

/// A scenario without mesh under gravity along -z, with `extra` TOML lines.
fn text(extra: &str) -> String {
    format!(
        "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
         [material]\ndensity = {RHO}\nyoungs_modulus = {E}\npoisson_ratio = {NU}\n\
         restitution = 0.3\n\
         [kinetics]\ngravity = [0.0, 0.0, -{G}]\n\
         [simulation]\nmax_particles = 0\nspawn_attempts = 0\n{extra}"
    )
}

fn at(x: DVec3) -> Particle {
    common::sphere(R, x, DVec3::ZERO, DVec3::ZERO)
}

fn sim(extra: &str, particles: Vec<Particle>) -> Simulation {
    let s = common::scenario(&text(extra));
    Simulation::from_parts(s, Mesh::default(), particles.into_iter().collect()).unwrap()
}

/// A box around the plane z = 0, holding every centre on it.
const FLOOR_BOX: &str = "[[fixed]]\nmin = [-1.0, -1.0, -0.001]\nmax = [1.0, 1.0, 0.001]\n";

#[test]
fn a_grain_rests_on_a_fixed_grain_at_the_hertz_overlap() {
    let mut s = sim(
        FLOOR_BOX,
        vec![at(DVec3::ZERO), at(DVec3::new(0.0, 0.0, 2.0 * R + 1e-4))],
    );
    assert_eq!(s.particles.fixed, vec![true, false]);
    let start = s.particles.clone();
    let steps = (0.4 / s.scenario.simulation.timestep) as u64;
    for _ in 0..steps {
        s.step().unwrap();
    }
    let p = &s.particles;
    // The fixed grain has not moved by a bit, though the other's weight rests on it.
    assert_eq!((p.x[0], p.q[0]), (start.x[0], start.q[0]));
    assert_eq!((p.v[0], p.w[0]), (DVec3::ZERO, DVec3::ZERO));
    assert!(p.v[1].length() < 1e-6, "still moving: {}", p.v[1]);
    // Hertz: m g = 4/3 E* sqrt(R*) δ^(3/2), E* = E / (2 (1 - ν²)), R* = R / 2.
    let e_star = E / (2.0 * (1.0 - NU * NU));
    let weight = Inertia::mass(R, RHO) * G;
    let delta = (weight / (4.0 / 3.0 * e_star * (R / 2.0).sqrt())).powf(2.0 / 3.0);
    let overlap = 2.0 * R - (p.x[1].z - p.x[0].z);
    assert!(
        (overlap / delta - 1.0).abs() < 0.01,
        "overlap {overlap} vs Hertz {delta}"
    );
}

/// A floor of 9 x 9 grains at z = 0 and 18 grains above its middle, falling.
fn floor_and_grains() -> Vec<Particle> {
    let mut p = Vec::new();
    for i in 0..9 {
        for j in 0..9 {
            p.push(at(DVec3::new(i as f64, j as f64, 0.0) * 2.0 * R));
        }
    }
    for k in 0..18 {
        let (i, j, l) = (k % 3, (k / 3) % 3, k / 9);
        let jitter = DVec3::new(0.05 * (k % 4) as f64, 0.03 * (k % 3) as f64, 0.0) * R;
        p.push(at(DVec3::new(
            2.6 + i as f64,
            2.6 + j as f64,
            1.0 + l as f64,
        ) * 2.2
            * R
            + jitter));
    }
    p
}

fn settle(mut s: Simulation) -> Particles {
    for _ in 0..6000 {
        s.step().unwrap();
    }
    s.particles
}

#[test]
fn a_box_a_column_and_fix_particles_give_the_same_bits() {
    let grains = floor_and_grains();
    let by_box = settle(sim(FLOOR_BOX, grains.clone()));
    // The `fixed` column of a particle file.
    let mut marked: Particles = grains.iter().copied().collect();
    for k in 0..FLOOR {
        marked.fixed[k] = true;
    }
    let mut csv = Vec::new();
    write_particles(&mut csv, &marked, Extra::default()).unwrap();
    let read = read_particles(&csv[..], "floor.csv").unwrap();
    let s = common::scenario(&text(""));
    let by_column = settle(Simulation::from_parts(s, Mesh::default(), read).unwrap());
    // Fixed from outside, before the first step.
    let mut s = sim("", grains.clone());
    s.fix_particles(&(0..FLOOR as u64).collect::<Vec<u64>>(), true)
        .unwrap();
    assert!(
        s.fix_particles(&[99], true)
            .unwrap_err()
            .to_string()
            .contains("no particle 99")
    );
    let by_call = settle(s);
    assert_eq!(by_box, by_column);
    assert_eq!(by_box, by_call);
    // The floor held; the grains came to rest on it, none fell through.
    let end: Vec<Particle> = by_box.iter_by_id().map(|(_, p)| p).collect();
    for k in 0..FLOOR {
        assert!(end[k].fixed && end[k].x == grains[k].x && end[k].v == DVec3::ZERO);
    }
    let lowest = end[FLOOR..]
        .iter()
        .map(|p| p.x.z)
        .fold(f64::INFINITY, f64::min);
    // (In a hollow of four floor grains a centre lies sqrt(2) R above theirs.)
    assert!(lowest > 1.4 * R, "a grain fell to {lowest}");
    assert!(end[FLOOR..].iter().all(|p| p.v.length() < 0.05));
}

#[test]
fn unfixed_particles_fall_again_from_rest() {
    let mut s = sim(FLOOR_BOX, vec![at(DVec3::ZERO)]);
    for _ in 0..100 {
        s.step().unwrap();
    }
    assert_eq!(s.particles.x[0], DVec3::ZERO);
    s.fix_particles(&[0], false).unwrap();
    let t0 = s.time;
    for _ in 0..100 {
        s.step().unwrap();
    }
    let fall = -s.particles.x[0].z;
    let expected = 0.5 * G * (s.time - t0).powi(2);
    assert!((fall / expected - 1.0).abs() < 0.03, "{fall} vs {expected}");
}

#[test]
fn runs_write_the_fixed_column_and_check_counts_the_held() {
    let t = tempfile::tempdir().unwrap();
    let mut csv = Vec::new();
    let grains: Particles = floor_and_grains().into_iter().collect();
    write_particles(&mut csv, &grains, Extra::default()).unwrap();
    std::fs::write(t.path().join("grains.csv"), csv).unwrap();
    let scenario = format!(
        "{}frames = 2\nsteps_per_frame = 50\n{FLOOR_BOX}[input]\nparticles = \"grains.csv\"\n[output]\ndir = \"out\"\n",
        text("")
    );
    std::fs::write(t.path().join("s.toml"), scenario).unwrap();
    let o = common::tinydem(&["check", "s.toml"], t.path());
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains("holds the 81 initial grains in it in place"),
        "{said}"
    );
    let o = common::tinydem(&["run", "s.toml", "-q"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let frame = std::fs::read_to_string(t.path().join("out/particles000002.csv")).unwrap();
    assert!(frame.lines().next().unwrap().ends_with(",fixed"));
    let fixed = frame.lines().skip(1).filter(|l| l.ends_with(",1")).count();
    assert_eq!(fixed, FLOOR);
    let resolved = std::fs::read_to_string(t.path().join("out/run.toml")).unwrap();
    assert!(resolved.contains("[[fixed]]"), "{resolved}");
}
