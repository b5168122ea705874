//! The cases of the contact models beyond the paper's: Hooke's impacts against the damped
//! linear oscillator and against LIGGGHTS, the rolling resistances' stopping distance, and
//! DMT's resting overlap.

use anyhow::Result;
use glam::DVec3;

use super::{Check, Setup, simulation, sphere_of};
use crate::model::contact::damping_factor;
use crate::model::integrate::Inertia;

/// LIGGGHTS 3.8's restitution and contact time of the impacts of `hooke_impact`
/// (`bench/hooke/compare.sh` with its deck `bench/hooke/in.liggghts`, `model hooke/stiffness`,
/// run 2026-12-07): (wall, e) → (e, t_c).
const LIGGGHTS: [((bool, f64), (f64, f64)); 4] = [
    ((false, 0.5), (0.500085, 1.839933e-3)),
    ((false, 0.9), (0.900044, 1.797731e-3)),
    ((true, 0.5), (0.500085, 2.602059e-3)),
    ((true, 0.9), (0.900044, 2.542376e-3)),
];

/// Head-on Hooke impacts at 1 m/s (k_n = 2000 N/m, R = 5 mm, ρ = 2500 kg/m³, t_c / 4000
/// steps), of two grains and of a grain on a floor, at e = 0.5 and 0.9: the restitution and
/// the contact time (steps with overlap x Δt) against the damped linear oscillator, e and
/// t_c = π / (ω_0 sqrt(1 - ζ²)), and against LIGGGHTS's `hooke/stiffness` run alike.
pub(super) fn hooke_impact(setup: Setup) -> Result<Vec<Check>> {
    let (k, r, rho) = (2000.0, 0.005, 2500.0);
    let m = Inertia::mass(r, rho);
    let mut checks = Vec::new();
    for ((wall, e), (e_liggghts, t_liggghts)) in LIGGGHTS {
        let m_star = if wall { m } else { 0.5 * m };
        let zeta = damping_factor(e);
        let t_c = std::f64::consts::PI / ((k / m_star).sqrt() * (1.0 - zeta * zeta).sqrt());
        let dt = t_c / 4000.0;
        let (restitution, time) = hooke_contact(setup, (k, r, rho), (wall, e), dt)?;
        let what = if wall { "wall" } else { "pair" };
        let check = |quantity: String, unit, measured, reference, tolerance| {
            Check::of(
                "hooke_impact",
                quantity,
                unit,
                (measured, reference, tolerance),
            )
        };
        checks.extend([
            check(
                format!("{what}, e = {e}: restitution"),
                "-",
                restitution,
                e,
                1e-3,
            ),
            check(
                format!("{what}, e = {e}: contact time"),
                "s",
                time,
                t_c,
                1e-3,
            ),
            check(
                format!("{what}, e = {e}: restitution vs LIGGGHTS"),
                "-",
                restitution,
                e_liggghts,
                1e-5,
            ),
            check(
                format!("{what}, e = {e}: contact time vs LIGGGHTS"),
                "s",
                time,
                t_liggghts,
                1e-5,
            ),
        ]);
    }
    Ok(checks)
}

/// One impact of `hooke_impact` (k_n, R and ρ of the grains; on a wall or not, at
/// restitution `e`; time step `dt`): its restitution and contact time.
fn hooke_contact(
    setup: Setup,
    (k, r, rho): (f64, f64, f64),
    (wall, e): (bool, f64),
    dt: f64,
) -> Result<(f64, f64)> {
    let material = format!(
        "density = {rho}\nhooke_stiffness = {k}\nrestitution = {e}\nfriction_sliding = 0.0\nfriction_rolling = 0.0"
    );
    let top = sphere_of(
        r,
        DVec3::new(0.0, 0.0, if wall { r } else { 2.0 * r } + 1e-9),
        -DVec3::Z,
    );
    let mut grains = vec![top];
    if !wall {
        grains.push(sphere_of(r, DVec3::ZERO, DVec3::ZERO));
    }
    let mut s = simulation(setup, &material, 0.0, Some(dt), wall, grains)?;
    let gap = |s: &crate::engine::Simulation| {
        let x = &s.particles.x;
        if wall {
            x[0].z - r
        } else {
            x[0].z - x[1].z - 2.0 * r
        }
    };
    let (mut steps, mut touched) = (0u64, false);
    while !touched || gap(&s) < 0.0 {
        s.step()?;
        if gap(&s) < 0.0 {
            touched = true;
            steps += 1;
        }
        anyhow::ensure!(steps < 100_000, "the grains did not part");
    }
    let v = &s.particles.v;
    let restitution = if wall { v[0].z } else { v[0].z - v[1].z };
    let time = steps as f64 * dt;
    Ok((restitution, time))
}

/// A sphere (R 5 mm, ρ 2500 kg/m³, E 100 MPa) rolling without slip at 0.1 m/s on a floor under
/// gravity with μ_r = 0.1, started at its static overlap: braked by the torque μ_r R m g
/// (`"cdt"`, and `"epsd2"` once mobilised), it stops after 7 v0² / (10 μ_r g).
pub(super) fn rolling_resistance(setup: Setup) -> Result<Vec<Check>> {
    let (r, rho, e, g, mu_r, v0) = (0.005, 2500.0, 1e8, 9.81, 0.1, 0.1);
    let m = Inertia::mass(r, rho);
    let delta = (3.0 * m * g / (4.0 * e / (1.0 - 0.09) * r.sqrt())).powf(2.0 / 3.0);
    let distance = 7.0 * v0 * v0 / (10.0 * mu_r * g);
    let mut checks = Vec::new();
    for model in ["cdt", "epsd2"] {
        let material = format!(
            "density = {rho}\nyoungs_modulus = {e:e}\npoisson_ratio = 0.3\nrestitution = 0.5\n\
             friction_sliding = 0.8\nfriction_rolling = {mu_r}\nfriction_twisting = 0.0\n\
             rolling_model = \"{model}\""
        );
        let mut ball = sphere_of(r, DVec3::new(0.0, 0.0, r - delta), DVec3::X * v0);
        ball.w = DVec3::Y * (v0 / r);
        let mut s = simulation(setup, &material, -g, Some(2e-6), true, vec![ball])?;
        while s.particles.v[0].x > 0.0 {
            s.step()?;
            anyhow::ensure!(s.time < 1.0, "{model}: still rolling after 1 s");
        }
        checks.push(Check::of(
            "rolling_resistance",
            format!("rolling_model = \"{model}\": stopping distance"),
            "m",
            (s.particles.x[0].x, distance, 1e-2),
        ));
    }
    Ok(checks)
}

/// Two grains (R 5 mm, E 10 MPa, ν 0.3) at rest with DMT's pull 2 π γ R* (γ = 0.05 J/m²,
/// R* = R/2) settle where Hertz's force balances it: δ = (3 π γ R* / (2 E* sqrt(R*)))^(2/3).
pub(super) fn dmt_contact(setup: Setup) -> Result<Vec<Check>> {
    let (r, e, gamma) = (0.005, 1e7, 0.05);
    let (e_star, r_star) = (e / (2.0 * (1.0 - 0.09)), r / 2.0);
    let pull = 2.0 * std::f64::consts::PI * gamma * r_star;
    let delta = (3.0 * pull / (4.0 * e_star * r_star.sqrt())).powf(2.0 / 3.0);
    let material = format!(
        "density = 2500.0\nyoungs_modulus = {e:e}\npoisson_ratio = 0.3\nrestitution = 0.3\n\
         adhesion_model = \"dmt\"\nsurface_energy = {gamma}"
    );
    let pair = vec![
        sphere_of(r, DVec3::new(-r + 1e-7, 0.0, 0.0), DVec3::ZERO),
        sphere_of(r, DVec3::new(r - 1e-7, 0.0, 0.0), DVec3::ZERO),
    ];
    let mut s = simulation(setup, &material, 0.0, Some(1e-6), false, pair)?;
    for _ in 0..100_000 {
        s.step()?;
    }
    let overlap = 2.0 * r - (s.particles.x[1] - s.particles.x[0]).length();
    Ok(vec![Check::of(
        "dmt_contact",
        "resting overlap of two grains",
        "m",
        (overlap, delta, 1e-3),
    )])
}
