//! The cases of contacts that outlast touch: JKR's pull-off and sticking speed, and a
//! liquid bridge's force and rupture (`models/adhesion.md`, `models/liquid-bridges.md`).

use std::f64::consts::PI;

use anyhow::{Result, bail};
use glam::DVec3;

use super::{Check, Setup, simulation, sphere_of};

/// R, ρ, E and ν of the grains of these cases, and γ of JKR.
const R: f64 = 0.005;
const E: f64 = 1e7;
const GAMMA: f64 = 0.5;
const MATERIAL: &str = "density = 2500.0\nyoungs_modulus = 1e7\npoisson_ratio = 0.3\n\
                        restitution = 1.0\nadhesion_model = \"jkr\"\nsurface_energy = 0.5";

/// E* of a grain against the floor.
fn e_wall() -> f64 {
    E / (1.0 - 0.09)
}

fn mass() -> f64 {
    2500.0 * 4.0 / 3.0 * PI * R.powi(3)
}

/// An elastic grain (R 5 mm, E 10 MPa, ν 0.3, γ 0.5 J/m², e_n = 1) on a JKR floor: pulled
/// off by a body force of 1.2 F_c, the strongest pull of its contact is F_c = 3/2 π γ R and
/// the contact ends at the overlap -(3/4) (π² γ² R / E*²)^(1/3); dropped at 1.05 times the
/// sticking speed of JKR's hysteresis it leaves at sqrt(1.05² - 1) of it, at 0.95 it stays.
pub(super) fn jkr_contact(setup: Setup) -> Result<Vec<Check>> {
    let f_c = 1.5 * PI * GAMMA * R;
    let delta_c = 0.75 * (PI * PI * GAMMA * GAMMA * R / (e_wall() * e_wall())).cbrt();
    let (strongest, last) = pulled_off(setup, -1.2 * f_c / mass())?;
    let v_s = sticking_speed();
    let mut checks = vec![
        Check::of(
            "jkr_contact",
            "pull-off force, 3/2 pi gamma R",
            "N",
            (strongest, f_c, 1e-3),
        ),
        Check::of(
            "jkr_contact",
            "pull-off separation, -delta_c",
            "m",
            (last, -delta_c, 1e-3),
        ),
    ];
    for share in [1.05, 1.2] {
        let leaving = dropped(setup, share * v_s)?;
        let expected = (share * share - 1.0).sqrt() * v_s;
        checks.push(Check::of(
            "jkr_contact",
            format!("speed after an impact at {share} v_s"),
            "m/s",
            (leaving, expected, 1e-2),
        ));
    }
    if dropped(setup, 0.95 * v_s)? != 0.0 {
        bail!("jkr_contact: a grain dropped at 0.95 v_s did not stick");
    }
    Ok(checks)
}

/// The speed below which an elastic grain sticks: ½ m v_s² = W, the work of parting the
/// contact from δ = 0 to -δ_c, W = 2 π γ l² ∫ from 4^(-1/3) to 1 of -(4x⁶/3 - 2x³)(4x³ - 1)
/// dx with l = (c R)^(2/3), c² = 2 π γ / E*.
fn sticking_speed() -> f64 {
    let l2 = ((2.0 * PI * GAMMA / e_wall()).sqrt() * R).powf(4.0 / 3.0);
    let antiderivative = |x: f64| 8.0 / 15.0 * x.powi(10) - 4.0 / 3.0 * x.powi(7) + 0.5 * x.powi(4);
    let integral = antiderivative(1.0) - antiderivative(0.25f64.cbrt());
    (2.0 * -2.0 * PI * GAMMA * l2 * integral / mass()).sqrt()
}

/// A grain on the floor under the body force `g` along -z (negative: up): the strongest pull
/// of its contact and its last overlap.
fn pulled_off(setup: Setup, g: f64) -> Result<(f64, f64)> {
    let grain = sphere_of(R, DVec3::new(0.0, 0.0, R - 1e-9), DVec3::ZERO);
    let mut s = simulation(setup, MATERIAL, -g, Some(2e-8), true, vec![grain])?;
    let (mut strongest, mut last) = (0.0f64, f64::NAN);
    for _ in 0..2_000_000 {
        s.step()?;
        let Some(c) = s.held_contacts().first().copied() else {
            return Ok((strongest, last));
        };
        strongest = strongest.max(-c.f_n.z);
        last = c.overlap;
    }
    bail!("jkr_contact: the grain did not come off the floor")
}

/// The speed at which a grain dropped at `v0` leaves the floor (0: it stuck).
fn dropped(setup: Setup, v0: f64) -> Result<f64> {
    let grain = sphere_of(R, DVec3::new(0.0, 0.0, R + 1e-9), DVec3::new(0.0, 0.0, -v0));
    let mut s = simulation(setup, MATERIAL, 0.0, Some(2e-8), true, vec![grain])?;
    for _ in 0..400_000 {
        s.step()?;
    }
    let v = s.particles.v[0].z;
    Ok(if s.held_contacts().is_empty() { v } else { 0.0 })
}

/// A grain flying off a fixed one (R 5 mm) from touch at 0.05 m/s with a bridge (V 2e-10 m³,
/// γ_l 0.07 N/m, θ 20°): the bridge's force at gaps of 10, 30 and 60 % of the rupture
/// distance against Willett et al. 2000's closed form, and where it breaks against Lian et
/// al. 1993's (1 + θ/2) V^(1/3).
pub(super) fn liquid_bridge(setup: Setup) -> Result<Vec<Check>> {
    let (gamma_l, theta, v): (f64, f64, f64) = (0.07, 20.0, 2e-10);
    let rupture = (1.0 + 0.5 * theta.to_radians()) * v.cbrt();
    let willett = |s: f64| {
        let r = R; // 2 R* of two grains of R
        let s_plus = 0.5 * s * (r / v).sqrt();
        2.0 * PI * r * gamma_l * theta.to_radians().cos()
            / (1.0 + 2.1 * s_plus + 10.0 * s_plus * s_plus)
    };
    let material = format!(
        "density = 2500.0\nyoungs_modulus = 1e7\nliquid_volume = {v:e}\nsurface_tension = {gamma_l}\n\
         contact_angle = {theta}"
    );
    let mut fixed = sphere_of(R, DVec3::ZERO, DVec3::ZERO);
    fixed.fixed = true;
    let free = sphere_of(
        R,
        DVec3::new(2.0 * R - 1e-7, 0.0, 0.0),
        DVec3::new(0.05, 0.0, 0.0),
    );
    let mut s = simulation(setup, &material, 0.0, Some(1e-6), false, vec![fixed, free])?;
    let mut checks = Vec::new();
    let mut marks = [0.1, 0.3, 0.6].into_iter().peekable();
    let mut last = 0.0;
    for _ in 0..100_000 {
        s.step()?;
        let gap = s.particles.x[1].x - 2.0 * R;
        let Some(c) = s.held_contacts().first().copied() else {
            checks.push(Check::of(
                "liquid_bridge",
                "last gap of the bridge, (1 + theta/2) V^(1/3)",
                "m",
                (last, rupture, 2e-4),
            ));
            return Ok(checks);
        };
        last = gap;
        if let Some(&mark) = marks.peek()
            && gap >= mark * rupture
        {
            checks.push(Check::of(
                "liquid_bridge",
                format!("force at a gap of {mark} of the rupture distance"),
                "N",
                (c.f_n.x, willett(gap), 1e-9),
            ));
            marks.next();
        }
    }
    bail!("liquid_bridge: the bridge did not break")
}
