//! The rolling sub-model: the paper's rolling spring u_r with k_r = k_n and c_r = c_n,
//! clipped by Coulomb's law with μ_r (Eqs. 32, 34, 36, 39, 52-55).

use crate::model::lanes::{Displacement, Lanes};

use super::Shared;
use super::friction::{Order, coulomb_spring, project_onto_tangent_plane};

coefficients! {
    /// μ_r of the pair.
    pub struct Rolling {
        mu_r,
    }
}

impl<T> Rolling<T>
where
    T: Lanes + Displacement<T>,
    T::Vec: Displacement<T>,
{
    /// The rolling torque τ_r on body i, advancing the spring `u_r`.
    #[inline(always)]
    pub fn torque<O: Order>(&self, at: &Shared<T>, u_r: &mut T::Vec) -> T::Vec {
        let v_r = T::cross(at.omega, at.n) * at.r_roll; // Eq. (36)
        *u_r = project_onto_tangent_plane::<T>(*u_r, at.n); // Eq. (52)
        let f_r = coulomb_spring(
            u_r,
            v_r,
            at.stiffness.k_n,
            at.c_n,
            self.mu_r * at.f_n_norm,
            at.dt,
            O::ADVANCE_FIRST,
        ); // Eqs. (34), (39), (53)-(55)
        T::cross(at.n, f_r) * at.r_star // Eq. (32)
    }
}
