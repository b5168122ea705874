//! The energy a contact holds, by mode (the energy ledger's `stored_elastic`): the elastic
//! energy of the overlap, the springs' energies and the adhesion's, each sub-model's own.

use super::adhesion::Adhesion;
use super::friction::spring_energy;
use super::{Coefficients, ContactLaw, Kinematics, Models, Other, Springs, effective};
use crate::model::registry::RollingModel;

impl ContactLaw {
    /// The energy held by the contact of particle `i` (radius and mass in `body_i`) with
    /// `other`, at `kin` with its springs `springs` and the pair's coefficients `coef`, by
    /// mode of `ledger::MODES`: normal, sliding, rolling, twisting, adhesion.
    pub fn stored(
        &self,
        coef: &Coefficients,
        body_i: (f64, f64),
        other: Other,
        kin: &Kinematics,
        springs: &Springs,
    ) -> [f64; 5] {
        crate::model::contact::with_models!(self.choice, M => self.stored_by::<M>(coef, body_i, other, kin, springs))
    }

    /// [`ContactLaw::stored`] under the sub-models `M`.
    fn stored_by<M: Models>(
        &self,
        coef: &Coefficients,
        (radius_i, m_i): (f64, f64),
        other: Other,
        kin: &Kinematics,
        springs: &Springs,
    ) -> [f64; 5] {
        let (r_star, _, _, _) = effective(radius_i, m_i, other, kin.r_i, kin.r_j);
        let delta = kin.delta;
        let adhesion = M::Adhesion::energy(&coef.adhesion, (radius_i, r_star), other, delta);
        // A contact apart (a bridge's, JKR's neck) holds no spring energy.
        if delta <= 0.0 {
            let normal = match M::Adhesion::NECK {
                true => M::Adhesion::elastic_energy(&coef.adhesion, &coef.normal, r_star, delta),
                false => 0.0,
            };
            return [normal, 0.0, 0.0, 0.0, adhesion];
        }
        let a = M::Adhesion::contact_radius(&coef.adhesion, r_star, delta); // Eq. (14)
        let stiffness = coef.normal.stiffness_at(a); // Eqs. (12), (13)
        let rolling = match M::DYNAMIC {
            true => self.choice.rolling,
            false => RollingModel::Spring,
        };
        [
            M::Adhesion::elastic_energy(&coef.adhesion, &coef.normal, r_star, delta),
            spring_energy(stiffness.k_s, springs.u_s.length_squared()),
            coef.rolling
                .energy(rolling, stiffness.k_n, r_star, springs.u_r),
            spring_energy(stiffness.k_s, springs.u_t * springs.u_t),
            adhesion,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::materials::{FrictionSprings, Liquid, Material};
    use crate::model::registry::{AdhesionModel, NormalModel};
    use glam::DVec3;

    /// Each model's stored energy is the potential of its force: dU/dδ of the normal and
    /// adhesion energies is the elastic force less the pull, for a pair and on a wall.
    #[test]
    fn stored_energy_is_the_potential_of_the_normal_force() {
        let base = Material {
            density: 2500.0,
            youngs_modulus: 1e7,
            poisson_ratio: 0.3,
            restitution: 1.0,
            friction_sliding: 0.4,
            friction_rolling: 0.05,
            friction_twisting: 0.02,
            viscosity: 0.0,
            cohesion: 0.0,
            surface_energy: 0.0,
            liquid: Liquid::default(),
            hooke_stiffness: 0.0,
            hooke_stiffness_ratio: 2.0 / 7.0,
            models: Default::default(),
            thermal: Default::default(),
        };
        let mut hooke = base.clone();
        (hooke.hooke_stiffness, hooke.models.normal) = (500.0, NormalModel::Hooke);
        let mut sjkr = base.clone();
        sjkr.cohesion = 3e4;
        let mut dmt = base.clone();
        (dmt.surface_energy, dmt.models.adhesion) = (0.05, AdhesionModel::Dmt);
        let mut jkr = base.clone();
        (jkr.surface_energy, jkr.models.adhesion) = (0.05, AdhesionModel::Jkr);
        let mut wet = base.clone();
        wet.liquid = Liquid {
            volume: 1e-10,
            surface_tension: 0.07,
            contact_angle: 20.0,
        };
        let (radius, m) = (5e-3, 1e-3);
        for (name, material, gaps) in [
            ("hertz", base.clone(), false),
            ("hooke", hooke, false),
            ("sjkr", sjkr, false),
            ("dmt", dmt, false),
            ("jkr", jkr, true),
            ("bridge", wet, true),
        ] {
            let law = ContactLaw::new(&material, 1e-6, FrictionSprings::AdvanceFirst);
            for wall in [false, true] {
                let (coef, other, r_j) = match wall {
                    true => (law.with_wall(0, 0), Other::Wall, f64::INFINITY),
                    false => (law.pair(0, 0), Other::Particle { r: radius, m }, radius),
                };
                let kin = |delta: f64| Kinematics {
                    n: DVec3::Z,
                    delta,
                    r_i: radius - 0.5 * delta,
                    r_j: r_j - 0.5 * delta,
                    v: DVec3::ZERO,
                    omega: DVec3::ZERO,
                };
                let u = |delta: f64| {
                    let e = law.stored(coef, (radius, m), other, &kin(delta), &Springs::default());
                    e[0] + e[4]
                };
                // Apart within the reach (JKR's δ_c is some 1e-6 m here).
                let deltas: &[f64] = match gaps {
                    true => &[-5e-7, -2e-7, 1e-6, 2e-5, 1e-4],
                    false => &[1e-6, 2e-5, 1e-4],
                };
                for &delta in deltas {
                    let f = crate::model::contact::with_models!(law.choice(), M => {
                        let mut springs = Springs::default();
                        let body = (radius, m);
                        let (_, p) =
                            law.compose_parts::<M, f64>(coef, body, other, &kin(delta), &mut springs);
                        p.f_normal - p.pull
                    });
                    let h = 1e-4 * delta.abs();
                    let slope = (u(delta + h) - u(delta - h)) / (2.0 * h);
                    assert!(
                        (slope - f).abs() < 1e-5 * f.abs().max(1e-9),
                        "{name} wall {wall} at {delta:e}: dU/dδ {slope:e}, force {f:e}"
                    );
                }
            }
        }
    }
}
