//! The cases of single contacts: Hertz's impacts, restitution, free fall, wall impacts,
//! Chung & Ooi's test 2, the slip-to-rolling limit and stacked spheres at rest.

use anyhow::Result;
use glam::DVec3;

use super::*;
use crate::model::integrate::Inertia;

/// What a head-on impact of two spheres at relative speed `v0` shows: restitution, contact
/// time, peak overlap and peak force (from sphere 1's change of momentum per step).
struct Impact {
    restitution: f64,
    contact_time: f64,
    peak_overlap: f64,
    peak_force: f64,
}

fn impact(setup: Setup, e_n: f64, v0: f64) -> Result<Impact> {
    let gap = 1e-5;
    let mut s = simulation(
        setup,
        &format!("restitution = {e_n}\nfriction_sliding = 0.3"),
        0.0,
        Some(1e-7),
        false,
        vec![
            sphere(DVec3::new(-R - gap, 0.0, 0.0), DVec3::X * v0 / 2.0),
            sphere(DVec3::new(R + gap, 0.0, 0.0), -DVec3::X * v0 / 2.0),
        ],
    )?;
    let dt = s.scenario.simulation.timestep;
    let m = Inertia::mass(R, RHO);
    let overlap = |s: &Simulation| 2.0 * R - (s.particles.x[1] - s.particles.x[0]).length();
    let (mut steps_in_contact, mut peak_overlap, mut peak_force) = (0u64, 0.0f64, 0.0f64);
    let mut touched = false;
    for _ in 0..10_000_000 {
        let v_before = s.particles.v[1].x;
        s.step()?;
        let delta = overlap(&s);
        if delta > 0.0 {
            touched = true;
            steps_in_contact += 1;
            peak_overlap = peak_overlap.max(delta);
            peak_force = peak_force.max(m * (s.particles.v[1].x - v_before) / dt);
        } else if touched {
            break;
        }
    }
    Ok(Impact {
        restitution: (s.particles.v[1].x - s.particles.v[0].x) / v0,
        contact_time: steps_in_contact as f64 * dt,
        peak_overlap,
        peak_force,
    })
}

/// Hertz's elastic impact: with F = 4/3 E* sqrt(R*) δ^(3/2), the peak overlap
/// δ_m = (15 m* v0² / (16 E* sqrt(R*)))^(2/5) and the contact time
/// t_c = 2 δ_m / v0 ∫₀¹ dx / sqrt(1 - x^(5/2)) = 2.94328 δ_m / v0 (Johnson 1985, Sec. 11.4).
pub(super) fn hertz_impact(setup: Setup) -> Result<Vec<Check>> {
    let v0 = 0.5;
    let got = impact(setup, 1.0, v0)?;
    let m_star = Inertia::mass(R, RHO) / 2.0;
    let (r_star, e_star) = (R / 2.0, E / (2.0 * (1.0 - NU * NU)));
    let delta_m = (15.0 * m_star * v0 * v0 / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let check = |quantity: &str, unit, tinydem, reference, tolerance| {
        Check::of(
            "hertz_impact",
            quantity,
            unit,
            (tinydem, reference, tolerance),
        )
    };
    Ok(vec![
        check("peak overlap", "m", got.peak_overlap, delta_m, 1e-4),
        check(
            "peak force",
            "N",
            got.peak_force,
            4.0 / 3.0 * e_star * r_star.sqrt() * delta_m.powf(1.5),
            1e-4,
        ),
        check(
            "contact time",
            "s",
            got.contact_time,
            2.0 * 1.471_637_6 * delta_m / v0,
            5e-4, // the time step is 5e-5 of it
        ),
        check("restitution (elastic)", "-", got.restitution, 1.0, 1e-4),
    ])
}

/// The damping of Eq. (18) with β of Eq. (21) gives e_n independent of the impact speed
/// (the damped Hertz oscillator's restitution depends on β alone).
pub(super) fn restitution(setup: Setup) -> Result<Vec<Check>> {
    let mut checks = Vec::new();
    for e_n in [0.2, 0.5, 0.8] {
        for v0 in [0.1, 1.0] {
            let e = impact(setup, e_n, v0)?.restitution;
            let quantity = format!("e at e_n = {e_n}, v0 = {v0} m/s");
            checks.push(Check::of("restitution", quantity, "-", (e, e_n, 1e-3)));
        }
    }
    Ok(checks)
}

/// A sphere dropped from rest with its lowest point h = 50 mm above a floor (MFIX-DEM's first
/// case, Garg et al. 2012): it touches after sqrt(2 h / g) at sqrt(2 g h), and with
/// restitution e rises again to e² h: e is that of a free impact, and gravity acting
/// through the 2 ms contact takes a little from the rebound (3.6e-3 of the height here).
pub(super) fn free_fall(setup: Setup) -> Result<Vec<Check>> {
    let (g, h, e_n, dt) = (9.81, 0.05, 0.8, 1e-6);
    let mut s = simulation(
        setup,
        &format!("restitution = {e_n}\nfriction_sliding = 0.3"),
        -g,
        Some(dt),
        true,
        vec![sphere(DVec3::new(0.0, 0.0, R + h), DVec3::ZERO)],
    )?;
    let mut steps = 0u64;
    while s.particles.x[0].z >= R {
        s.step()?;
        steps += 1;
    }
    // The moment the lowest point crossed z = 0, between the last two steps.
    let (z, v) = (s.particles.x[0].z, s.particles.v[0].z);
    let touch = steps as f64 * dt - (R - z) / -v;
    let speed = -v;
    while s.particles.v[0].z <= 0.0 || s.particles.x[0].z < R {
        s.step()?;
    }
    let mut apex = s.particles.x[0].z;
    while s.particles.v[0].z > 0.0 {
        s.step()?;
        apex = apex.max(s.particles.x[0].z);
    }
    let check = |quantity: &str, unit, tinydem, reference, tolerance| {
        Check::of("free_fall", quantity, unit, (tinydem, reference, tolerance))
    };
    Ok(vec![
        check("time to touch", "s", touch, (2.0 * h / g).sqrt(), 1e-4),
        check("impact speed", "m/s", speed, (2.0 * g * h).sqrt(), 1e-4),
        check("rebound height", "m", apex - R, e_n * e_n * h, 5e-3),
    ])
}

/// A sphere falling onto a rigid floor, without gravity. Normal at 0.5 m/s, elastic: Hertz
/// with m* = m, R* = R and the wall's E* = E / (1 - ν²). Oblique (v_n = 0.2 m/s, v_t = 1
/// m/s, μ = 0.3, elastic, a grain 1000 times stiffer so that the overlap stays below 0.5 %
/// of R), in gross sliding (2 μ v_n < 2/7 v_t: the contact point slides throughout): the
/// friction impulse is μ times the normal one, 2 m v_n, so v_t' = v_t - 2 μ v_n and
/// ω' R = 5 μ v_n (Maw, Barber & Fawcett 1976, their regime of large incidence). The lever
/// of the friction force is the distance to the contact point, R - δ: the spin falls short
/// of the rigid limit by about the mean δ / R, hence its tolerance.
pub(super) fn wall_impact(setup: Setup) -> Result<Vec<Check>> {
    let bounce = |material: &str, v: DVec3| -> Result<(Simulation, u64)> {
        let at = DVec3::new(0.0, 0.0, R + 1e-6);
        let mut s = simulation(setup, material, 0.0, Some(1e-7), true, vec![sphere(at, v)])?;
        let mut steps_in_contact = 0;
        let mut touched = false;
        for _ in 0..10_000_000 {
            s.step()?;
            if s.particles.x[0].z < R {
                touched = true;
                steps_in_contact += 1;
            } else if touched {
                break;
            }
        }
        Ok((s, steps_in_contact))
    };
    let v0 = 0.5;
    let (s, steps) = bounce("restitution = 1.0", -DVec3::Z * v0)?;
    let m = Inertia::mass(R, RHO);
    let e_wall = E / (1.0 - NU * NU);
    let delta_m = (15.0 * m * v0 * v0 / (16.0 * e_wall * R.sqrt())).powf(0.4);
    let t_c = steps as f64 * s.scenario.simulation.timestep;
    let (v_n, v_t, mu) = (0.2, 1.0, 0.3);
    let material = format!(
        "youngs_modulus = {:e}\nrestitution = 1.0\nfriction_sliding = {mu}\nfriction_rolling = 0.0",
        1000.0 * E
    );
    let (oblique, _) = bounce(&material, DVec3::new(v_t, 0.0, -v_n))?;
    let check = |quantity: &str, unit, tinydem, reference, tolerance| {
        Check::of(
            "wall_impact",
            quantity,
            unit,
            (tinydem, reference, tolerance),
        )
    };
    let impulse = 2.0 * mu * v_n;
    Ok(vec![
        check(
            "contact time",
            "s",
            t_c,
            2.0 * 1.471_637_6 * delta_m / v0,
            5e-4,
        ),
        check(
            "rebound speed (elastic)",
            "m/s",
            s.particles.v[0].z,
            v0,
            1e-4,
        ),
        check(
            "oblique: tangential speed after",
            "m/s",
            oblique.particles.v[0].x,
            v_t - impulse,
            1e-3,
        ),
        check(
            "oblique: spin times R after",
            "m/s",
            oblique.particles.w[0].y * R,
            2.5 * impulse,
            2e-3,
        ),
    ])
}

/// Chung & Ooi (2011), test 2: a sphere of radius 0.1 m meets a rigid plane at 0.2 m/s,
/// elastic and frictionless, of aluminium alloy (E = 70 GPa, ν = 0.30, ρ = 2699 kg/m³) and
/// of magnesium alloy (40 GPa, 0.35, 1800 kg/m³). Their figure is the force-overlap curve of
/// Hertz's solution; checked here: its peak overlap and force (force as m dv/dt) and the
/// contact time, with m* = m, R* = R, E* = E / (1 - ν²).
pub(super) fn chung_ooi_2(setup: Setup) -> Result<Vec<Check>> {
    let (r, v0, dt) = (0.1, 0.2, 1e-7);
    let mut checks = Vec::new();
    for (name, e, nu, rho) in [
        ("aluminium alloy", 7.0e10, 0.30, 2699.0),
        ("magnesium alloy", 4.0e10, 0.35, 1800.0),
    ] {
        let material = format!(
            "density = {rho:e}\nyoungs_modulus = {e:e}\npoisson_ratio = {nu}\n\
             restitution = 1.0\nfriction_sliding = 0.0\nfriction_rolling = 0.0"
        );
        let at = DVec3::new(0.0, 0.0, r + 1e-7);
        let ball = sphere_of(r, at, -DVec3::Z * v0);
        let mut s = simulation(setup, &material, 0.0, Some(dt), true, vec![ball])?;
        let m = Inertia::mass(r, rho);
        let (mut steps, mut peak_overlap, mut peak_force, mut touched) =
            (0u64, 0.0f64, 0.0f64, false);
        for _ in 0..10_000_000 {
            let v_before = s.particles.v[0].z;
            s.step()?;
            let delta = r - s.particles.x[0].z;
            if delta > 0.0 {
                touched = true;
                steps += 1;
                peak_overlap = peak_overlap.max(delta);
                peak_force = peak_force.max(m * (s.particles.v[0].z - v_before) / dt);
            } else if touched {
                break;
            }
        }
        let e_star = e / (1.0 - nu * nu);
        let measured = (peak_overlap, peak_force, steps as f64 * dt);
        checks.extend(hertz_checks(
            ("chung_ooi_2", name),
            measured,
            (e_star, r, m, v0),
        ));
    }
    Ok(checks)
}

/// A sphere launched sliding without spin on a floor: Coulomb friction slows it and spins it
/// up until v = ω R, at v = 5/7 v0 for a solid sphere (I = 2/5 m R²), whatever μ.
pub(super) fn slip_to_rolling(setup: Setup) -> Result<Vec<Check>> {
    let v0 = 0.5;
    let mut s = simulation(
        setup,
        "restitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.0\nfriction_twisting = 0.0",
        -9.81,
        None,
        true,
        vec![sphere(DVec3::new(0.0, 0.0, R * 0.9995), DVec3::X * v0)],
    )?;
    for _ in 0..40_000 {
        s.step()?;
    }
    let (v, w) = (s.particles.v[0], s.particles.w[0]);
    // The tolerance: the sphere bounces a little at the start.
    let check = |quantity: &str, tinydem, reference| {
        Check::of(
            "slip_to_rolling",
            quantity,
            "m/s",
            (tinydem, reference, 2e-3),
        )
    };
    Ok(vec![
        check("final speed", v.x, 5.0 / 7.0 * v0),
        check("final spin times R", w.y * R, 5.0 / 7.0 * v0),
    ])
}

/// Two spheres stacked on a floor, settled under gravity: the floor carries 2 m g at
/// overlap (3 F / (4 E*_w sqrt(R)))^(2/3) with E*_w = E / (1 - ν²) (a rigid wall); the
/// spheres' contact m g with E* = E / (2 (1 - ν²)), R* = R / 2.
pub(super) fn stacked_spheres(setup: Setup) -> Result<Vec<Check>> {
    let g = 9.81;
    let mut s = simulation(
        setup,
        "restitution = 0.1\nfriction_sliding = 0.3",
        -g,
        None,
        true,
        vec![
            sphere(DVec3::new(0.0, 0.0, R), DVec3::ZERO),
            sphere(DVec3::new(0.0, 0.0, 3.0 * R), DVec3::ZERO),
        ],
    )?;
    let dt = s.scenario.simulation.timestep;
    // Settled: many periods of the contact's oscillation, damped.
    let steps = (0.5 / dt) as usize;
    for _ in 0..steps {
        s.step()?;
    }
    let p = &s.particles;
    let (low, high) = if p.x[0].z < p.x[1].z { (0, 1) } else { (1, 0) };
    let m = Inertia::mass(R, RHO);
    let static_overlap = |f: f64, e_star: f64, r_star: f64| {
        (3.0 * f / (4.0 * e_star * r_star.sqrt())).powf(2.0 / 3.0)
    };
    let e_wall = E / (1.0 - NU * NU);
    let e_pair = E / (2.0 * (1.0 - NU * NU));
    let check = |quantity: &str, tinydem, reference| {
        Check::of("stacked_spheres", quantity, "m", (tinydem, reference, 1e-6))
    };
    Ok(vec![
        check(
            "overlap with the floor",
            R - p.x[low].z,
            static_overlap(2.0 * m * g, e_wall, R),
        ),
        check(
            "overlap between the spheres",
            2.0 * R - (p.x[high] - p.x[low]).length(),
            static_overlap(m * g, e_pair, R / 2.0),
        ),
    ])
}
