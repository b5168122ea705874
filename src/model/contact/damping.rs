//! The damping sub-model: viscoelastic dashpots c_n, c_s from the pair's restitution
//! (Eqs. 18, 19, 21, 25), in parallel with the springs of every mode.
//!
//! With Hooke's constant stiffness the contact is a damped linear oscillator, whose
//! restitution is e = exp(-π ζ / sqrt(1 - ζ²)) at the damping ratio ζ = c_n / (2 sqrt(m* k_n)):
//! ζ = -ln e / sqrt(ln² e + π²), which is Eq. (21)'s β. So c_n = 2 β sqrt(m* k_n), written
//! as Eq. (18) with β' = 2 β / sqrt(5); and c_s = 2 β sqrt(m* k_s), the same ratio in the
//! tangential mode (LIGGGHTS's `hooke/stiffness` takes γ_n and γ_t as given numbers).

use crate::model::lanes::Lanes;
use crate::model::materials::Material;
use crate::model::registry::NormalModel;

use super::normal::Elastic;

coefficients! {
    /// β of the pair's restitution (Eq. 21) and c_s / c_n = sqrt(k_s / (30 k_n)) =
    /// sqrt(G* / (5 E*)) (Eqs. 18, 19, 25).
    pub struct Viscoelastic {
        beta,
        c_s_per_c_n,
    }
}

/// Damping factor β of Eq. (21), with its limits e_n → 0 (β = 1) and e_n = 1 (β = 0).
pub fn damping_factor(e_n: f64) -> f64 {
    if e_n <= 0.0 {
        1.0
    } else if e_n >= 1.0 {
        0.0
    } else {
        1.0 / (1.0 + (std::f64::consts::PI / e_n.ln()).powi(2)).sqrt()
    }
}

impl Viscoelastic {
    /// Of two particles of materials `m` and `n` (whose moduli are `elastic`) with the
    /// pair's restitution `e_n`, for its normal sub-model `normal`.
    pub fn of_particles(
        m: &Material,
        n: &Material,
        elastic: &Elastic,
        (e_n, normal): (f64, NormalModel),
    ) -> Viscoelastic {
        if normal == NormalModel::Hooke {
            return Viscoelastic::hooke(elastic, e_n);
        }
        let c_s_per_c_n = if m == n {
            let nu = m.poisson_ratio;
            ((1.0 - nu) / (10.0 * (2.0 - nu))).sqrt() // Eq. (25)
        } else {
            (elastic.g_star / (5.0 * elastic.e_star)).sqrt()
        };
        Viscoelastic {
            beta: damping_factor(e_n), // Eq. (21)
            c_s_per_c_n,
        }
    }

    /// Of a particle of material `m` against a rigid wall (moduli `elastic`) with the
    /// pair's restitution `e_n`, for its normal sub-model `normal`.
    pub fn against_wall(
        m: &Material,
        elastic: &Elastic,
        (e_n, normal): (f64, NormalModel),
    ) -> Viscoelastic {
        if normal == NormalModel::Hooke {
            return Viscoelastic::hooke(elastic, e_n);
        }
        let nu = m.poisson_ratio;
        Viscoelastic {
            beta: damping_factor(e_n),                              // Eq. (21)
            c_s_per_c_n: ((1.0 - nu) / (10.0 * (2.0 - nu))).sqrt(), // Eq. (25)
        }
    }
}

impl Viscoelastic {
    /// Of a Hooke pair (constant stiffnesses `elastic`) with restitution `e_n`: see the
    /// module's comment.
    fn hooke(elastic: &Elastic, e_n: f64) -> Viscoelastic {
        Viscoelastic {
            beta: 2.0 * damping_factor(e_n) / 5f64.sqrt(),
            c_s_per_c_n: (elastic.k_s0 / elastic.k_n0).sqrt(),
        }
    }
}

impl<T: Lanes> Viscoelastic<T> {
    /// c_n and c_s of a contact of effective mass `m_star` and normal stiffness `k_n`.
    #[inline(always)]
    pub fn dampers(&self, m_star: T, k_n: T) -> (T, T) {
        let c_n = (T::splat(5.0) * m_star * k_n).sqrt() * self.beta; // Eq. (18)
        (c_n, c_n * self.c_s_per_c_n) // Eq. (19), as Eq. (25)
    }
}
