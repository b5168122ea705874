//! The visco-elastic Hertz-Mindlin contact law with sliding, rolling and twisting
//! friction (paper Section 2.2 and the spring update of Section 2.3, Eqs. 51-55), composed
//! of sub-models: normal (`normal.rs`), damping (`damping.rs`), sliding, rolling and
//! twisting friction (`sliding.rs`, `rolling.rs`, `twisting.rs` on the spring of
//! `friction.rs`) and adhesion (`adhesion.rs`), named in `model/registry.rs` and composed in `composition.rs`.
//!
//! Sign convention as in the paper: vectors are those of body `i` relative to body `j`,
//! forces and torques act on `i`. A contact is evaluated once per pair; the reaction on
//! `j` follows from the antisymmetries (56)-(60).
//!
//! | symbol | here | meaning | unit |
//! |---|---|---|---|
//! | δ | `delta` | overlap, Eq. (7) | L |
//! | n̂ | `n` | unit normal from j to i, Eq. (9) | - |
//! | R*, m* | `r_star`, `m_star` | effective radius and mass, Eqs. (17), (20) | L, M |
//! | E*, G* | `e_star`, `g_star` | effective Young's and shear modulus, Eqs. (15), (16) | M/LT² |
//! | a | `a` | radius of the Hertzian contact area, Eq. (14) | L |
//! | k_n, k_s | `k_n`, `k_s` | normal and shear stiffness, Eqs. (12), (13) | M/T² |
//! | c_n, c_s | `c_n`, `c_s` | normal and shear damping, Eqs. (18), (19) | M/T |
//! | β | `beta` | damping factor from e_n, Eq. (21) | - |
//! | r_i, r_j | `r_i`, `r_j` | centre to contact point, Eqs. (29), (30) | L |
//! | u_s, u_r, u_t | [`Springs`] | static friction spring displacements, Eq. (51) | L |
//! | μ_s, μ_r, μ_t | `mu_s`, `mu_r`, `mu_t` | Coulomb coefficients, Eqs. (11), (39), (40) | - |
//! | k_c | `k_c` | simplified JKR cohesion | M/LT² |

use crate::model::lanes::{Displacement, Lanes};
use crate::model::materials::{FrictionSprings, Material, PairCoefficients};
use crate::model::registry::{AdhesionModel, RollingModel, TangentialCoulomb};
pub use crate::model::springs::Springs;

/// A sub-model's coefficients of one pair, over lanes: the struct, with `splat` (the same
/// in every lane) and `gather` (one pair's in each lane).
macro_rules! coefficients {
    ($(#[$m:meta])* pub struct $name:ident { $($(#[$fm:meta])* $field:ident,)* }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name<T: $crate::model::lanes::Lanes = f64> {
            $($(#[$fm])* pub $field: T,)*
        }

        impl $name {
            #[inline(always)]
            pub fn splat<T: $crate::model::lanes::Lanes>(&self) -> $name<T> {
                $name { $($field: T::splat(self.$field),)* }
            }

            #[inline(always)]
            pub fn gather<T: $crate::model::lanes::Gather<N>, const N: usize>(
                c: [&$name; N],
            ) -> $name<T> {
                $name { $($field: T::gather(c.map(|c| c.$field)),)* }
            }
        }
    };
}

pub mod adhesion;
pub mod composition;
pub mod damping;
mod energy;
pub mod friction;
pub mod kinematics;
pub mod normal;
pub mod rolling;
pub mod sliding;
pub mod twisting;

pub(crate) use composition::with_models;
pub use composition::{Choice, Models};
pub use damping::damping_factor;
pub use kinematics::{Body, Kinematics, Other};

use adhesion::{Adhesion, Cohesion};
use damping::Viscoelastic;
use normal::{Elastic, Stiffness};
use rolling::Rolling;
use sliding::Sliding;
use twisting::Twisting;

/// The constants of the contact law for one pair of materials (a particle's with another
/// particle's, or with a wall's), derived once: one per pair, or one per lane of a group.
/// Each sub-model owns its part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients<T: Lanes = f64> {
    pub normal: Elastic<T>,
    pub damping: Viscoelastic<T>,
    pub sliding: Sliding<T>,
    pub rolling: Rolling<T>,
    pub twisting: Twisting<T>,
    pub adhesion: Cohesion<T>,
}

impl Coefficients {
    /// Of two particles of materials `m` and `n` with the pair's coefficients `pair`.
    fn of_particles(m: &Material, n: &Material, pair: &PairCoefficients) -> Coefficients {
        let normal = Elastic::of_particles(m, n, pair);
        let e_n = (pair.restitution, pair.models.normal);
        Coefficients {
            damping: Viscoelastic::of_particles(m, n, &normal, e_n),
            normal,
            ..Self::friction_and_adhesion(pair, normal.e_star)
        }
    }

    /// Of a particle of material `m` against a rigid wall; the wall's material enters
    /// through the pair's restitution and friction.
    fn against_wall(m: &Material, pair: &PairCoefficients) -> Coefficients {
        let normal = Elastic::against_wall(m, pair);
        let e_n = (pair.restitution, pair.models.normal);
        Coefficients {
            damping: Viscoelastic::against_wall(m, &normal, e_n),
            normal,
            ..Self::friction_and_adhesion(pair, normal.e_star)
        }
    }

    /// The pair's friction and adhesion (JKR's with the pair's E*), with the elastic parts
    /// left zero.
    fn friction_and_adhesion(pair: &PairCoefficients, e_star: f64) -> Coefficients {
        Coefficients {
            normal: Elastic {
                e_star: 0.0,
                g_star: 0.0,
                k_n0: 0.0,
                k_s0: 0.0,
            },
            damping: Viscoelastic {
                beta: 0.0,
                c_s_per_c_n: 0.0,
            },
            sliding: Sliding {
                mu_s: pair.friction_sliding,
            },
            rolling: Rolling {
                mu_r: pair.friction_rolling,
            },
            twisting: Twisting {
                mu_t: pair.friction_twisting,
            },
            adhesion: Cohesion::of(pair, e_star),
        }
    }

    /// The same coefficients in every lane.
    #[inline(always)]
    pub fn splat<T: Lanes>(&self) -> Coefficients<T> {
        Coefficients {
            normal: self.normal.splat(),
            damping: self.damping.splat(),
            sliding: self.sliding.splat(),
            rolling: self.rolling.splat(),
            twisting: self.twisting.splat(),
            adhesion: self.adhesion.splat(),
        }
    }

    /// Coefficients `c[l]` in lane `l`.
    #[inline(always)]
    pub fn gather<T: crate::model::lanes::Gather<N>, const N: usize>(
        c: [&Coefficients; N],
    ) -> Coefficients<T> {
        Coefficients {
            normal: Elastic::gather(c.map(|c| &c.normal)),
            damping: Viscoelastic::gather(c.map(|c| &c.damping)),
            sliding: Sliding::gather(c.map(|c| &c.sliding)),
            rolling: Rolling::gather(c.map(|c| &c.rolling)),
            twisting: Twisting::gather(c.map(|c| &c.twisting)),
            adhesion: Cohesion::gather(c.map(|c| &c.adhesion)),
        }
    }
}

/// The contact law of Section 2.2 with its constants for every pair of materials.
#[derive(Clone, Debug)]
pub struct ContactLaw {
    /// Number of materials.
    materials: usize,
    /// Particle-particle coefficients of materials (a, b) at `a * materials + b`.
    pairs: Vec<Coefficients>,
    /// Particle-wall coefficients of particle material a and wall material w at
    /// `a * materials + w`.
    walls: Vec<Coefficients>,
    dt: f64,
    /// The sub-models in force.
    choice: Choice,
}

/// Force and torques of one contact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce<T: Lanes = f64> {
    /// f_n + f_s on body i; body j receives the opposite, Eqs. (56), (57).
    pub f: T::Vec,
    /// τ_s + τ_r + τ_t on body i.
    pub tau_i: T::Vec,
    /// Torque on body j: (r_j / r_i) τ_s - τ_r - τ_t, Eqs. (58)-(60).
    pub tau_j: T::Vec,
}

/// A contact's force and torques by mode, for the energy ledger: the work each does.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactParts<T: Lanes = f64> {
    /// k_n δ - c_n v_n along n̂, the elastic and damped normal force on body i.
    pub f_normal: T,
    /// The adhesion's pull along -n̂.
    pub pull: T,
    /// f_s, the sliding force on body i (its torques follow from the arms).
    pub f_s: T::Vec,
    /// τ_r and τ_t on body i.
    pub tau_r: T::Vec,
    pub tau_t: T::Vec,
}

/// What the sub-models of one contact share, computed once: its geometry, effective
/// quantities, stiffnesses, dampers and normal load.
#[derive(Clone, Copy, Debug)]
pub struct Shared<T: Lanes> {
    /// n̂, Eq. (9).
    pub n: T::Vec,
    /// r_i, Eq. (29).
    pub r_i: T,
    /// R*, Eq. (17).
    pub r_star: T,
    /// (1/r_i + 1/r_j)^-1 of Eq. (36).
    pub r_roll: T,
    /// ω = ω_i - ω_j, Eq. (38).
    pub omega: T::Vec,
    /// v_s, Eq. (28).
    pub v_s: T::Vec,
    pub stiffness: Stiffness<T>,
    pub c_n: T,
    pub c_s: T,
    /// |f_n|, the load of the Coulomb limits.
    pub f_n_norm: T,
    pub dt: T,
}

impl ContactLaw {
    /// The law for one material (the paper's), with the springs' update in `springs`' order.
    pub fn new(material: &Material, dt: f64, springs: FrictionSprings) -> Self {
        let pair = PairCoefficients {
            restitution: material.restitution,
            friction_sliding: material.friction_sliding,
            friction_rolling: material.friction_rolling,
            friction_twisting: material.friction_twisting,
            cohesion: material.cohesion,
            surface_energy: material.surface_energy,
            liquid: material.liquid,
            hooke_stiffness: material.hooke_stiffness,
            hooke_stiffness_ratio: material.hooke_stiffness_ratio,
            models: material.models,
            given: false,
        };
        Self::of(std::slice::from_ref(material), |_, _| pair, dt, springs)
    }

    /// The law for every pair of `materials`, with the coefficients `pair(a, b)` of the
    /// contacts between materials `a` and `b` (`Scenario::pair`), the time step `dt` and the
    /// springs' update in `springs`' order.
    pub fn of(
        materials: &[Material],
        pair: impl Fn(u16, u16) -> PairCoefficients,
        dt: f64,
        springs: FrictionSprings,
    ) -> Self {
        let n = materials.len();
        let m = |a: usize| &materials[a];
        let mut law = ContactLaw {
            materials: n,
            pairs: Vec::with_capacity(n * n),
            walls: Vec::with_capacity(n * n),
            dt,
            choice: Choice {
                adhesion: AdhesionModel::None,
                bridges: false,
                springs,
                rolling: RollingModel::default(),
                tangential: TangentialCoulomb::default(),
            },
        };
        for a in 0..n {
            for b in 0..n {
                let pair = pair(a as u16, b as u16);
                law.pairs
                    .push(Coefficients::of_particles(m(a), m(b), &pair));
                law.walls.push(Coefficients::against_wall(m(a), &pair));
                if pair.cohesion > 0.0 || pair.surface_energy > 0.0 {
                    law.choice.adhesion = pair.models.adhesion;
                }
                law.choice.bridges |= pair.liquid.wet();
                // One rolling model and one Coulomb test per run (the scenario refuses
                // pairs that differ).
                law.choice.rolling = pair.models.rolling;
                law.choice.tangential = pair.models.tangential;
            }
        }
        law
    }

    /// The sub-models in force, for `with_models!`.
    #[inline]
    pub fn choice(&self) -> Choice {
        self.choice
    }

    /// The largest gap at which a contact of the run's law ends (its adhesion's reach) for
    /// particles up to the radius `r_max`: the lists' skin must cover it.
    pub fn largest_reach(&self, r_max: f64) -> f64 {
        with_models!(self.choice, M => {
            let pairs = self.pairs.iter().map(|c| Self::reach::<M>(c, 0.5 * r_max));
            let walls = self.walls.iter().map(|c| Self::reach::<M>(c, r_max));
            pairs.chain(walls).fold(0.0, f64::max)
        })
    }

    /// Whether the run's contacts may outlast touch (JKR, liquid bridges).
    pub fn beyond_touch(&self) -> bool {
        with_models!(self.choice, M => M::BEYOND_TOUCH)
    }

    /// The gap at which an open contact with the coefficients `coef` and the effective
    /// radius `r_star` ends under the run's sub-models (off the hot loops: reports).
    pub fn reach_of(&self, coef: &Coefficients, r_star: f64) -> f64 {
        with_models!(self.choice, M => Self::reach::<M>(coef, r_star))
    }

    /// The gap at which an open contact with the coefficients `coef` and the effective
    /// radius `r_star` ends under the sub-models `M` (0: at touch).
    #[inline(always)]
    pub fn reach<M: Models>(coef: &Coefficients, r_star: f64) -> f64 {
        M::Adhesion::reach(&coef.adhesion, r_star)
    }

    /// Whether every contact has the same coefficients (one material).
    #[inline]
    pub fn uniform(&self) -> bool {
        self.materials == 1
    }

    /// The coefficients of two particles of materials `a` and `b`.
    #[inline(always)]
    pub fn pair(&self, a: u16, b: u16) -> &Coefficients {
        &self.pairs[a as usize * self.materials + b as usize]
    }

    /// The coefficients of a particle of material `a` against a wall of material `w`.
    #[inline(always)]
    pub fn with_wall(&self, a: u16, w: u16) -> &Coefficients {
        &self.walls[a as usize * self.materials + w as usize]
    }

    /// The law with every E* times `factor`: a wrong model, for the tests that must see it fail.
    #[cfg(test)]
    pub(crate) fn stiffer(&mut self, factor: f64) {
        for c in self.pairs.iter_mut().chain(&mut self.walls) {
            c.normal.e_star *= factor;
            c.normal.k_n0 *= factor;
        }
    }

    /// Normal stiffness k_n at overlap `delta` between two particles of radii `r_i`, `r_j`
    /// (Eqs. 12, 14, 17); used for reporting derived quantities.
    pub fn normal_stiffness(&self, r_i: f64, r_j: f64, delta: f64) -> f64 {
        let r_star = 1.0 / (1.0 / r_i + 1.0 / r_j);
        self.pair(0, 0).normal.stiffness(r_star, delta).k_n
    }

    /// [`ContactLaw::compose`] with the run's sub-models, chosen at this call: for one
    /// contact at a time off the hot loops (reports, tests).
    #[inline]
    pub fn evaluate<T>(
        &self,
        coef: &Coefficients<T>,
        radius_i: T,
        m_i: T,
        other: Other<T>,
        kin: &Kinematics<T>,
        springs: &mut Springs<T>,
    ) -> ContactForce<T>
    where
        T: Lanes + Displacement<T>,
        T::Vec: Displacement<T>,
    {
        with_models!(self.choice, M => self.compose::<M, T>(coef, radius_i, m_i, other, kin, springs))
    }

    /// Evaluates the contact of particle `i` (radius `radius_i`, mass `m_i`) with body
    /// `other` with the pair's coefficients `coef` and the sub-models `M`, updating the
    /// friction springs for the next time step. One contact, or several in lanes.
    #[inline(always)]
    pub fn compose<M: Models, T>(
        &self,
        coef: &Coefficients<T>,
        radius_i: T,
        m_i: T,
        other: Other<T>,
        kin: &Kinematics<T>,
        springs: &mut Springs<T>,
    ) -> ContactForce<T>
    where
        T: Lanes + Displacement<T>,
        T::Vec: Displacement<T>,
    {
        self.compose_parts::<M, T>(coef, (radius_i, m_i), other, kin, springs)
            .0
    }

    /// [`ContactLaw::compose`] with the force and torques by mode (the energy ledger's);
    /// body i's radius and mass in `body_i`.
    #[inline(always)]
    pub fn compose_parts<M: Models, T>(
        &self,
        coef: &Coefficients<T>,
        (radius_i, m_i): (T, T),
        other: Other<T>,
        kin: &Kinematics<T>,
        springs: &mut Springs<T>,
    ) -> (ContactForce<T>, ContactParts<T>)
    where
        T: Lanes + Displacement<T>,
        T::Vec: Displacement<T>,
    {
        let Kinematics {
            n,
            delta,
            r_i,
            r_j,
            v,
            omega,
        } = *kin;
        let (r_star, m_star, r_roll, r_j_per_r_i) = effective(radius_i, m_i, other, r_i, r_j);
        let a = M::Adhesion::contact_radius(&coef.adhesion, r_star, delta); // Eq. (14)
        let stiffness = coef.normal.stiffness_at(a); // Eqs. (12), (13)
        let (c_n, c_s) = coef.damping.dampers(m_star, stiffness.k_n); // Eqs. (18), (19)

        // Normal force, along n̂: f_n = -k_n u_n - c_n v_n with u_n = -δ n̂ (Eqs. 5, 10).
        let v_dot_n = T::dot(v, n);
        let v_n = n * v_dot_n; // Eq. (27)
        let f_n_scalar = stiffness.k_n * delta - c_n * v_dot_n;
        let radii = (radius_i, r_star);
        let pull = M::Adhesion::pull(&coef.adhesion, radii, other, delta, a);
        let at = Shared {
            n,
            r_i,
            r_star,
            r_roll,
            omega,
            v_s: v - v_n, // Eq. (28)
            stiffness,
            c_n,
            c_s,
            f_n_norm: M::Adhesion::coulomb_load(&coef.adhesion, f_n_scalar, pull, r_star),
            dt: T::splat(self.dt),
        };

        let (rolling, tangential) = if M::DYNAMIC {
            (self.choice.rolling, self.choice.tangential)
        } else {
            (RollingModel::Spring, TangentialCoulomb::Total)
        };
        let (f_s, tau_s) = coef
            .sliding
            .force::<M::Order>(tangential, &at, &mut springs.u_s);
        let tau_r = coef
            .rolling
            .torque::<M::Order>(rolling, &at, &mut springs.u_r);
        let tau_t = coef.twisting.torque::<M::Order>(&at, &mut springs.u_t);
        let mut force = ContactForce {
            f: if M::Adhesion::PULLS {
                n * f_n_scalar + f_s - n * pull // Eq. (5), f_s and the pull
            } else {
                n * f_n_scalar + f_s // Eq. (5) and f_s
            },
            tau_i: tau_s + tau_r + tau_t,
            // A wall takes no reaction torque; avoid ∞ · 0 there.
            tau_j: match other {
                Other::Particle { .. } => tau_s * r_j_per_r_i - tau_r - tau_t, // Eqs. (58)-(60)
                Other::Wall => T::Vec::default(),
            },
        };
        let mut parts = ContactParts {
            f_normal: f_n_scalar,
            pull,
            f_s,
            tau_r,
            tau_t,
        };
        if M::Adhesion::BEYOND_TOUCH && !M::Adhesion::NECK {
            // Apart, a bridge alone: no solid contact, and its springs start afresh.
            let apart = delta.le(T::splat(0.0));
            let zero = T::splat_vec(glam::DVec3::ZERO);
            force.f = T::pick_vec(apart, || n * -pull, || force.f);
            force.tau_i = T::pick_vec(apart, || zero, || force.tau_i);
            force.tau_j = T::pick_vec(apart, || zero, || force.tau_j);
            springs.forget_where(apart);
            parts.f_normal = <T as Lanes>::pick(apart, || T::splat(0.0), || f_n_scalar);
            parts.f_s = T::pick_vec(apart, || zero, || f_s);
            parts.tau_r = T::pick_vec(apart, || zero, || tau_r);
            parts.tau_t = T::pick_vec(apart, || zero, || tau_t);
        }
        (force, parts)
    }
}

/// R*, m*, (1/r_i + 1/r_j)^-1 and r_j / r_i of body i (radius `radius_i`, mass `m_i`,
/// contact point at `r_i`) against `other` (contact point at `r_j`); for a wall R_j = m_j =
/// r_j = ∞. The four quotients of a particle pair share one division (it costs as much as
/// a dozen multiplications): with A = (R_i + R_j)(m_i + m_j) and B = r_i (r_i + r_j),
/// 1/A = B/(AB), 1/B = A/(AB).
#[inline(always)]
fn effective<T: Lanes>(radius_i: T, m_i: T, other: Other<T>, r_i: T, r_j: T) -> (T, T, T, T) {
    match other {
        Other::Particle {
            r: radius_j,
            m: m_j,
        } => {
            let (sum_r, sum_m, sum_contact) = (radius_i + radius_j, m_i + m_j, r_i + r_j);
            let a = sum_r * sum_m;
            let b = r_i * sum_contact;
            let inv_ab = T::splat(1.0) / (a * b);
            let (inv_a, inv_b) = (b * inv_ab, a * inv_ab);
            (
                radius_i * radius_j * sum_m * inv_a, // Eq. (17)
                m_i * m_j * sum_r * inv_a,           // Eq. (20)
                r_i * r_i * r_j * inv_b,             // (1/r_i + 1/r_j)^-1 of Eq. (36)
                r_j * sum_contact * inv_b,
            )
        }
        Other::Wall => (radius_i, m_i, r_i, T::splat(0.0)),
    }
}

#[cfg(test)]
mod tests;
