//! The adhesion sub-model: none, or a pull along -n̂ while the bodies overlap:
//!
//! - the simplified JKR cohesion (SJKR): k_c A over the area A = π a² of the contact circle
//!   (of the two spheres' lens, or of the sphere cut by the wall's plane);
//! - DMT (Derjaguin, Muller & Toporov 1975, J. Colloid Interface Sci. 53:314): 2 π γ R*, γ the
//!   work of adhesion (`surface_energy`), the pull-off force of two spheres in DMT's theory,
//!   acting while they touch (as LAMMPS's `dmt`; the attraction beyond contact is left out).
//!
//! A pair's coefficients hold k_c or 2 π γ (the other zero), so both run in one loop. The
//! pull adds to the force only: the Coulomb limits rest on the repulsive load |f_n|, which at
//! rest carries the outer load and the pull together.

use crate::model::lanes::Lanes;

use super::kinematics::Other;

coefficients! {
    /// k_c of the pair [J/m³] and 2 π γ [J/m²] (zero: no pull).
    pub struct Cohesion {
        k_c,
        dmt,
    }
}

/// An adhesion sub-model, chosen once per run.
pub trait Adhesion {
    /// The force `f` of a contact of body i (radius `radius_i`) with `other` at overlap
    /// `delta` along `n` (effective radius `r_star`), with the pull added.
    fn add_pull<T: Lanes>(
        coef: &Cohesion<T>,
        f: T::Vec,
        n: T::Vec,
        radii: (T, T),
        other: Other<T>,
        delta: T,
    ) -> T::Vec;
}

/// No adhesion (no pair of the run pulls).
pub struct NoAdhesion;

/// A pull: the simplified JKR cohesion and DMT.
pub struct Pull;

impl Adhesion for NoAdhesion {
    #[inline(always)]
    fn add_pull<T: Lanes>(
        _: &Cohesion<T>,
        f: T::Vec,
        _: T::Vec,
        _: (T, T),
        _: Other<T>,
        _: T,
    ) -> T::Vec {
        f
    }
}

impl Adhesion for Pull {
    #[inline(always)]
    fn add_pull<T: Lanes>(
        coef: &Cohesion<T>,
        f: T::Vec,
        n: T::Vec,
        (radius_i, r_star): (T, T),
        other: Other<T>,
        delta: T,
    ) -> T::Vec {
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
        f - n * (coef.k_c * c(std::f64::consts::PI) * a2 + coef.dmt * r_star)
    }
}
