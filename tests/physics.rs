//! Physics against theory: Hertz collisions, energy conservation, friction regimes,
//! drag, planar runs and orientation.

use crate::common;

use std::f64::consts::PI;

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};

const R: f64 = 0.005;
const RHO: f64 = 1000.0;
const E: f64 = 1e6;
const NU: f64 = 0.3;

fn particle(x: DVec3, v: DVec3, w: DVec3) -> Particle {
    common::sphere(R, x, v, w)
}

/// A simulation of `particles` with material keys `material` (TOML lines), gravity `g`
/// and an optional mesh given as OFF text.
fn sim(
    material: &str,
    g: DVec3,
    dt: Option<f64>,
    off: Option<&str>,
    particles: Vec<Particle>,
) -> Simulation {
    let dt = dt.map_or(String::new(), |dt| format!("timestep = {dt:e}\n"));
    let text = format!(
        "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
         [material]\ndensity = {RHO}\nyoungs_modulus = {E}\npoisson_ratio = {NU}\n{material}\n\
         [kinetics]\ngravity = [{}, {}, {}]\n\
         [simulation]\nmax_particles = 0\nspawn_attempts = 0\n{dt}",
        g.x, g.y, g.z
    );
    let s = common::scenario(&text);
    let mesh = off.map_or_else(Mesh::default, |t| {
        Mesh::parse_off(t, "test mesh", &s.geometry.mesh_radii).unwrap()
    });
    Simulation::from_parts(s, mesh, particles.into_iter().collect::<Particles>()).unwrap()
}

/// A square floor rectangle at z = 0.
const FLOOR: &str = "OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n";

/// Head-on collision of two equal spheres: returns (restitution, contact duration).
fn head_on(e_n: f64, v0: f64) -> (f64, f64) {
    let mut s = sim(
        &format!("restitution = {e_n}\nfriction_sliding = 0.3\nfriction_rolling = 0.3"),
        DVec3::ZERO,
        Some(1e-7),
        None,
        vec![
            particle(
                DVec3::new(-R - 1e-5, 0.0, 0.0),
                DVec3::X * v0 / 2.0,
                DVec3::ZERO,
            ),
            particle(
                DVec3::new(R + 1e-5, 0.0, 0.0),
                -DVec3::X * v0 / 2.0,
                DVec3::ZERO,
            ),
        ],
    );
    let dt = s.scenario.simulation.timestep;
    let touching = |s: &Simulation| s.particles.x[1].x - s.particles.x[0].x < 2.0 * R;
    let mut steps_in_contact = 0u64;
    while !touching(&s) {
        s.step().unwrap();
    }
    let mut last_touch = 0;
    for k in 0..200_000 {
        s.step().unwrap();
        if touching(&s) {
            steps_in_contact += 1;
            last_touch = k;
        } else if k > last_touch + 100 {
            break;
        }
    }
    let v_after = s.particles.v[1].x - s.particles.v[0].x;
    (v_after / v0, steps_in_contact as f64 * dt)
}

#[test]
fn elastic_hertz_contact_duration_matches_hertz_theory() {
    let v0 = 0.5;
    let (e, t_c) = head_on(1.0, v0);
    assert!((e - 1.0).abs() < 1e-4, "restitution {e}");
    // Hertz: t_c = 2.8683 (m*^2 / (R* E*^2 v0))^(1/5), with F = 4/3 E* sqrt(R*) δ^(3/2).
    let m_star = Inertia::mass(R, RHO) / 2.0;
    let r_star = R / 2.0;
    let e_star = E / (2.0 * (1.0 - NU * NU));
    let theory = 2.868_265 * (m_star * m_star / (r_star * e_star * e_star * v0)).powf(0.2);
    assert!(
        (t_c / theory - 1.0).abs() < 2e-3,
        "t_c {t_c} vs Hertz {theory}"
    );
}

#[test]
fn damped_hertz_collision_restitution_follows_e_n() {
    // The damping of Eq. (18) with β of Eq. (21) makes e_n nearly independent of the
    // impact speed; the measured coefficient matches within a few per cent.
    for e_n in [0.2, 0.5, 0.8] {
        for v0 in [0.1, 1.0] {
            let (e, _) = head_on(e_n, v0);
            assert!(
                (e - e_n).abs() < 0.05,
                "e_n = {e_n}, v0 = {v0}: measured {e}"
            );
        }
    }
}

/// Kinetic + rotational + Hertzian elastic energy (8/15 E* sqrt(R*) δ^(5/2) per contact).
fn energy(s: &Simulation) -> f64 {
    let p = &s.particles;
    let e_star_pp = E / (2.0 * (1.0 - NU * NU));
    let e_star_pw = E / (1.0 - NU * NU);
    let mut total = 0.0;
    for i in 0..p.len() {
        let b = Inertia::new(p.radius[i], RHO, 0.0);
        total += 0.5 * b.m * p.v[i].length_squared() + 0.5 * b.i * p.w[i].length_squared();
        for j in i + 1..p.len() {
            let delta = p.radius[i] + p.radius[j] - p.x[i].distance(p.x[j]);
            if delta > 0.0 {
                let r_star = p.radius[i] * p.radius[j] / (p.radius[i] + p.radius[j]);
                total += 8.0 / 15.0 * e_star_pp * r_star.sqrt() * delta.powf(2.5);
            }
        }
        for face in &s.walls.mesh.faces {
            let delta = p.radius[i] + face.radius - p.x[i].distance(face.closest_point(p.x[i]));
            if delta > 0.0 {
                total += 8.0 / 15.0 * e_star_pw * p.radius[i].sqrt() * delta.powf(2.5);
            }
        }
    }
    total
}

#[test]
fn elastic_frictionless_gas_conserves_energy_without_drift() {
    // 27 spheres in a closed box, e_n = 1, no friction, no drag: the symplectic scheme
    // keeps the energy error bounded and free of drift.
    let box_off = "OFF\n8 6 0\n0 0 0\n0.06 0 0\n0.06 0.06 0\n0 0.06 0\n0 0 0.06\n0.06 0 0.06\n0.06 0.06 0.06\n0 0.06 0.06\n\
                   4 0 1 2 3\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
    let mut particles = Vec::new();
    let mut k = 0u32;
    for ix in 0..3 {
        for iy in 0..3 {
            for iz in 0..3 {
                k += 1;
                let x = DVec3::new(ix as f64, iy as f64, iz as f64) * 0.018 + DVec3::splat(0.012);
                let v = DVec3::new(
                    (k * 7 % 5) as f64 - 2.0,
                    (k * 3 % 7) as f64 - 3.0,
                    (k % 3) as f64 - 1.0,
                ) * 0.2;
                particles.push(particle(x, v, DVec3::ZERO));
            }
        }
    }
    let frictionless = "restitution = 1.0\nfriction_sliding = 0.0\nfriction_rolling = 0.0";
    // A fifth of Eq. (50) keeps the O(Δt) shadow-energy oscillation during contacts small.
    let mut s = sim(
        frictionless,
        DVec3::ZERO,
        Some(3.0e-5),
        Some(box_off),
        particles,
    );
    let e0 = energy(&s);
    let mut samples = Vec::new();
    for _ in 0..200 {
        for _ in 0..100 {
            s.step().unwrap();
        }
        samples.push(energy(&s));
    }
    assert!(s.contact_count() > 0 || s.rebuilds() > 1);
    let max_dev = samples
        .iter()
        .map(|e| (e - e0).abs() / e0)
        .fold(0.0, f64::max);
    assert!(max_dev < 1e-2, "energy deviates by {max_dev:e}");
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let drift = (mean(&samples[150..]) - mean(&samples[..50])).abs() / e0;
    eprintln!("max deviation {max_dev:e}, drift {drift:e}");
    assert!(drift < 2e-4, "energy drifts by {drift:e}");
}

#[test]
fn sliding_sphere_ends_rolling_at_five_sevenths_of_its_speed() {
    let v0 = 0.5;
    let mut s = sim(
        "restitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.0\nfriction_twisting = 0.0",
        DVec3::new(0.0, 0.0, -9.81),
        None,
        Some(FLOOR),
        vec![particle(
            DVec3::new(0.0, 0.0, R * 0.9995),
            DVec3::X * v0,
            DVec3::ZERO,
        )],
    );
    for _ in 0..40_000 {
        s.step().unwrap();
    }
    let v = s.particles.v[0];
    let w = s.particles.w[0];
    assert!(
        (v.x / v0 - 5.0 / 7.0).abs() < 5e-3,
        "final speed ratio {}",
        v.x / v0
    );
    // Rolling without slipping: v = ω R.
    assert!((w.y * R - v.x).abs() < 1e-2 * v.x, "v {v} w {w}");
}

/// Sphere resting on a floor under gravity tilted by `theta`: returns the distance moved
/// along the slope during the second half of the run.
fn incline(theta_deg: f64, mu_s: f64, mu_r: f64) -> f64 {
    let th = theta_deg.to_radians();
    let g = DVec3::new(th.sin(), 0.0, -th.cos()) * 9.81;
    let mut s = sim(
        &format!("restitution = 0.5\nfriction_sliding = {mu_s}\nfriction_rolling = {mu_r}"),
        g,
        None,
        Some(FLOOR),
        vec![particle(
            DVec3::new(0.0, 0.0, R * 0.9996),
            DVec3::ZERO,
            DVec3::ZERO,
        )],
    );
    for _ in 0..20_000 {
        s.step().unwrap();
    }
    let x_half = s.particles.x[0].x;
    for _ in 0..20_000 {
        s.step().unwrap();
    }
    s.particles.x[0].x - x_half
}

#[test]
fn static_friction_holds_a_sphere_on_an_incline_below_both_coefficients() {
    // tan(10°) = 0.176 < μ_s, μ_r = 0.3: the springs hold it.
    let moved = incline(10.0, 0.3, 0.3);
    assert!(moved.abs() < 1e-7, "moved {moved}");
}

#[test]
fn sphere_moves_once_the_incline_exceeds_either_coefficient() {
    // tan(20°) = 0.364 > μ_r = 0.3 (μ_s large): rolls.
    let rolled = incline(20.0, 1.0, 0.3);
    assert!(rolled > 1e-2, "rolled {rolled}");
    // tan(20°) > μ_s = 0.3 (μ_r large): slides.
    let slid = incline(20.0, 0.3, 1.0);
    assert!(slid > 1e-2, "slid {slid}");
}

#[test]
fn twisting_spin_decays_and_stops() {
    // At Eq. (50)'s step: with the springs advanced first the torsional oscillation of the
    // stiff twisting spring is damped out (in the paper's order it gains more per step than
    // its damping removes, and the spin ends in a stick-slip limit cycle of about ±0.7
    // rad/s, as in the original program: `tests/friction_springs.rs`).
    let mut s = sim(
        "restitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.3",
        DVec3::new(0.0, 0.0, -9.81),
        None,
        Some(FLOOR),
        vec![particle(
            DVec3::new(0.0, 0.0, R * 0.9996),
            DVec3::ZERO,
            DVec3::Z * 50.0,
        )],
    );
    // Kinetic phase: the spin falls steadily to near zero.
    let mut previous: f64 = 50.0;
    while s.particles.w[0].z > 1.0 {
        s.step().unwrap();
        let w = s.particles.w[0].z;
        assert!(w < previous, "spin grew: {w} after {previous}");
        previous = w;
    }
    // Static phase: the twisting spring's oscillation is damped out.
    let envelope = |s: &mut Simulation| {
        let mut m: f64 = 0.0;
        for _ in 0..4000 {
            s.step().unwrap();
            m = m.max(s.particles.w[0].z.abs());
        }
        m
    };
    let first = envelope(&mut s);
    let mut last = first;
    for _ in 0..10 {
        let next = envelope(&mut s);
        assert!(
            next <= last * 1.0001 + 1e-12,
            "oscillation grew from {last} to {next}"
        );
        last = next;
    }
    assert!(last < 1e-6, "still spinning at {last} rad/s");
}

#[test]
fn stokes_drag_decays_velocity_and_spin_at_their_rates() {
    let eta = 0.05;
    let mut s = sim(
        &format!("viscosity = {eta}"),
        DVec3::ZERO,
        None,
        None,
        vec![particle(DVec3::ZERO, DVec3::X, DVec3::Z * 10.0)],
    );
    let dt = s.scenario.simulation.timestep;
    let steps = 5000;
    for _ in 0..steps {
        s.step().unwrap();
    }
    let t = steps as f64 * dt;
    let c = 9.0 * eta / (2.0 * RHO * R * R); // Eq. (3)
    let gamma = 10.0 / 3.0 * c; // Eq. (4)
    let v = s.particles.v[0].x;
    let w = s.particles.w[0].z;
    // Explicit Euler decay (1 - c dt)^n approximates exp(-c t) to O(c dt).
    assert!(
        (v / (-c * t).exp() - 1.0).abs() < c * dt * c * t,
        "v {v} vs {}",
        (-c * t).exp()
    );
    assert!(
        (w / 10.0 / (-gamma * t).exp() - 1.0).abs() < gamma * dt * gamma * t,
        "w {w}"
    );
    assert!((v - (1.0 - c * dt).powi(steps)).abs() < 1e-12);
}

#[test]
fn planar_run_stays_in_its_plane() {
    // A 2D pile in the plane y = 0.01: spawned particles fall onto a floor between walls.
    let off = "OFF\n8 3 0\n-0.05 -1 0\n0.05 -1 0\n0.05 1 0\n-0.05 1 0\n-0.05 -1 0.2\n0.05 -1 0.2\n0.05 1 0.2\n-0.05 1 0.2\n\
               4 0 1 2 3\n4 0 3 7 4\n4 1 2 6 5\n";
    let dir = tempfile::tempdir().unwrap();
    let mesh_path = dir.path().join("planar.off");
    std::fs::write(&mesh_path, off).unwrap();
    let text = format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.005\nmesh = \"{}\"\nmesh_radii = [0.0]\n\
                spawn_min = [-0.04, 0.01, 0.05]\nspawn_max = [0.04, 0.01, 0.15]\n\
                [kinetics]\ninitial_velocity = [0.3, 0.0, -1.0]\n\
                [simulation]\nmax_particles = 60\nspawn_attempts = 5\n",
        mesh_path.display()
    );
    let s = common::simulate(&text, 8000);
    assert!(s.particles.len() == 60);
    assert!(s.contact_count() > 20, "the pile has contacts");
    for i in 0..s.particles.len() {
        assert!(
            (s.particles.x[i].y - 0.01).abs() < 1e-12,
            "{i}: {}",
            s.particles.x[i].y - 0.01
        );
        assert_eq!(s.particles.v[i].y, 0.0);
        assert_eq!(s.particles.w[i].x, 0.0);
        assert_eq!(s.particles.w[i].z, 0.0);
    }
}

#[test]
fn orientation_stays_unit_and_composes_world_spin_from_the_left() {
    let q0 = DQuat::from_rotation_x(PI / 2.0);
    let w = 7.0;
    let mut p = particle(DVec3::ZERO, DVec3::ZERO, DVec3::Z * w);
    p.q = q0;
    let mut s = sim("", DVec3::ZERO, None, None, vec![p]);
    let steps = 20_000;
    for _ in 0..steps {
        s.step().unwrap();
        assert!((s.particles.q[0].length() - 1.0).abs() < 1e-14);
    }
    let t = steps as f64 * s.scenario.simulation.timestep;
    let expected = DQuat::from_rotation_z(w * t) * q0;
    let q = s.particles.q[0];
    assert!(q.dot(expected).abs() > 1.0 - 1e-12, "{q:?} vs {expected:?}");
}

/// A contact that ends forgets its friction history (Table 3: springs exist only while
/// touching), also while the pair stays listed, for particle pairs and for faces; a new
/// touch starts from zero springs.
#[test]
fn contacts_forget_their_springs_when_they_end() {
    let mut s = sim(
        "restitution = 0.5\nfriction_sliding = 0.5\nfriction_rolling = 0.1\nfriction_twisting = 0.1",
        DVec3::ZERO,
        Some(1e-6),
        Some(FLOOR),
        vec![
            // A glancing, spinning collision of two grains...
            particle(
                DVec3::new(-R - 1e-5, 0.0, 0.1),
                DVec3::new(0.2, 0.05, 0.0),
                DVec3::new(0.0, 0.0, 30.0),
            ),
            particle(DVec3::new(R + 1e-5, 0.002, 0.1), DVec3::ZERO, DVec3::ZERO),
            // ...and a grain that skids along the floor and jumps off it.
            particle(
                DVec3::new(0.3, 0.0, R - 1e-5),
                DVec3::new(0.1, 0.0, 0.05),
                DVec3::new(5.0, 0.0, 0.0),
            ),
        ],
    );
    let mut touched = (false, false);
    for _ in 0..20_000 {
        s.step().unwrap();
        let snapshot = s.snapshot().unwrap();
        touched.0 |= !snapshot.pair_history.is_empty();
        touched.1 |= !snapshot.face_history.is_empty();
    }
    assert_eq!(touched, (true, true), "both contacts built up springs");
    let (pairs, faces) = s.list_slots();
    assert!(
        pairs > 0 && faces > 0,
        "still listed: {pairs} pairs, {faces} faces"
    );
    let snapshot = s.snapshot().unwrap();
    assert!(
        snapshot.pair_history.is_empty(),
        "{:?}",
        snapshot.pair_history
    );
    assert!(
        snapshot.face_history.is_empty(),
        "{:?}",
        snapshot.face_history
    );
    assert_eq!(s.contact_count(), 0);
}

/// A pair's friction springs are those of the pair, not of the storage order. Two grains
/// touch in one cell, where the lower id is stored first; one rolls over the other (its
/// sliding spring sticking) into the next cell, which then decides the order. So in one of two runs that differ only in
/// which grain has the lower id, a re-sort swaps the grains' storage order during the
/// contact. The runs agree to rounding (the sliding spring flips sign when seen from the
/// other grain; kept as seen from the lower id, it never needs to).
#[test]
fn friction_history_does_not_depend_on_the_storage_order() {
    // Grain A rests on a floor at z = -4 mm, grain B on A; B rolls over A in +x. Cells are
    // 12.5 mm wide: both start in cell (0, 0, 0), and B rolls into cell (1, 0, 0).
    let off = "OFF\n4 1 0\n-1 -1 -0.004\n1 -1 -0.004\n1 1 -0.004\n-1 1 -0.004\n4 0 1 2 3\n";
    let z = -0.004 + R * 0.9999;
    let a = particle(DVec3::new(0.01, 0.0, z), DVec3::ZERO, DVec3::ZERO);
    let b = particle(
        DVec3::new(0.01, 0.0, z + 2.0 * R * 0.9999),
        DVec3::X * 0.3,
        DVec3::Y * (0.3 / R),
    );
    let g = DVec3::new(0.0, 0.0, -9.81);
    let run = |first: Particle, second: Particle| {
        let mut s = sim(
            "restitution = 0.5\nfriction_sliding = 1.0\nfriction_rolling = 0.05",
            g,
            Some(1e-5),
            Some(off),
            vec![first, second],
        );
        // Steps at which the storage order changed while the grains touched.
        let mut swaps = 0;
        for _ in 0..3000 {
            let before = s.particles.id.clone();
            s.step().unwrap();
            let x = &s.particles.x;
            if s.particles.id != before && x[0].distance(x[1]) < 2.0 * R {
                swaps += 1;
            }
        }
        let p: Vec<Particle> = s.particles.iter_by_id().map(|(_, p)| p).collect();
        (p, swaps)
    };
    let (ab, swaps_ab) = run(a, b);
    let (ba, swaps_ba) = run(b, a);
    assert_eq!(
        (swaps_ab, swaps_ba),
        (0, 1),
        "a re-sort swaps touching grains in one run"
    );
    let (ab, ba) = ([ab[0], ab[1]], [ba[1], ba[0]]);
    assert!(
        ab[1].x.x > 0.0125 + 0.002,
        "B rolled into the next cell: {}",
        ab[1].x
    );
    for (p, q) in ab.iter().zip(&ba) {
        assert!((p.x - q.x).length() < 1e-12, "{} vs {}", p.x, q.x);
        assert!((p.v - q.v).length() < 1e-9, "{} vs {}", p.v, q.v);
        assert!((p.w - q.w).length() < 1e-6, "{} vs {}", p.w, q.w);
    }
}
