//! The normal sub-model: the elastic stiffnesses k_n and k_s of a contact. Hertz-Mindlin,
//! the paper's (Eqs. 12-16, 22, 23): both grow with the radius a of the contact area.

use crate::model::lanes::Lanes;
use crate::model::materials::Material;

coefficients! {
    /// E* and G* of a pair: Eqs. (22), (23) for two particles; for a wall, of the particle
    /// against a rigid body (text after Eq. 25).
    pub struct Hertz {
        e_star,
        g_star,
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

impl Hertz {
    /// Of two particles of materials `m` and `n`.
    pub fn of_particles(m: &Material, n: &Material) -> Hertz {
        if m == n {
            let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
            Hertz {
                e_star: e / (2.0 * (1.0 - nu * nu)),         // Eq. (22)
                g_star: e / (4.0 * (2.0 - nu) * (1.0 + nu)), // Eq. (23)
            }
        } else {
            // Eqs. (22), (23) for two materials: 1/E* = (1 - ν_i²)/E_i + (1 - ν_j²)/E_j,
            // 1/G* = (2 - ν_i)/G_i + (2 - ν_j)/G_j with G = E / (2 (1 + ν)) (Eq. 16).
            let g = |m: &Material| m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
            let compliance =
                |m: &Material| (1.0 - m.poisson_ratio * m.poisson_ratio) / m.youngs_modulus;
            Hertz {
                e_star: 1.0 / (compliance(m) + compliance(n)),
                g_star: 1.0 / ((2.0 - m.poisson_ratio) / g(m) + (2.0 - n.poisson_ratio) / g(n)),
            }
        }
    }

    /// Of a particle of material `m` against a rigid wall.
    pub fn against_wall(m: &Material) -> Hertz {
        let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
        let g = e / (2.0 * (1.0 + nu)); // Eq. (16), G_i
        Hertz {
            e_star: e / (1.0 - nu * nu),
            g_star: g / (2.0 - nu),
        }
    }
}

impl<T: Lanes> Hertz<T> {
    /// k_n and k_s at overlap `delta` of a contact of effective radius `r_star`.
    #[inline(always)]
    pub fn stiffness(&self, r_star: T, delta: T) -> Stiffness<T> {
        let a = (r_star * delta).sqrt(); // Eq. (14)
        Stiffness {
            k_n: T::splat(4.0 / 3.0) * self.e_star * a, // Eq. (12)
            k_s: T::splat(8.0) * self.g_star * a,       // Eq. (13)
        }
    }
}
