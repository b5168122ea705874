//! The rolling sub-model, the torque τ_r that resists rolling (`rolling_model`):
//!
//! - `spring` (the paper's): a rolling spring u_r with k_r = k_n and c_r = c_n, clipped by
//!   Coulomb's law with μ_r (Eqs. 32, 34, 36, 39, 52-55).
//! - `cdt`, the constant directional torque (Ai, Chen, Rotter & Ooi 2011, Powder Technol.
//!   206:269, model A; LIGGGHTS `rolling_friction cdt`): τ_r = -μ_r R* |f_n| ω̂_r, with ω_r the
//!   rolling part of the relative angular velocity ω = ω_i - ω_j (Eq. 38), the part in the
//!   tangent plane: ω_r = ω - (ω·n̂) n̂. It acts while anything rolls, so a grain at rest
//!   rocks by μ_r R* |f_n| Δt / I about zero instead of holding still (the model's known
//!   flaw, which the other two have not).
//! - `epsd2`, the elastic-plastic spring (Ai et al. 2011, model C without its viscous
//!   damper; LIGGGHTS `rolling_friction epsd2`): the torque itself is the state, kept in
//!   u_r's place, turned into the tangent plane (Eq. 52), then advanced by the rolling angle
//!   of the step, M_r ← M_r - k_r ω_r Δt with k_r = 2.25 k_n μ_r² R*², and clipped to
//!   |M_r| ≤ μ_r R* |f_n| (fully mobilised rolling: the constant torque of `cdt`). A grain
//!   rolling on a plane is braked as by `cdt`, and comes to rest on the spring.

use crate::model::lanes::{Displacement, Lanes};
use crate::model::registry::RollingModel;

use super::Shared;
use super::friction::{Order, coulomb_spring, project_onto_tangent_plane};

coefficients! {
    /// μ_r of the pair.
    pub struct Rolling {
        mu_r,
    }
}

impl Rolling {
    /// The energy its state holds (the energy ledger's), at normal stiffness `k_n`: the
    /// spring's k_r |u_r|²/2, EPSD2's |M_r|²/(2 k_r), none in CDT.
    pub fn energy(&self, model: RollingModel, k_n: f64, r_star: f64, u_r: glam::DVec3) -> f64 {
        let mu_r = self.mu_r;
        match model {
            RollingModel::Spring => 0.5 * k_n * u_r.length_squared(),
            RollingModel::Cdt => 0.0,
            RollingModel::Epsd2 => {
                let k_r = 2.25 * k_n * (mu_r * r_star).powi(2);
                if k_r > 0.0 {
                    u_r.length_squared() / (2.0 * k_r)
                } else {
                    0.0
                }
            }
        }
    }
}

impl<T> Rolling<T>
where
    T: Lanes + Displacement<T>,
    T::Vec: Displacement<T>,
{
    /// The rolling torque τ_r on body i by the run's `model`, advancing its state `u_r`.
    #[inline(always)]
    pub fn torque<O: Order>(
        &self,
        model: RollingModel,
        at: &Shared<T>,
        u_r: &mut T::Vec,
    ) -> T::Vec {
        match model {
            RollingModel::Spring => self.spring::<O>(at, u_r),
            RollingModel::Cdt => self.constant(at),
            RollingModel::Epsd2 => self.elastic_plastic(at, u_r),
        }
    }

    /// The paper's rolling spring.
    #[inline(always)]
    fn spring<O: Order>(&self, at: &Shared<T>, u_r: &mut T::Vec) -> T::Vec {
        let v_r = T::cross(at.omega, at.n) * at.r_roll; // Eq. (36)
        *u_r = project_onto_tangent_plane::<T>(*u_r, at.n); // Eq. (52)
        let f_r = coulomb_spring(
            u_r,
            v_r,
            at.stiffness.k_n,
            at.c_n,
            self.mu_r * at.f_n_norm,
            (at.dt, O::ADVANCE_FIRST),
            false,
        ); // Eqs. (34), (39), (53)-(55)
        T::cross(at.n, f_r) * at.r_star // Eq. (32)
    }

    /// ω_r, the rolling part of the relative angular velocity (in the tangent plane).
    #[inline(always)]
    fn rolling_velocity(at: &Shared<T>) -> T::Vec {
        at.omega - at.n * T::dot(at.omega, at.n)
    }

    /// The largest rolling torque, μ_r R* |f_n|.
    #[inline(always)]
    fn limit(&self, at: &Shared<T>) -> T {
        self.mu_r * at.r_star * at.f_n_norm
    }

    /// CDT: -μ_r R* |f_n| ω̂_r (nothing where ω_r = 0).
    #[inline(always)]
    fn constant(&self, at: &Shared<T>) -> T::Vec {
        let w_r = Self::rolling_velocity(at);
        let w2 = T::dot(w_r, w_r);
        let scale = <T as Lanes>::pick(
            w2.is_zero(),
            || T::splat(0.0),
            || self.limit(at) / w2.sqrt(),
        );
        -(w_r * scale)
    }

    /// EPSD2: the torque `m_r` (kept in u_r's place) advanced by -k_r ω_r Δt, clipped.
    #[inline(always)]
    fn elastic_plastic(&self, at: &Shared<T>, m_r: &mut T::Vec) -> T::Vec {
        let reach = self.mu_r * at.r_star;
        let k_r = T::splat(2.25) * at.stiffness.k_n * reach * reach;
        let turned = project_onto_tangent_plane::<T>(*m_r, at.n); // Eq. (52)
        let m = turned - Self::rolling_velocity(at) * (k_r * at.dt);
        let (m2, most) = (T::dot(m, m), self.limit(at));
        *m_r = T::pick_vec(m2.le(most * most), || m, || m * (most / m2.sqrt()));
        *m_r
    }
}
