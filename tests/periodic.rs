//! Periodic domains: a pair that touches across a periodic side behaves as the same pair
//! inside the box; a periodic gas keeps its particles and its momentum; a periodic run
//! resumes bit for bit.

use crate::common;

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};

const R: f64 = 0.004;

fn grain(x: DVec3, v: DVec3, w: DVec3) -> Particle {
    Particle {
        x,
        radius: R,
        v,
        q: DQuat::IDENTITY,
        w,
        tag: 0,
        material: 0,
        fixed: false,
        body: None,
        ..Particle::default()
    }
}

fn periodic(particles: Vec<Particle>, extra: &str) -> Simulation {
    let s = common::scenario(&format!(
        "[geometry]\nradius_min = {R}\nradius_max = {R}\n\
         [material]\nfriction_sliding = 0.5\nfriction_rolling = 0.2\n\
         [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\ntimestep = 1e-5\nmax_particles = 0\nspawn_attempts = 0\n\
         [domain]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.05]\nperiodic = [true, true, true]\n{extra}"
    ));
    Simulation::from_parts(
        s,
        Default::default(),
        particles.into_iter().collect::<Particles>(),
    )
    .unwrap()
}

/// An oblique, spinning collision: at `o` inside the box, or across the corner of the box.
fn collision(o: DVec3) -> Simulation {
    let d = DVec3::new(R + 2e-5, 0.3 * R, -0.2 * R);
    periodic(
        vec![
            grain(o - d, DVec3::new(0.4, 0.05, 0.0), DVec3::new(0.0, 5.0, 1.0)),
            grain(
                o + d,
                DVec3::new(-0.3, 0.0, 0.02),
                DVec3::new(2.0, 0.0, -3.0),
            ),
        ],
        "",
    )
}

#[test]
fn a_pair_across_a_periodic_side_equals_the_pair_inside() {
    let mut inside = collision(DVec3::new(0.01, -0.02, 0.0));
    let mut across = collision(DVec3::new(0.05, 0.05, -0.05)); // a corner: three sides
    let mut touched = 0;
    for step in 0..3000 {
        inside.step().unwrap();
        across.step().unwrap();
        touched += (inside.contact_count() > 0) as u32;
        assert_eq!(
            inside.contact_count(),
            across.contact_count(),
            "step {step}"
        );
        // The contact network sees the pair across the sides too, with the same force.
        let (a, b) = (inside.contact_network(), across.contact_network());
        assert_eq!(a.len(), b.len(), "step {step}");
        for (a, b) in a.iter().zip(&b) {
            assert!((a.f_n - b.f_n).length() <= 1e-9 * a.f_n.length().max(1e-12));
        }
        let state = |s: &Simulation| {
            let p: Vec<_> = s.particles.iter_by_id().map(|(_, q)| q).collect();
            let period = |d: DVec3| d - (d / 0.1).round() * 0.1;
            (period(p[1].x - p[0].x), p[0].v, p[1].v, p[0].w, p[1].w)
        };
        let (a, b) = (state(&inside), state(&across));
        let close = |x: DVec3, y: DVec3, scale: f64| (x - y).length() <= 1e-12 * scale;
        assert!(
            close(a.0, b.0, 0.1),
            "step {step}: separation {} vs {}",
            a.0,
            b.0
        );
        for (x, y) in [(a.1, b.1), (a.2, b.2)] {
            assert!(close(x, y, 1.0), "step {step}: velocity {x} vs {y}");
        }
        for (x, y) in [(a.3, b.3), (a.4, b.4)] {
            assert!(close(x, y, 100.0), "step {step}: spin {x} vs {y}");
        }
    }
    assert!(
        touched > 100,
        "the grains collided ({touched} steps in contact)"
    );
}

/// A dense periodic gas: nothing leaves, momentum stays, frames lie in the box.
fn gas() -> Vec<Particle> {
    let mut p = Vec::new();
    let mut k = 0u32;
    for i in 0..8 {
        for j in 0..8 {
            for l in 0..8 {
                let x = DVec3::new(i as f64, j as f64, l as f64) * 0.0125 - DVec3::splat(0.045);
                let h = |m: u32| {
                    ((k.wrapping_mul(2654435761).wrapping_add(m) >> 8) % 1000) as f64 / 1000.0 - 0.5
                };
                p.push(grain(
                    x,
                    DVec3::new(h(1), h(2), h(3)),
                    DVec3::new(h(4), h(5), h(6)) * 50.0,
                ));
                k += 1;
            }
        }
    }
    p
}

#[test]
fn a_periodic_gas_keeps_its_particles_and_momentum() {
    let mut s = periodic(gas(), "");
    let momentum = |s: &Simulation| -> DVec3 {
        let m = Inertia::mass(R, 1000.0);
        s.particles.v.iter().map(|v| *v * m).sum()
    };
    let p0 = momentum(&s);
    let mut contacts = 0;
    for _ in 0..4000 {
        s.step().unwrap();
        contacts = contacts.max(s.contact_count());
    }
    assert_eq!(s.particles.len(), 512);
    assert_eq!(s.removed.count(), 0);
    let scale = Inertia::mass(R, 1000.0) * 512.0;
    assert!(
        (momentum(&s) - p0).length() < 1e-12 * scale,
        "{} vs {p0}",
        momentum(&s)
    );
    let inside = s.particles_in_domain();
    assert!(
        inside
            .x
            .iter()
            .all(|x| x.cmpge(DVec3::splat(-0.05)).all() && x.cmplt(DVec3::splat(0.05)).all())
    );
    assert!(s.particles.x.iter().any(|x| x.abs().max_element() > 0.05) || s.rebuilds() > 0);
    assert!(contacts > 10);
}

#[test]
fn a_periodic_run_resumes_bit_for_bit() {
    let mut whole = periodic(gas(), "");
    let mut first = periodic(gas(), "");
    for _ in 0..1500 {
        whole.step().unwrap();
        first.step().unwrap();
    }
    let snapshot = first.snapshot().unwrap();
    let mut resumed = Simulation::restore(first.scenario.clone(), snapshot).unwrap();
    for _ in 0..1500 {
        whole.step().unwrap();
        resumed.step().unwrap();
    }
    assert!(
        whole.particles == resumed.particles,
        "the resumed run differs"
    );
}

/// Spawning into a periodic box sees the images: no grain starts overlapping another across
/// a side.
#[test]
fn spawned_grains_do_not_overlap_across_periodic_sides() {
    let mut s = common::simulate(
        &format!(
            "[geometry]\nradius_min = {R}\nradius_max = {R}\n\
             [kinetics]\ngravity = [0.0, 0.0, 0.0]\ninitial_velocity = [0.0, 0.0, 0.0]\n\
             [simulation]\nmax_particles = 900\nspawn_attempts = 20000\n\
             [domain]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.05]\nperiodic = [true, true, true]\n\
             [[spawn]]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.05]\ncount = 900\n"
        ),
        0,
    );
    s.step().unwrap();
    let x = &s.particles.x;
    assert!(x.len() > 600, "{} grains", x.len());
    let period = |d: DVec3| d - (d / 0.1).round() * 0.1;
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            let d = period(x[i] - x[j]).length();
            assert!(
                d >= 2.0 * R * (1.0 - 1e-9),
                "grains {i} and {j} overlap: {d}"
            );
        }
    }
}

/// Lees-Edwards boundaries across z sliding along x at V: a gas that starts without mean
/// flow takes up the imposed profile v_x(z) = V (z - z_0) / L_z.
#[test]
fn lees_edwards_boundaries_impose_the_shear_profile() {
    let v = 0.5;
    let mut s = periodic(
        gas(),
        &format!(
            "lees_edwards = {{ velocity = {v}, shear_axis = \"x\", gradient_axis = \"z\" }}\n"
        ),
    );
    for _ in 0..30_000 {
        s.step().unwrap();
    }
    // The profile, averaged over the last 10,000 steps in 5 layers.
    let mut sum = [0.0; 5];
    let mut count = [0usize; 5];
    for step in 0..10_000 {
        s.step().unwrap();
        if step % 100 == 0 {
            let p = s.particles_in_domain();
            for (x, u) in p.x.iter().zip(&p.v) {
                let k = (((x.z + 0.05) / 0.02) as usize).min(4);
                sum[k] += u.x;
                count[k] += 1;
            }
        }
    }
    let profile: Vec<f64> = (0..5).map(|k| sum[k] / count[k] as f64).collect();
    // Least-squares slope against the layer centres.
    let z: Vec<f64> = (0..5).map(|k| -0.04 + 0.02 * k as f64).collect();
    let slope = z.iter().zip(&profile).map(|(z, u)| z * u).sum::<f64>()
        / z.iter().map(|z| z * z).sum::<f64>();
    assert!(
        (slope / (v / 0.1) - 1.0).abs() < 0.15,
        "slope {slope} 1/s, imposed {} 1/s; profile {profile:?}",
        v / 0.1
    );
    assert_eq!(s.particles.len(), 512);
}

/// Across the sheared sides the image moves: a grain at rest near the top is struck by the
/// image of a grain at rest near the bottom, which slides past at V.
#[test]
fn the_image_across_a_sheared_side_moves_with_the_shear_velocity() {
    let v = 0.5;
    let mut s = periodic(
        vec![
            grain(DVec3::new(0.0, 0.0, 0.047), DVec3::ZERO, DVec3::ZERO),
            grain(DVec3::new(-0.012, 0.0, -0.047), DVec3::ZERO, DVec3::ZERO),
        ],
        &format!(
            "lees_edwards = {{ velocity = {v}, shear_axis = \"x\", gradient_axis = \"z\" }}\n"
        ),
    );
    for _ in 0..6000 {
        s.step().unwrap();
    }
    let p: Vec<_> = s.particles.iter_by_id().map(|(_, q)| q).collect();
    // The top grain is pushed along +x and down (the image of the other is above it, across
    // the upper side), the bottom one along -x and up.
    assert!(p[0].v.x > 0.1 * v && p[0].v.z < 0.0, "top grain {}", p[0].v);
    assert!(
        p[1].v.x < -0.1 * v && p[1].v.z > 0.0,
        "bottom grain {}",
        p[1].v
    );
    // In the frame of the collision momentum is kept: equal and opposite changes.
    assert!((p[0].v + p[1].v).length() < 1e-9, "{} {}", p[0].v, p[1].v);
}
