//! The twisting sub-model: a twisting spring u_t with k_t = k_s and c_t = c_s, clipped by
//! Coulomb's law with μ_t (Eqs. 33, 35, 37, 40, 53-55).

use crate::model::lanes::{Displacement, Lanes};

use super::Shared;
use super::friction::{Order, coulomb_spring};

coefficients! {
    /// μ_t of the pair.
    pub struct Twisting {
        mu_t,
    }
}

impl<T> Twisting<T>
where
    T: Lanes + Displacement<T>,
    T::Vec: Displacement<T>,
{
    /// The twisting torque τ_t on body i, advancing the spring `u_t`.
    #[inline(always)]
    pub fn torque<O: Order>(&self, at: &Shared<T>, u_t: &mut T) -> T::Vec {
        let v_t = at.r_star * T::dot(at.omega, at.n); // Eq. (37)
        let f_t = coulomb_spring(
            u_t,
            v_t,
            at.stiffness.k_s,
            at.c_s,
            self.mu_t * at.f_n_norm,
            (at.dt, O::ADVANCE_FIRST),
            false,
        ); // Eqs. (35), (40), (53)-(55)
        at.n * (f_t * at.r_star) // Eq. (33)
    }
}
