//! The static friction spring shared by the sliding, rolling and twisting sub-models:
//! a Kelvin-Voigt element clipped by Coulomb's law (Eqs. 52-55), and the order in which it
//! is advanced (`[simulation] friction_springs`, `FrictionSprings`).

use crate::model::lanes::{Displacement, Lanes};

/// When a spring is advanced by Δt v relative to the force taken from it, chosen once per
/// run (see `coulomb_spring`).
pub trait Order {
    /// Whether the spring advances before its force is taken.
    const ADVANCE_FIRST: bool;
}

/// Advance the spring, then take its force: symplectic Euler (the default).
pub struct AdvanceFirst;
/// The paper's order: the force of the previous step's spring, then advance.
pub struct PaperOrder;

impl Order for AdvanceFirst {
    const ADVANCE_FIRST: bool = true;
}

impl Order for PaperOrder {
    const ADVANCE_FIRST: bool = false;
}

/// Eq. (52): rotate a spring back into the tangent plane of the current normal, keeping its
/// length (unless it is zero or parallel to the normal).
#[inline(always)]
pub(super) fn project_onto_tangent_plane<T: Lanes>(u: T::Vec, n: T::Vec) -> T::Vec {
    let length2 = T::dot(u, u);
    let tangential = u - n * T::dot(u, n);
    let t2 = T::dot(tangential, tangential);
    let stretch = T::pick(t2.is_zero(), || T::splat(0.0), || (length2 / t2).sqrt());
    tangential * stretch
}

/// The energy k |u|²/2 of a spring of stiffness `k` stretched by |u|² = `u2`.
pub(super) fn spring_energy(k: f64, u2: f64) -> f64 {
    0.5 * k * u2
}

/// One friction mode m ∈ {s, r, t}: the Kelvin-Voigt force -k u - c v, clipped by Coulomb's
/// law to `f_max` = μ_m |f_n|. Static: the spring grows by Δt v (Eq. 53). Kinetic: the force
/// is scaled to the Coulomb limit (Eq. 54) and the spring set to match it (Eq. 55), so the
/// force is continuous at the switch between the two.
///
/// `advance_first` says when the spring grows. The paper takes the force of the previous
/// step's spring, then advances it; the default advances it first. The difference is that
/// between creating energy and not. Take one sticking contact: a mass m on the spring k
/// with damper c, ω² = k/m, γ = c/m, moved by the semi-implicit Euler of Eqs. (45)-(46)
/// (the velocity first, the position with the new velocity), so that the spring is the
/// integral of the velocity the contact sees. Per step, the state (u, v) maps to
///
/// ```text
///   paper:          u' = u + Δt v            | 1      Δt       |   det = 1 - γΔt + ω²Δt²
///                   v' = v - Δt (ω² u + γ v) | -ω²Δt  1 - γΔt  |
///
///   advance first:  u' = u + Δt v            | 1      Δt              |   det = 1 - γΔt
///                   v' = v - Δt (ω² u' + γ v)| -ω²Δt  1 - ω²Δt² - γΔt |
/// ```
///
/// The determinant is the factor by which a step scales the area of phase space, and so
/// (for the undamped oscillator) its energy on average. The paper's order is forward
/// Euler: undamped (an elastic contact has c = 0, Eq. 18 with β = 0) it gains a factor
/// 1 + (ωΔt)² per step, and damped it still gains whenever ω²Δt > γ; with ωΔt ≈ 0.3
/// at Eq. (50)'s time step an elastic oblique impact leaves with ~20 % more energy and a
/// settled bed keeps spinning. Advancing first is symplectic Euler: undamped it keeps
/// the area exactly (|trace| < 2 for ωΔt < 2, so the energy stays bounded and returns),
/// and any damping only removes energy.
///
/// With `spring_only` (`tangential_coulomb = "spring"`, LIGGGHTS's and LAMMPS's test) the
/// limit clips the spring's force k u alone: sticking, the force is -k u - c v; sliding,
/// the spring is cut to |k u| = f_max and the force is -k u, the damper idle.
#[inline(always)]
pub(super) fn coulomb_spring<T: Lanes, V: Displacement<T>>(
    u: &mut V,
    v: V,
    k: T,
    c: T,
    f_max: T,
    (dt, advance_first): (T, bool),
    spring_only: bool,
) -> V {
    let spring = if advance_first { *u + v * dt } else { *u }; // Eq. (53), first
    let advanced = || if advance_first { spring } else { *u + v * dt }; // Eq. (53)
    if spring_only {
        let f_spring = -(spring * k);
        let f_norm2 = f_spring.norm_squared();
        let sticking = f_norm2.le(f_max * f_max);
        let cut = V::pick(sticking, || spring, || spring * (f_max / f_norm2.sqrt()));
        let f = V::pick(sticking, || f_spring + -(v * c), || -(cut * k));
        *u = V::pick(sticking, advanced, || cut);
        return f;
    }
    let f = -(spring * k) + -(v * c);
    let f_norm2 = f.norm_squared();
    let sticking = f_norm2.le(f_max * f_max);
    let f = V::pick(sticking, || f, || f * (f_max / f_norm2.sqrt())); // Eq. (54)
    *u = V::pick(
        sticking,
        advanced,
        || -(f + v * c) * (T::splat(1.0) / k), // Eq. (55)
    );
    f
}
