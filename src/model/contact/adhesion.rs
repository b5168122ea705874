//! The adhesion sub-model: none, or a pull along -n̂:
//!
//! - the simplified JKR cohesion (SJKR): k_c A over the area A = π a² of the contact circle
//!   (of the two spheres' lens, or of the sphere cut by the wall's plane), while touching;
//! - DMT (Derjaguin, Muller & Toporov 1975, J. Colloid Interface Sci. 53:314): 2 π γ R*, γ the
//!   work of adhesion (`surface_energy`), the pull-off force of two spheres in DMT's theory,
//!   acting while they touch (as LAMMPS's `dmt`; the attraction beyond contact is left out);
//! - JKR (Johnson, Kendall & Roberts 1971, Proc. R. Soc. A 324:301): the contact radius a
//!   follows from the overlap by δ = a²/R* - sqrt(2 π γ a / E*), the elastic force is
//!   F = 4 E* a³ / (3 R*) - sqrt(8 π γ E* a³), and the contact, once made at δ = 0, holds
//!   until δ falls to -δ_c = -(3/4) (π² γ² R* / E*²)^(1/3) (the neck's end under a
//!   prescribed separation): a hysteresis of approach and pull-off;
//! - liquid bridges: once two bodies touch, a bridge of volume V pulls them by Willett et
//!   al. 2000's closed form (Langmuir 16:9396, Eqs. 12-13),
//!   F = 2 π R γ_l cos θ / (1 + 2.1 S⁺ + 10 S⁺²) with S⁺ = (s/2) sqrt(R/V) at the gap s
//!   (R = 2 R*, Derjaguin's mean, 2 R_i on a wall), until the gap passes (1 + θ/2) V^(1/3)
//!   (Lian et al. 1993, J. Colloid Interface Sci. 161:138); no force after that until they
//!   touch again.
//!
//! A pair's coefficients hold each model's constants (zero where the pair has not the model),
//! so pairs of several kinds share one loop. The pull adds to the force only: the Coulomb
//! limits rest on the repulsive load |f_n|, which at rest carries the outer load and the pull
//! together; JKR's on |F + 2 F_c| (Thornton & Yin 1991), F_c = 3/2 π γ R* its pull-off force.

use crate::model::lanes::Lanes;
use crate::model::materials::PairCoefficients;
use crate::model::registry::AdhesionModel;

use super::kinematics::Other;
use super::normal::Elastic;

coefficients! {
    /// The pair's constants of each adhesion model (zero: not that model).
    pub struct Cohesion {
        /// k_c \[J/m³\] of SJKR.
        k_c,
        /// 2 π γ \[J/m²\] of DMT.
        dmt,
        /// JKR's c = sqrt(2 π γ / E*) \[m^½\] and c E* = sqrt(2 π γ E*) \[N/m^(3/2)\].
        jkr,
        jkr_e,
        /// Where a JKR contact parts, as a share of δ_c: 1 (at the pull-off separation), or
        /// 3^(-2/3) (at the pull-off force, `jkr_force`).
        jkr_parting,
        /// 4 π γ_l cos θ \[N/m\]: a bridge's pull at touch is this times R*.
        bridge,
        /// 1/V \[1/m³\] of a bridge (0: dry).
        per_volume,
        /// The bridge's rupture distance (1 + θ/2) V^(1/3) \[m\].
        rupture,
    }
}

impl Cohesion {
    /// The constants of the pair's adhesion `pair` (with E* `e_star`, for JKR).
    pub fn of(pair: &PairCoefficients, e_star: f64) -> Cohesion {
        use std::f64::consts::PI;
        let (gamma, liquid) = (pair.surface_energy, &pair.liquid);
        let jkr = pair.models.adhesion.is_jkr() && gamma > 0.0;
        let theta = liquid.contact_angle.to_radians();
        Cohesion {
            k_c: pair.cohesion,
            dmt: if pair.models.adhesion == AdhesionModel::Dmt {
                2.0 * PI * gamma
            } else {
                0.0
            },
            jkr: if jkr {
                (2.0 * PI * gamma / e_star).sqrt()
            } else {
                0.0
            },
            jkr_e: if jkr {
                (2.0 * PI * gamma * e_star).sqrt()
            } else {
                0.0
            },
            // At the pull-off force (x³ = 3/4 on the branch) the overlap is 3^(-2/3) of its
            // least, -δ_c.
            jkr_parting: match pair.models.adhesion {
                AdhesionModel::JkrForce => 3f64.powf(-2.0 / 3.0),
                _ => 1.0,
            },
            bridge: if liquid.wet() {
                4.0 * PI * liquid.surface_tension * theta.cos()
            } else {
                0.0
            },
            per_volume: if liquid.wet() {
                1.0 / liquid.volume
            } else {
                0.0
            },
            rupture: if liquid.wet() {
                liquid.rupture_distance()
            } else {
                0.0
            },
        }
    }
}

/// An adhesion sub-model, chosen once per run.
pub trait Adhesion {
    /// Whether a contact outlasts touch (JKR's neck, a liquid bridge): the contact stages
    /// keep an open contact while its gap is within [`Adhesion::reach`].
    const BEYOND_TOUCH: bool = false;
    /// Whether apart the bodies still touch through a solid neck (JKR): otherwise a contact
    /// apart has no solid part (no elastic force, damping or friction; springs forgotten).
    const NECK: bool = false;
    /// Whether any pair pulls (otherwise the pull is not even subtracted).
    const PULLS: bool = true;

    /// a, the radius of the contact area at overlap `delta`: Hertz's sqrt(R* δ) (Eq. 14).
    #[inline(always)]
    fn contact_radius<T: Lanes>(_: &Cohesion<T>, r_star: T, delta: T) -> T {
        (r_star * delta).sqrt()
    }

    /// The pull along -n̂ of a contact of body i (radius `radius_i`) with `other` at
    /// overlap `delta`, effective radius `r_star` and contact radius `a`.
    fn pull<T: Lanes>(coef: &Cohesion<T>, radii: (T, T), other: Other<T>, delta: T, a: T) -> T;

    /// The load of the Coulomb limits, from the normal force without the pull
    /// (`f_n_scalar`, positive pushing) and the `pull`.
    #[inline(always)]
    fn coulomb_load<T: Lanes>(_: &Cohesion<T>, f_n_scalar: T, _pull: T, _r_star: T) -> T {
        f_n_scalar.abs()
    }

    /// The gap at which an open contact of effective radius `r_star` ends (0: at touch).
    #[inline(always)]
    fn reach(_: &Cohesion, _r_star: f64) -> f64 {
        0.0
    }

    /// The elastic energy ∫ f_n dδ at overlap `delta` (the energy ledger's): Hertz's or
    /// Hooke's, unless the model sets the contact radius.
    fn elastic_energy(_: &Cohesion, elastic: &Elastic, r_star: f64, delta: f64) -> f64 {
        elastic.energy(r_star, delta)
    }

    /// The energy of the pull, -∫ pull dδ from touch (the energy ledger's), of a contact
    /// of body i (radius and R* in `radii`) with `other` at overlap `delta`.
    fn energy(_: &Cohesion, _radii: (f64, f64), _other: Other, _delta: f64) -> f64 {
        0.0
    }
}

/// No adhesion (no pair of the run pulls).
pub struct NoAdhesion;

/// A pull while touching: the simplified JKR cohesion and DMT.
pub struct Pull;

/// JKR's contact (and the pulls of [`Pull`] for the run's other pairs).
pub struct Jkr;

/// Liquid bridges (and the pulls of [`Pull`] while touching).
pub struct Bridge;

impl Adhesion for NoAdhesion {
    const PULLS: bool = false;

    #[inline(always)]
    fn pull<T: Lanes>(_: &Cohesion<T>, _: (T, T), _: Other<T>, _: T, _: T) -> T {
        T::splat(0.0)
    }
}

impl Adhesion for Pull {
    #[inline(always)]
    fn pull<T: Lanes>(
        coef: &Cohesion<T>,
        (radius_i, r_star): (T, T),
        other: Other<T>,
        delta: T,
        _: T,
    ) -> T {
        let c = T::splat;
        // a², the squared radius of the contact circle.
        let a2 = match other {
            Other::Particle { r: radius_j, .. } => {
                let d = radius_i + radius_j - delta;
                let x = (d * d + radius_i * radius_i - radius_j * radius_j) / (c(2.0) * d);
                radius_i * radius_i - x * x
            }
            Other::Wall => delta * (c(2.0) * radius_i - delta),
        };
        coef.k_c * c(std::f64::consts::PI) * a2 + coef.dmt * r_star
    }

    /// SJKR's -k_c π ∫ a² dδ (a² as in `pull`, integrated in closed form) and DMT's
    /// -2 π γ R* δ, while touching.
    fn energy(coef: &Cohesion, (radius_i, r_star): (f64, f64), other: Other, delta: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        let area = match other {
            Other::Particle { r: radius_j, .. } => {
                // a² = (R_i² + R_j²)/2 - d²/4 - (R_i² - R_j²)²/(4 d²) at the distance
                // d = R_i + R_j - δ, whose antiderivative in d is `g`.
                let (ri2, rj2) = (radius_i * radius_i, radius_j * radius_j);
                let g = |d: f64| {
                    0.5 * (ri2 + rj2) * d - d * d * d / 12.0 + (ri2 - rj2).powi(2) / (4.0 * d)
                };
                let d0 = radius_i + radius_j;
                g(d0) - g(d0 - delta)
            }
            Other::Wall => radius_i * delta * delta - delta * delta * delta / 3.0,
        };
        -(coef.k_c * std::f64::consts::PI * area + coef.dmt * r_star * delta)
    }
}

impl Adhesion for Jkr {
    const BEYOND_TOUCH: bool = true;
    const NECK: bool = true;

    /// JKR's a at δ: s = sqrt(a) is the largest root of s⁴ - c R* s - δ R* = 0
    /// ([`jkr_root`]). Hertz's for a pair without JKR.
    #[inline(always)]
    fn contact_radius<T: Lanes>(coef: &Cohesion<T>, r_star: T, delta: T) -> T {
        T::pick(
            coef.jkr.is_zero(),
            || (r_star * delta).sqrt(),
            || {
                let s = jkr_root(coef.jkr * r_star, delta * r_star);
                s * s
            },
        )
    }

    /// F = 4/3 E* a δ - pull: with δ = a²/R* - sqrt(2 π γ a / E*), the pull is
    /// (2/3) sqrt(2 π γ E* a³).
    #[inline(always)]
    fn pull<T: Lanes>(coef: &Cohesion<T>, radii: (T, T), other: Other<T>, delta: T, a: T) -> T {
        let jkr = T::splat(2.0 / 3.0) * coef.jkr_e * a * a.sqrt();
        jkr + Pull::pull(coef, radii, other, delta, a)
    }

    /// |F + 2 F_c| with F_c = 3/2 π γ R* = 3/4 c (c E*) R*.
    #[inline(always)]
    fn coulomb_load<T: Lanes>(coef: &Cohesion<T>, f_n_scalar: T, pull: T, r_star: T) -> T {
        let f_c = T::splat(0.75) * coef.jkr * coef.jkr_e * r_star;
        (f_n_scalar - pull + T::splat(2.0) * f_c).abs()
    }

    /// δ_c = (3/4) (π² γ² R* / E*²)^(1/3) = (3/4) (c⁴ R* / 4)^(1/3), or the overlap at the
    /// pull-off force, 3^(-2/3) δ_c (`jkr_force`).
    #[inline(always)]
    fn reach(coef: &Cohesion, r_star: f64) -> f64 {
        coef.jkr_parting * 0.75 * (coef.jkr.powi(4) * r_star / 4.0).cbrt()
    }

    /// ∫ 4/3 E* a δ dδ along JKR's branch from touch (a₀ = (c R*)^(2/3) at δ = 0), with
    /// δ = a²/R* - c √a: 4/3 E* [2/5 a⁵/R*² - 5c/(7R*) a^(7/2) + c²/4 a²] from a₀ to a.
    fn elastic_energy(coef: &Cohesion, elastic: &Elastic, r_star: f64, delta: f64) -> f64 {
        let c = coef.jkr;
        if c == 0.0 {
            return elastic.energy(r_star, delta);
        }
        let e = |a: f64| {
            0.4 * a.powi(5) / (r_star * r_star) - 5.0 * c / (7.0 * r_star) * a.powf(3.5)
                + 0.25 * c * c * a * a
        };
        let (a, a0) = Self::radii(c, r_star, delta);
        4.0 / 3.0 * elastic.e_star * (e(a) - e(a0))
    }

    /// -∫ 2/3 sqrt(2π γ E*) a^(3/2) dδ along the branch from touch:
    /// -2/3 sqrt(2π γ E*) [4/7 a^(7/2)/R* - c/4 a²] from a₀ to a; and SJKR's and DMT's.
    fn energy(coef: &Cohesion, radii: (f64, f64), other: Other, delta: f64) -> f64 {
        let (c, r_star) = (coef.jkr, radii.1);
        let others = Pull::energy(coef, radii, other, delta);
        if c == 0.0 {
            return others;
        }
        let p = |a: f64| 4.0 / 7.0 * a.powf(3.5) / r_star - 0.25 * c * a * a;
        let (a, a0) = Self::radii(c, r_star, delta);
        others - 2.0 / 3.0 * coef.jkr_e * (p(a) - p(a0))
    }
}

impl Jkr {
    /// JKR's contact radius at overlap `delta` and at touch, for c = sqrt(2π γ / E*).
    fn radii(c: f64, r_star: f64, delta: f64) -> (f64, f64) {
        let s = jkr_root(c * r_star, delta * r_star);
        (s * s, (c * r_star).powf(2.0 / 3.0))
    }
}

impl Adhesion for Bridge {
    const BEYOND_TOUCH: bool = true;

    #[inline(always)]
    fn contact_radius<T: Lanes>(_: &Cohesion<T>, r_star: T, delta: T) -> T {
        T::pick(
            delta.positive(),
            || (r_star * delta).sqrt(),
            || T::splat(0.0),
        )
    }

    /// Willett's force at the gap s = -δ (its value at s = 0 while touching), with the pulls
    /// of [`Pull`] while touching.
    #[inline(always)]
    fn pull<T: Lanes>(coef: &Cohesion<T>, radii: (T, T), other: Other<T>, delta: T, a: T) -> T {
        let at_touch = coef.bridge * radii.1;
        T::pick(
            delta.positive(),
            || at_touch + Pull::pull(coef, radii, other, delta, a),
            || {
                let c = T::splat;
                // S⁺ = (s/2) sqrt(R/V) with R = 2 R*.
                let s = c(-0.5) * delta * (c(2.0) * radii.1 * coef.per_volume).sqrt();
                at_touch / (c(1.0) + s * (c(2.1) + c(10.0) * s)) // Willett Eq. (12)
            },
        )
    }

    #[inline(always)]
    fn reach(coef: &Cohesion, _: f64) -> f64 {
        coef.rupture
    }

    /// Touching, -F(0) δ (and SJKR's, DMT's); apart, the work of stretching the bridge
    /// from touch to the gap s = -δ, Willett's force integrated in closed form:
    /// F(0)/κ · 2/√D [atan((20 κ s + 2.1)/√D) - atan(2.1/√D)], S⁺ = κ s, D = 40 - 2.1².
    fn energy(coef: &Cohesion, radii: (f64, f64), other: Other, delta: f64) -> f64 {
        let at_touch = coef.bridge * radii.1;
        if delta > 0.0 {
            return -at_touch * delta + Pull::energy(coef, radii, other, delta);
        }
        if at_touch == 0.0 {
            return 0.0;
        }
        let kappa = 0.5 * (2.0 * radii.1 * coef.per_volume).sqrt();
        let root = (40.0f64 - 2.1 * 2.1).sqrt();
        let s = -delta * kappa;
        at_touch / kappa * 2.0 / root * (((20.0 * s + 2.1) / root).atan() - (2.1 / root).atan())
    }
}

/// The largest real root s of s⁴ - p s - q = 0 (p > 0; q at least the least value of s⁴ -
/// p s on the branch s ≥ (p/4)^(1/3), where the two largest roots meet: taken as that below
/// it), in closed form: Ferrari's resolvent cubic m³ + q m = p²/8 has one real root there,
/// m = u - w by Cardano (u = cbrt(p²/16 + sqrt(p⁴/256 + q³/27)), w = q / (3u)), written as
/// (p²/8) / (u² + u w + w²) for q > 0 where u - w cancels; then s = (sqrt(2m) +
/// sqrt(2p / sqrt(2m) - 2m)) / 2. One cube root, the rest in lanes.
#[inline(always)]
pub fn jkr_root<T: Lanes>(p: T, q: T) -> T {
    let c = T::splat;
    let zero = c(0.0);
    let at_least_zero = |x: T| T::pick(x.le(zero), || zero, || x);
    let p2 = p * p;
    let root = at_least_zero(p2 * p2 * c(1.0 / 256.0) + q * q * q * c(1.0 / 27.0)).sqrt();
    let u = (p2 * c(1.0 / 16.0) + root).each(f64::cbrt);
    let w = q / (c(3.0) * u);
    let m = T::pick(
        q.le(zero),
        || u - w,
        || p2 * c(0.125) / (u * u + u * w + w * w),
    );
    let two_m = c(2.0) * m;
    let s = two_m.sqrt();
    c(0.5) * (s + at_least_zero(c(2.0) * p / s - two_m).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jkr_root_solves_its_quartic_on_the_stable_branch() {
        for p in [1e-9, 1.0, 3e4] {
            // The least q = s⁴ - p s of the branch, at s = (p/4)^(1/3).
            let s_c = (p / 4.0f64).cbrt();
            let q_min = s_c.powi(4) - p * s_c;
            for share in [1.0, 0.99, 0.5, 1e-3, 0.0, -1e-6, -1.0, -10.0, -1e6, -1e12] {
                let q = share * q_min;
                let s: f64 = jkr_root(p, q);
                let residual = (s.powi(4) - p * s - q) / (s.powi(4) + p * s);
                assert!(
                    residual.abs() < 1e-11,
                    "p {p}, q {q}: s {s}, residual {residual}"
                );
                assert!(s >= s_c * (1.0 - 1e-7), "the stable branch: {s} < {s_c}");
            }
        }
        assert_eq!(jkr_root(1.0, 0.0), 1.0);
    }
}
