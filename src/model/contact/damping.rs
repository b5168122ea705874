//! The damping sub-model: viscoelastic dashpots c_n, c_s from the pair's restitution
//! (Eqs. 18, 19, 21, 25), in parallel with the springs of every mode.

use crate::model::lanes::Lanes;
use crate::model::materials::Material;

use super::normal::Hertz;

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
    /// pair's restitution `e_n`.
    pub fn of_particles(m: &Material, n: &Material, elastic: &Hertz, e_n: f64) -> Viscoelastic {
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

    /// Of a particle of material `m` against a rigid wall with the pair's restitution `e_n`.
    pub fn against_wall(m: &Material, e_n: f64) -> Viscoelastic {
        let nu = m.poisson_ratio;
        Viscoelastic {
            beta: damping_factor(e_n),                              // Eq. (21)
            c_s_per_c_n: ((1.0 - nu) / (10.0 * (2.0 - nu))).sqrt(), // Eq. (25)
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
