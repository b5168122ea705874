//! The adhesion sub-model: none, or the simplified JKR cohesion (SJKR), a pull k_c A along
//! -n̂ over the area A = π a² of the contact circle (of the two spheres' lens, or of the
//! sphere cut by the wall's plane). It adds to the force only: the Coulomb limits rest on
//! the repulsive load |f_n|, which at rest carries the outer load and the pull together.

use crate::model::lanes::Lanes;

use super::kinematics::Other;

coefficients! {
    /// k_c of the pair [J/m³] (zero: no pull).
    pub struct Cohesion {
        k_c,
    }
}

/// An adhesion sub-model, chosen once per run.
pub trait Adhesion {
    /// The force `f` of a contact of body i (radius `radius_i`) with `other` at overlap
    /// `delta` along `n`, with the pull added.
    fn add_pull<T: Lanes>(
        coef: &Cohesion<T>,
        f: T::Vec,
        n: T::Vec,
        radius_i: T,
        other: Other<T>,
        delta: T,
    ) -> T::Vec;
}

/// No adhesion (no pair of the run has k_c > 0).
pub struct NoAdhesion;

/// The simplified JKR cohesion.
pub struct Sjkr;

impl Adhesion for NoAdhesion {
    #[inline(always)]
    fn add_pull<T: Lanes>(
        _: &Cohesion<T>,
        f: T::Vec,
        _: T::Vec,
        _: T,
        _: Other<T>,
        _: T,
    ) -> T::Vec {
        f
    }
}

impl Adhesion for Sjkr {
    #[inline(always)]
    fn add_pull<T: Lanes>(
        coef: &Cohesion<T>,
        f: T::Vec,
        n: T::Vec,
        radius_i: T,
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
        f - n * (coef.k_c * c(std::f64::consts::PI) * a2)
    }
}
