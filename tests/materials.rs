//! Several materials: restitution per material pair (own, given, mean), the Hertz contact
//! time with E* of two materials, momentum with two densities, walls of a material, and the
//! lanes of a mixed group giving each pair the bits it has alone.

use crate::common;

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};

const R: f64 = 0.005;

/// Glass, rubber and steel; glass-rubber and glass-steel (elastic) restitution given,
/// rubber-steel the mean.
const MATERIALS: &str = "\
[[materials]]\nname = \"glass\"\ndensity = 2500.0\nyoungs_modulus = 1e7\npoisson_ratio = 0.25\nrestitution = 0.9\n\
[[materials]]\nname = \"rubber\"\ndensity = 1100.0\nyoungs_modulus = 1e6\npoisson_ratio = 0.45\nrestitution = 0.3\nfriction_sliding = 0.8\n\
[[materials]]\nname = \"steel\"\ndensity = 7800.0\nyoungs_modulus = 2e7\nrestitution = 0.5\n\
[[interactions]]\nmaterials = [\"rubber\", \"glass\"]\nrestitution = 0.6\n\
[[interactions]]\nmaterials = [\"glass\", \"steel\"]\nrestitution = 1.0\n";

fn grain(x: DVec3, v: DVec3, material: u16) -> Particle {
    Particle {
        x,
        radius: R,
        v,
        q: DQuat::IDENTITY,
        w: DVec3::ZERO,
        tag: 0,
        material,
        fixed: false,
        body: None,
        ..Particle::default()
    }
}

fn sim(extra: &str, mesh: Option<&str>, particles: Vec<Particle>) -> Simulation {
    let s = common::scenario(&format!(
        "{MATERIALS}{extra}\n[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
         [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\ntimestep = 2e-7\nmax_particles = 0\nspawn_attempts = 0\n"
    ));
    let mesh = mesh.map_or_else(Mesh::default, |t| {
        Mesh::parse_off(t, "test mesh", &s.geometry.mesh_radii).unwrap()
    });
    Simulation::from_parts(s, mesh, particles.into_iter().collect::<Particles>()).unwrap()
}

/// A head-on collision of grains of materials `a` and `b` at relative speed `v0`: the
/// coefficient of restitution, the contact time and both final velocities.
fn head_on(a: u16, b: u16, v0: f64) -> (f64, f64, DVec3, DVec3) {
    let mut s = sim(
        "",
        None,
        vec![
            grain(DVec3::new(-R - 1e-5, 0.0, 0.0), DVec3::X * v0 / 2.0, a),
            grain(DVec3::new(R + 1e-5, 0.0, 0.0), -DVec3::X * v0 / 2.0, b),
        ],
    );
    let dt = s.scenario.simulation.timestep;
    let gap = |s: &Simulation| {
        let p = &s.particles;
        let (i, j) = if p.id[0] == 0 { (0, 1) } else { (1, 0) };
        (p.x[j].x - p.x[i].x, p.v[i], p.v[j])
    };
    while gap(&s).0 >= 2.0 * R {
        s.step().unwrap();
    }
    let mut steps = 0;
    while gap(&s).0 < 2.0 * R {
        s.step().unwrap();
        steps += 1;
    }
    let (_, vi, vj) = gap(&s);
    ((vj.x - vi.x) / v0, steps as f64 * dt, vi, vj)
}

#[test]
fn restitution_is_that_of_the_material_pair() {
    // Own, given by [[interactions]] (in either order), the mean of the two.
    for (a, b, e) in [
        (0, 0, 0.9),
        (1, 1, 0.3),
        (0, 1, 0.6),
        (1, 0, 0.6),
        (0, 2, 1.0),
        (1, 2, 0.4),
    ] {
        let (measured, ..) = head_on(a, b, 0.5);
        assert!(
            (measured - e).abs() < 0.03,
            "materials {a}, {b}: restitution {measured}, expected {e}"
        );
    }
}

#[test]
fn two_materials_collide_with_the_hertz_time_of_their_combined_modulus() {
    let v0 = 0.2;
    let (_, t_c, vi, vj) = head_on(0, 2, v0);
    let m = |rho: f64| Inertia::mass(R, rho);
    let (m_i, m_j) = (m(2500.0), m(7800.0));
    let m_star = m_i * m_j / (m_i + m_j);
    let r_star = R / 2.0;
    let e_star = 1.0 / ((1.0 - 0.25f64.powi(2)) / 1e7 + (1.0 - 0.3f64.powi(2)) / 2e7);
    // Hertz for an elastic impact (the pair's e_n is 1).
    let elastic = 2.868_265 * (m_star * m_star / (r_star * e_star * e_star * v0)).powf(0.2);
    assert!(
        (t_c / elastic - 1.0).abs() < 2e-3,
        "t_c {t_c} vs Hertz {elastic}"
    );
    // Momentum is conserved with the two densities.
    let p0 = (m_i - m_j) * v0 / 2.0;
    let p1 = m_i * vi.x + m_j * vj.x;
    assert!((p1 - p0).abs() < 1e-9 * m_j * v0, "{p1} vs {p0}");
}

#[test]
fn a_wall_of_a_material_gives_the_pair_restitution() {
    let floor = "OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n";
    for (grain_material, wall, e) in [(0u16, "glass", 0.9), (0, "rubber", 0.6), (1, "steel", 0.4)] {
        let text = format!(
            "{MATERIALS}\n[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\nmesh_material = \"{wall}\"\n\
             [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
             [simulation]\ntimestep = 2e-7\nmax_particles = 0\nspawn_attempts = 0\n"
        );
        let sc = common::scenario(&text);
        let mesh = Mesh::parse_off(floor, "floor", &sc.geometry.mesh_radii).unwrap();
        let p: Particles = [grain(
            DVec3::new(0.0, 0.0, R + 1e-5),
            DVec3::new(0.0, 0.0, -0.3),
            grain_material,
        )]
        .into_iter()
        .collect();
        let mut s = Simulation::from_parts(sc, mesh, p).unwrap();
        while s.particles.v[0].z < 0.0 || s.particles.x[0].z < R {
            s.step().unwrap();
        }
        let measured = s.particles.v[0].z / 0.3;
        assert!(
            (measured - e).abs() < 0.03,
            "grain {grain_material} on {wall}: {measured}, expected {e}"
        );
    }
}

/// Twelve pairs of every combination of materials, far apart, collide at once: each moves
/// with the bits it has alone (the lanes gather each pair's own coefficients and masses).
#[test]
fn pairs_of_mixed_materials_in_lanes_move_as_alone() {
    let pair = |k: usize| -> Vec<Particle> {
        let (a, b) = ((k % 3) as u16, ((k / 3) % 3) as u16);
        let o = DVec3::new(0.1 * k as f64, 0.0, 0.0);
        let spin = DVec3::new(0.0, 3.0 * k as f64, 1.0);
        vec![
            Particle {
                w: spin,
                ..grain(
                    o - DVec3::X * (R + 1e-5),
                    DVec3::new(0.3, 0.01 * k as f64, 0.0),
                    a,
                )
            },
            grain(
                o + DVec3::new(R + 1e-5, 0.002, 0.0),
                DVec3::new(-0.2, 0.0, 0.0),
                b,
            ),
        ]
    };
    let run = |particles: Vec<Particle>| {
        let mut s = sim("", None, particles);
        for _ in 0..800 {
            s.step().unwrap();
        }
        s.particles
            .iter_by_id()
            .map(|(_, q)| (q.x, q.v, q.w, q.q))
            .collect::<Vec<_>>()
    };
    let together = run((0..12).flat_map(pair).collect());
    for k in 0..12 {
        let alone = run(pair(k));
        assert!(
            alone[..] == together[2 * k..2 * k + 2],
            "pair {k} moves differently among the others"
        );
    }
}
