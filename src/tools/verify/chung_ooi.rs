//! Chung & Ooi's (2011, Granular Matter 13:643) benchmark tests with their materials and
//! speeds (as the published test scripts set them), against the analytic solutions their
//! figures show: test 1 (two identical spheres, Hertz), test 3 (restitution on a rigid plane)
//! and test 4 (oblique impacts on a rigid plane in gross sliding). Test 2 is in `contacts.rs`.

use anyhow::Result;
use glam::DVec3;

use super::{Check, Setup, hertz_checks, simulation, sphere_of};
use crate::model::integrate::Inertia;

/// Test 1: two identical spheres of radius 10 mm meet head-on at 10 m/s each, elastic, of
/// glass (E = 48 GPa, ν = 0.20, ρ = 2800 kg/m³) and of limestone (20 GPa, 0.25, 2500 kg/m³).
/// Their figure is Hertz's force-overlap curve; checked: its peak overlap and force (force as
/// m dv/dt of one sphere) and the contact time, with m* = m/2, R* = R/2, E* = E / (2 (1 - ν²))
/// and the approach speed 20 m/s.
pub(super) fn chung_ooi_1(setup: Setup) -> Result<Vec<Check>> {
    let (r, v, dt) = (0.010, 10.0, 1e-9);
    let mut checks = Vec::new();
    for (name, e, nu, rho) in [
        ("glass", 4.8e10, 0.20, 2800.0),
        ("limestone", 2.0e10, 0.25, 2500.0),
    ] {
        let material = format!(
            "density = {rho:e}\nyoungs_modulus = {e:e}\npoisson_ratio = {nu}\n\
             restitution = 1.0\nfriction_sliding = 0.35\nfriction_rolling = 0.0"
        );
        let grains = vec![
            sphere_of(r, DVec3::new(-r - 1e-8, 0.0, 0.0), DVec3::X * v),
            sphere_of(r, DVec3::new(r + 1e-8, 0.0, 0.0), -DVec3::X * v),
        ];
        let mut s = simulation(setup, &material, 0.0, Some(dt), false, grains)?;
        let m = Inertia::mass(r, rho);
        let (mut steps, mut peak_overlap, mut peak_force, mut touched) =
            (0u64, 0.0f64, 0.0f64, false);
        for _ in 0..10_000_000 {
            let v_before = s.particles.v[0].x;
            s.step()?;
            let delta = 2.0 * r - (s.particles.x[1].x - s.particles.x[0].x);
            if delta > 0.0 {
                touched = true;
                steps += 1;
                peak_overlap = peak_overlap.max(delta);
                peak_force = peak_force.max(m * (v_before - s.particles.v[0].x) / dt);
            } else if touched {
                break;
            }
        }
        let (e_star, r_star, m_star, v0) = (e / (2.0 * (1.0 - nu * nu)), r / 2.0, m / 2.0, 2.0 * v);
        let measured = (peak_overlap, peak_force, steps as f64 * dt);
        let label = ("chung_ooi_1", name);
        checks.extend(hertz_checks(label, measured, (e_star, r_star, m_star, v0)));
    }
    Ok(checks)
}

/// Test 3: a sphere of radius 2.5 mm meets a rigid plane at 3.9 m/s, frictionless, of
/// aluminium oxide (E = 380 GPa, ν = 0.23, ρ = 4000 kg/m³) and of cast iron (100 GPa, 0.25,
/// 7000 kg/m³), with e = 0.2, 0.4, 0.6, 0.8 and 1.0: the rebound speed over the impact speed
/// against the restitution asked for (their figure's diagonal).
pub(super) fn chung_ooi_3(setup: Setup) -> Result<Vec<Check>> {
    let (r, v0, dt) = (0.0025, 3.9, 2e-9);
    let mut checks = Vec::new();
    for (name, e, nu, rho) in [
        ("aluminium oxide", 3.8e11, 0.23, 4000.0),
        ("cast iron", 1.0e11, 0.25, 7000.0),
    ] {
        for e_n in [0.2, 0.4, 0.6, 0.8, 1.0] {
            let material = format!(
                "density = {rho:e}\nyoungs_modulus = {e:e}\npoisson_ratio = {nu}\n\
                 restitution = {e_n}\nfriction_sliding = 0.0\nfriction_rolling = 0.0"
            );
            let s = off_the_plane(setup, &material, dt, (r, -DVec3::Z * v0))?;
            checks.push(Check::of(
                "chung_ooi_3",
                format!("{name}, e = {e_n}: restitution"),
                "-",
                (s.particles.v[0].z / v0, e_n, 1e-3),
            ));
        }
    }
    Ok(checks)
}

/// Test 4: a sphere of aluminium oxide (R = 2.5 mm, E = 380 GPa, ν = 0.23, ρ = 4000 kg/m³,
/// μ = 0.092, e = 0.98) meets a rigid plane at 3.9 m/s, at angles θ from the normal. Past
/// tan θ = 7/2 μ (1 + e) (32.5°) it slides throughout: the tangential restitution v_t'/v_t =
/// 1 - μ (1 + e) cot θ and the spin ω' R = 5/2 μ (1 + e) v_n (Chung & Ooi's figures, and
/// Maw, Barber & Fawcett's gross-sliding regime). Checked at 40° to 80°; at smaller angles
/// the tangential compliance rules (Maw et al.'s curves, not in closed form): not checked.
/// The spin comes out short by up to 1e-3: friction acts at the contact point, r_i = R - δ/2
/// from the centre (Eq. 29), not at R.
pub(super) fn chung_ooi_4(setup: Setup) -> Result<Vec<Check>> {
    let (r, speed, mu, e_n, dt) = (0.0025, 3.9, 0.092, 0.98, 2e-9);
    let material = format!(
        "density = 4000.0\nyoungs_modulus = 3.8e11\npoisson_ratio = 0.23\nrestitution = {e_n}\n\
         friction_sliding = {mu}\nfriction_rolling = 0.0\nfriction_twisting = 0.0"
    );
    let mut checks = Vec::new();
    for degrees in [40.0f64, 50.0, 60.0, 70.0, 80.0] {
        let theta = degrees.to_radians();
        let (v_n, v_t) = (speed * theta.cos(), speed * theta.sin());
        let s = off_the_plane(setup, &material, dt, (r, DVec3::new(v_t, 0.0, -v_n)))?;
        let impulse = mu * (1.0 + e_n) * v_n;
        let check = |quantity: &str, unit, tinydem, reference, tolerance| {
            let quantity = format!("{degrees}°: {quantity}");
            Check::of(
                "chung_ooi_4",
                quantity,
                unit,
                (tinydem, reference, tolerance),
            )
        };
        let (e_t, spin) = (s.particles.v[0].x / v_t, s.particles.w[0].y);
        checks.extend([
            check(
                "tangential restitution",
                "-",
                e_t,
                1.0 - impulse / v_t,
                2e-4,
            ),
            check("spin after", "rad/s", spin, 2.5 * impulse / r, 2e-3),
        ]);
    }
    Ok(checks)
}

/// A sphere of radius `r` touching a plane at velocity `v` (of `material`, time step `dt`),
/// stepped until it leaves the plane again.
fn off_the_plane(
    setup: Setup,
    material: &str,
    dt: f64,
    (r, v): (f64, DVec3),
) -> Result<crate::engine::Simulation> {
    let ball = sphere_of(r, DVec3::new(0.0, 0.0, r + 1e-9), v);
    let mut s = simulation(setup, material, 0.0, Some(dt), true, vec![ball])?;
    let mut touched = false;
    for _ in 0..10_000_000 {
        s.step()?;
        if s.particles.x[0].z < r {
            touched = true;
        } else if touched {
            break;
        }
    }
    Ok(s)
}
