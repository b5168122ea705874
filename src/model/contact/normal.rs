//! The normal sub-model: the elastic stiffnesses k_n and k_s of a contact.
//!
//! - Hertz-Mindlin, the paper's (Eqs. 12-16, 22, 23): both grow with the radius a of the
//!   contact area, k_n = 4/3 E* a, k_s = 8 G* a.
//! - Hooke, the linear spring-dashpot (Cundall & Strack 1979; LIGGGHTS `hooke/stiffness`,
//!   LAMMPS `gran/hooke/history`): constant k_n (`hooke_stiffness`) and k_s = κ k_n
//!   (`hooke_stiffness_ratio` κ, 2/7 by default, the ratio at which the normal and tangential
//!   periods of a sphere on a plane agree).
//!
//! A pair's coefficients hold one of the two: `k_n = k_n0 + 4/3 E* a` with E* = 0 for a
//! Hooke pair and k_n0 = 0 for a Hertz one, so that pairs of both kinds share one loop.

use crate::model::lanes::Lanes;
use crate::model::materials::{Material, PairCoefficients};
use crate::model::registry::NormalModel;

coefficients! {
    /// E* and G* of a Hertz pair: Eqs. (22), (23) for two particles; for a wall, of the
    /// particle against a rigid body (text after Eq. 25). k_n0 and k_s0 of a Hooke pair.
    pub struct Elastic {
        e_star,
        g_star,
        k_n0,
        k_s0,
    }
}

/// The stiffnesses of a contact at its overlap.
#[derive(Clone, Copy, Debug)]
pub struct Stiffness<T: Lanes> {
    /// Normal stiffness k_n, which the rolling mode shares (k_r = k_n).
    pub k_n: T,
    /// Shear stiffness k_s, which the twisting mode shares (k_t = k_s).
    pub k_s: T,
}

impl Elastic {
    /// Of two particles of materials `m` and `n` whose contacts have the coefficients `pair`.
    pub fn of_particles(m: &Material, n: &Material, pair: &PairCoefficients) -> Elastic {
        if pair.models.normal == NormalModel::Hooke {
            return Elastic::hooke(pair);
        }
        if m == n {
            let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
            Elastic {
                e_star: e / (2.0 * (1.0 - nu * nu)),         // Eq. (22)
                g_star: e / (4.0 * (2.0 - nu) * (1.0 + nu)), // Eq. (23)
                k_n0: 0.0,
                k_s0: 0.0,
            }
        } else {
            // Eqs. (22), (23) for two materials: 1/E* = (1 - ν_i²)/E_i + (1 - ν_j²)/E_j,
            // 1/G* = (2 - ν_i)/G_i + (2 - ν_j)/G_j with G = E / (2 (1 + ν)) (Eq. 16).
            let g = |m: &Material| m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
            let compliance =
                |m: &Material| (1.0 - m.poisson_ratio * m.poisson_ratio) / m.youngs_modulus;
            Elastic {
                e_star: 1.0 / (compliance(m) + compliance(n)),
                g_star: 1.0 / ((2.0 - m.poisson_ratio) / g(m) + (2.0 - n.poisson_ratio) / g(n)),
                k_n0: 0.0,
                k_s0: 0.0,
            }
        }
    }

    /// Of a particle of material `m` against a rigid wall, the contacts' coefficients `pair`.
    pub fn against_wall(m: &Material, pair: &PairCoefficients) -> Elastic {
        if pair.models.normal == NormalModel::Hooke {
            return Elastic::hooke(pair);
        }
        let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
        let g = e / (2.0 * (1.0 + nu)); // Eq. (16), G_i
        Elastic {
            e_star: e / (1.0 - nu * nu),
            g_star: g / (2.0 - nu),
            k_n0: 0.0,
            k_s0: 0.0,
        }
    }

    /// A Hooke pair: the pair's k_n and κ k_n.
    fn hooke(pair: &PairCoefficients) -> Elastic {
        Elastic {
            e_star: 0.0,
            g_star: 0.0,
            k_n0: pair.hooke_stiffness,
            k_s0: pair.hooke_stiffness_ratio * pair.hooke_stiffness,
        }
    }
}

impl Elastic {
    /// The elastic energy ∫ f_n dδ of a contact of effective radius `r_star` at overlap
    /// `delta` (the energy ledger's): Hooke's k_n δ²/2, Hertz's 2/5 k_n δ² (f_n ∝ δ^(3/2)).
    pub fn energy(&self, r_star: f64, delta: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        let a = (r_star * delta).sqrt(); // Eq. (14)
        (0.5 * self.k_n0 + 8.0 / 15.0 * self.e_star * a) * delta * delta
    }
}

impl<T: Lanes> Elastic<T> {
    /// k_n and k_s at overlap `delta` of a contact of effective radius `r_star`.
    #[inline(always)]
    pub fn stiffness(&self, r_star: T, delta: T) -> Stiffness<T> {
        self.stiffness_at((r_star * delta).sqrt()) // Eq. (14)
    }

    /// k_n and k_s of a contact whose contact area has the radius `a`.
    #[inline(always)]
    pub fn stiffness_at(&self, a: T) -> Stiffness<T> {
        Stiffness {
            k_n: self.k_n0 + T::splat(4.0 / 3.0) * self.e_star * a, // Eq. (12)
            k_s: self.k_s0 + T::splat(8.0) * self.g_star * a,       // Eq. (13)
        }
    }
}
