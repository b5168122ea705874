//! The sliding sub-model: tangential friction by a static spring u_s clipped by Coulomb's
//! law with μ_s (Eqs. 6, 11, 31, 52-55), on the spring and damper together (the paper's
//! Eq. 55, `tangential_coulomb = "total"`) or on the spring alone (`"spring"`, as LIGGGHTS
//! and LAMMPS).

use crate::model::lanes::{Displacement, Lanes};

use super::Shared;
use super::friction::{Order, coulomb_spring, project_onto_tangent_plane};
use crate::model::registry::TangentialCoulomb;

coefficients! {
    /// μ_s of the pair.
    pub struct Sliding {
        mu_s,
    }
}

impl<T> Sliding<T>
where
    T: Lanes + Displacement<T>,
    T::Vec: Displacement<T>,
{
    /// The sliding force f_s and its torque τ_s on body i, advancing the spring `u_s`.
    #[inline(always)]
    pub fn force<O: Order>(
        &self,
        coulomb: TangentialCoulomb,
        at: &Shared<T>,
        u_s: &mut T::Vec,
    ) -> (T::Vec, T::Vec) {
        *u_s = project_onto_tangent_plane::<T>(*u_s, at.n); // Eq. (52)
        let f_s = coulomb_spring(
            u_s,
            at.v_s,
            at.stiffness.k_s,
            at.c_s,
            self.mu_s * at.f_n_norm,
            (at.dt, O::ADVANCE_FIRST),
            coulomb == TangentialCoulomb::Spring,
        ); // Eqs. (6), (11), (53)-(55)
        let tau_s = T::cross(f_s, at.n) * at.r_i; // Eq. (31)
        (f_s, tau_s)
    }
}
