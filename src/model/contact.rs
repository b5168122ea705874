//! The visco-elastic Hertz-Mindlin contact law with sliding, rolling and twisting
//! friction (paper Section 2.2 and the spring update of Section 2.3, Eqs. 51-55).
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

use glam::DVec3;

use crate::model::lanes::{Displacement, Gather, Lanes};
use crate::model::materials::{FrictionSprings, Material, PairCoefficients};
use crate::model::motion::RigidVelocity;
pub use crate::model::springs::Springs;

/// The constants of the contact law for one pair of materials (a particle's with another
/// particle's, or with a wall's), derived once: one per pair, or one per lane of a group.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients<T: Lanes = f64> {
    /// E* and G*, Eqs. (22), (23) for two materials; for a wall, of the particle against a
    /// rigid body (text after Eq. 25).
    pub e_star: T,
    pub g_star: T,
    /// Damping factor β of the pair's restitution, Eq. (21).
    pub beta: T,
    /// c_s / c_n = sqrt(k_s / (30 k_n)) = sqrt(G* / (5 E*)), Eqs. (18), (19), (25).
    pub c_s_per_c_n: T,
    /// μ_s, μ_r, μ_t of the pair.
    pub mu_s: T,
    pub mu_r: T,
    pub mu_t: T,
    /// k_c of the simplified JKR cohesion [J/m³].
    pub cohesion: T,
}

impl Coefficients {
    /// The same coefficients in every lane.
    #[inline(always)]
    pub fn splat<T: Lanes>(&self) -> Coefficients<T> {
        Coefficients {
            e_star: T::splat(self.e_star),
            g_star: T::splat(self.g_star),
            beta: T::splat(self.beta),
            c_s_per_c_n: T::splat(self.c_s_per_c_n),
            mu_s: T::splat(self.mu_s),
            mu_r: T::splat(self.mu_r),
            mu_t: T::splat(self.mu_t),
            cohesion: T::splat(self.cohesion),
        }
    }

    /// Coefficients `c[l]` in lane `l`.
    #[inline(always)]
    pub fn gather<T: Gather<N>, const N: usize>(c: [&Coefficients; N]) -> Coefficients<T> {
        Coefficients {
            e_star: T::gather(c.map(|c| c.e_star)),
            g_star: T::gather(c.map(|c| c.g_star)),
            beta: T::gather(c.map(|c| c.beta)),
            c_s_per_c_n: T::gather(c.map(|c| c.c_s_per_c_n)),
            mu_s: T::gather(c.map(|c| c.mu_s)),
            mu_r: T::gather(c.map(|c| c.mu_r)),
            mu_t: T::gather(c.map(|c| c.mu_t)),
            cohesion: T::gather(c.map(|c| c.cohesion)),
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
    /// Whether any pair is cohesive (otherwise the law skips the cohesion term).
    cohesive: bool,
    dt: f64,
    /// Whether the springs advance before their force is taken (`friction_springs`).
    advance_first: bool,
}

/// What body `j` of a contact is, as far as the law is concerned.
#[derive(Clone, Copy, Debug)]
pub enum Other<T: Lanes = f64> {
    /// Another particle, with radius R_j and mass m_j.
    Particle { r: T, m: T },
    /// A mesh element: infinitely flat, stiff and heavy (R_j = E_j = m_j = ∞).
    Wall,
}

/// Position, radius and velocities of a particle entering a contact.
#[derive(Clone, Copy, Debug)]
pub struct Body<T: Lanes = f64> {
    pub x: T::Vec,
    pub radius: T,
    pub v: T::Vec,
    pub w: T::Vec,
}

/// Geometry and relative motion of one contact, computed once and shared by all modes.
#[derive(Clone, Copy, Debug)]
pub struct Kinematics<T: Lanes = f64> {
    /// Unit normal n̂ pointing from j to i, Eq. (9).
    pub n: T::Vec,
    /// Overlap δ > 0, Eq. (7).
    pub delta: T,
    /// Distances of the contact point from the centres, Eqs. (29), (30); r_j = ∞ for a wall.
    pub r_i: T,
    pub r_j: T,
    /// Total relative velocity of the material points at the contact, Eq. (26).
    pub v: T::Vec,
    /// Relative angular velocity ω = ω_i - ω_j, Eq. (38).
    pub omega: T::Vec,
}

/// Unit vector of `d` with length `dist`; two coincident centres get an arbitrary but fixed
/// normal instead of NaN.
#[inline(always)]
fn unit<T: Lanes>(d: T::Vec, dist: T) -> T::Vec {
    T::pick_vec(
        dist.positive(),
        || d * (T::splat(1.0) / dist),
        || T::splat_vec(DVec3::Z),
    )
}

impl<T: Lanes> Kinematics<T> {
    /// The contact of particles `i` and `j`, known to overlap: |x_i - x_j|² = `dist2` <
    /// (R_i + R_j)².
    #[inline(always)]
    pub fn of_touching_particles(i: &Body<T>, j: &Body<T>, d: T::Vec, dist2: T) -> Self {
        let reach = i.radius + j.radius;
        let dist = dist2.sqrt();
        let delta = reach - dist; // Eq. (7)
        let n = unit(d, dist); // Eq. (9)
        let half = T::splat(0.5);
        let r_i = i.radius - delta * half; // Eq. (29)
        let r_j = j.radius - delta * half; // Eq. (30)
        Kinematics {
            n,
            delta,
            r_i,
            r_j,
            // Eq. (26), sign as in the guide's "Physics notes"
            v: i.v - j.v + T::cross(n, i.w * r_i + j.w * r_j),
            omega: i.w - j.w, // Eq. (38)
        }
    }
}

impl Kinematics {
    /// The contact of particles `i` and `j`, or `None` if they do not overlap.
    #[inline]
    pub fn between_particles(i: &Body, j: &Body) -> Option<Kinematics> {
        let d = i.x - j.x; // Eq. (8)
        let reach = i.radius + j.radius;
        let dist2 = d.length_squared();
        if dist2 >= reach * reach {
            return None;
        }
        Some(Kinematics::of_touching_particles(i, j, d, dist2))
    }

    /// The contact of particle `i` with a mesh face of radius `face_radius`, whose closest
    /// point lies at `d` = x_i - p from the centre and which moves with the rigid velocity
    /// field `wall` (zero for a static mesh), or `None` if they do not overlap.
    #[inline]
    pub fn with_wall(
        i: &Body,
        d: DVec3,
        face_radius: f64,
        wall: &RigidVelocity,
    ) -> Option<Kinematics> {
        let reach = i.radius + face_radius;
        let dist2 = d.length_squared();
        if dist2 >= reach * reach {
            return None;
        }
        let dist = dist2.sqrt();
        let delta = reach - dist; // Eq. (7)
        let n = unit::<f64>(d, dist); // Eq. (9)
        let r_i = i.radius - delta / 2.0; // Eq. (29)
        let contact_point = i.x - r_i * n;
        Some(Kinematics {
            n,
            delta,
            r_i,
            r_j: f64::INFINITY,
            // Eq. (26) with the wall's material velocity at the contact point for v_j.
            v: i.v + n.cross(r_i * i.w) - wall.at(contact_point),
            omega: i.w - wall.omega, // Eq. (38)
        })
    }
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

impl ContactLaw {
    /// The law for one material (the paper's), with the springs' update in `springs`' order.
    pub fn new(material: &Material, dt: f64, springs: FrictionSprings) -> Self {
        let pair = PairCoefficients {
            restitution: material.restitution,
            friction_sliding: material.friction_sliding,
            friction_rolling: material.friction_rolling,
            friction_twisting: material.friction_twisting,
            cohesion: material.cohesion,
            given: false,
        };
        ContactLaw {
            materials: 1,
            pairs: vec![Self::particles(material, material, &pair)],
            walls: vec![Self::wall(material, &pair)],
            cohesive: pair.cohesion > 0.0,
            dt,
            advance_first: springs == FrictionSprings::AdvanceFirst,
        }
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
            cohesive: false,
            dt,
            advance_first: springs == FrictionSprings::AdvanceFirst,
        };
        for a in 0..n {
            for b in 0..n {
                let pair = pair(a as u16, b as u16);
                law.pairs.push(Self::particles(m(a), m(b), &pair));
                law.walls.push(Self::wall(m(a), &pair));
                law.cohesive |= pair.cohesion > 0.0;
            }
        }
        law
    }

    /// Coefficients of two particles of materials `m` and `n`.
    fn particles(m: &Material, n: &Material, pair: &PairCoefficients) -> Coefficients {
        let (e_star, g_star, c_s_per_c_n) = if m == n {
            let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
            (
                e / (2.0 * (1.0 - nu * nu)),               // Eq. (22)
                e / (4.0 * (2.0 - nu) * (1.0 + nu)),       // Eq. (23)
                ((1.0 - nu) / (10.0 * (2.0 - nu))).sqrt(), // Eq. (25)
            )
        } else {
            // Eqs. (22), (23) for two materials: 1/E* = (1 - ν_i²)/E_i + (1 - ν_j²)/E_j,
            // 1/G* = (2 - ν_i)/G_i + (2 - ν_j)/G_j with G = E / (2 (1 + ν)) (Eq. 16).
            let g = |m: &Material| m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
            let compliance =
                |m: &Material| (1.0 - m.poisson_ratio * m.poisson_ratio) / m.youngs_modulus;
            let e_star = 1.0 / (compliance(m) + compliance(n));
            let g_star = 1.0 / ((2.0 - m.poisson_ratio) / g(m) + (2.0 - n.poisson_ratio) / g(n));
            (e_star, g_star, (g_star / (5.0 * e_star)).sqrt())
        };
        Coefficients {
            e_star,
            g_star,
            beta: damping_factor(pair.restitution), // Eq. (21)
            c_s_per_c_n,
            mu_s: pair.friction_sliding,
            mu_r: pair.friction_rolling,
            mu_t: pair.friction_twisting,
            cohesion: pair.cohesion,
        }
    }

    /// Coefficients of a particle of material `m` against a rigid wall; the wall's material
    /// enters through the pair's restitution and friction.
    fn wall(m: &Material, pair: &PairCoefficients) -> Coefficients {
        let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
        let g = e / (2.0 * (1.0 + nu)); // Eq. (16), G_i
        Coefficients {
            e_star: e / (1.0 - nu * nu),
            g_star: g / (2.0 - nu),
            beta: damping_factor(pair.restitution), // Eq. (21)
            c_s_per_c_n: ((1.0 - nu) / (10.0 * (2.0 - nu))).sqrt(), // Eq. (25)
            mu_s: pair.friction_sliding,
            mu_r: pair.friction_rolling,
            mu_t: pair.friction_twisting,
            cohesion: pair.cohesion,
        }
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

    /// Normal stiffness k_n at overlap `delta` between two particles of radii `r_i`, `r_j`
    /// (Eqs. 12, 14, 17); used for reporting derived quantities.
    pub fn normal_stiffness(&self, r_i: f64, r_j: f64, delta: f64) -> f64 {
        let r_star = 1.0 / (1.0 / r_i + 1.0 / r_j);
        4.0 / 3.0 * self.pair(0, 0).e_star * (r_star * delta).sqrt()
    }

    /// Evaluates the contact of particle `i` (radius `radius_i`, mass `m_i`) with body
    /// `other` with the pair's coefficients `coef`, updating the friction springs for the
    /// next time step. One contact, or several in lanes.
    // Kept whole: it reads top to bottom as Section 2.2, Eq. 11 to Eq. 45, and a split
    // would scatter the law over helpers that each carry most of its inputs.
    #[allow(clippy::too_many_lines)]
    #[inline(always)]
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
        let Kinematics {
            n,
            delta,
            r_i,
            r_j,
            v,
            omega,
        } = *kin;
        let c = T::splat;
        // Effective quantities; for a wall R_j = m_j = r_j = ∞. The four quotients of a
        // particle pair share one division (it costs as much as a dozen multiplications):
        // with A = (R_i + R_j)(m_i + m_j) and B = r_i (r_i + r_j), 1/A = B/(AB), 1/B = A/(AB).
        let (r_star, m_star, e_star, g_star, r_roll, r_j_per_r_i) = match other {
            Other::Particle {
                r: radius_j,
                m: m_j,
            } => {
                let (sum_r, sum_m, sum_contact) = (radius_i + radius_j, m_i + m_j, r_i + r_j);
                let a = sum_r * sum_m;
                let b = r_i * sum_contact;
                let inv_ab = c(1.0) / (a * b);
                let (inv_a, inv_b) = (b * inv_ab, a * inv_ab);
                (
                    radius_i * radius_j * sum_m * inv_a, // Eq. (17)
                    m_i * m_j * sum_r * inv_a,           // Eq. (20)
                    coef.e_star,
                    coef.g_star,
                    r_i * r_i * r_j * inv_b, // (1/r_i + 1/r_j)^-1 of Eq. (36)
                    r_j * sum_contact * inv_b,
                )
            }
            Other::Wall => (radius_i, m_i, coef.e_star, coef.g_star, r_i, c(0.0)),
        };

        let a = (r_star * delta).sqrt(); // Eq. (14)
        let k_n = c(4.0 / 3.0) * e_star * a; // Eq. (12)
        let k_s = c(8.0) * g_star * a; // Eq. (13)
        let c_n = (c(5.0) * m_star * k_n).sqrt() * coef.beta; // Eq. (18)
        let c_s = c_n * coef.c_s_per_c_n; // Eq. (19), as Eq. (25)

        // Normal force, along n̂: f_n = -k_n u_n - c_n v_n with u_n = -δ n̂ (Eqs. 5, 10).
        let v_dot_n = T::dot(v, n);
        let v_n = n * v_dot_n; // Eq. (27)
        let v_s = v - v_n; // Eq. (28)
        let f_n_scalar = k_n * delta - c_n * v_dot_n;
        let f_n = n * f_n_scalar; // Eq. (5)
        let f_n_norm = f_n_scalar.abs();
        let dt = c(self.dt);
        let first = self.advance_first;

        // Sliding friction.
        springs.u_s = project_onto_tangent_plane::<T>(springs.u_s, n); // Eq. (52)
        let f_s = coulomb_spring(
            &mut springs.u_s,
            v_s,
            k_s,
            c_s,
            coef.mu_s * f_n_norm,
            dt,
            first,
        ); // Eqs. (6), (11), (53)-(55)
        let tau_s = T::cross(f_s, n) * r_i; // Eq. (31)

        // Rolling friction, k_r = k_n and c_r = c_n.
        let v_r = T::cross(omega, n) * r_roll; // Eq. (36)
        springs.u_r = project_onto_tangent_plane::<T>(springs.u_r, n); // Eq. (52)
        let f_r = coulomb_spring(
            &mut springs.u_r,
            v_r,
            k_n,
            c_n,
            coef.mu_r * f_n_norm,
            dt,
            first,
        ); // Eqs. (34), (39), (53)-(55)
        let tau_r = T::cross(n, f_r) * r_star; // Eq. (32)

        // Twisting friction, k_t = k_s and c_t = c_s.
        let v_t = r_star * T::dot(omega, n); // Eq. (37)
        let f_t = coulomb_spring(
            &mut springs.u_t,
            v_t,
            k_s,
            c_s,
            coef.mu_t * f_n_norm,
            dt,
            first,
        ); // Eqs. (35), (40), (53)-(55)
        let tau_t = n * (f_t * r_star); // Eq. (33)

        // Cohesion, the simplified JKR model: a pull k_c A along -n̂ over the area A = π a²
        // of the contact circle (of the two spheres' lens, or of the sphere cut by the
        // wall's plane). It adds to the force only: the Coulomb limits above rest on the
        // repulsive load |f_n|, which at rest carries the outer load and the pull together.
        let f = if self.cohesive {
            let a2 = match other {
                Other::Particle { r: radius_j, .. } => {
                    let d = radius_i + radius_j - delta;
                    let x = (d * d + radius_i * radius_i - radius_j * radius_j) / (c(2.0) * d);
                    radius_i * radius_i - x * x
                }
                Other::Wall => delta * (c(2.0) * radius_i - delta),
            };
            f_n + f_s - n * (coef.cohesion * c(std::f64::consts::PI) * a2)
        } else {
            f_n + f_s
        };

        ContactForce {
            f,
            tau_i: tau_s + tau_r + tau_t,
            // A wall takes no reaction torque; avoid ∞ · 0 there.
            tau_j: match other {
                Other::Particle { .. } => tau_s * r_j_per_r_i - tau_r - tau_t, // Eqs. (58)-(60)
                Other::Wall => T::Vec::default(),
            },
        }
    }
}

/// Eq. (52): rotate a spring back into the tangent plane of the current normal, keeping its
/// length (unless it is zero or parallel to the normal).
#[inline(always)]
fn project_onto_tangent_plane<T: Lanes>(u: T::Vec, n: T::Vec) -> T::Vec {
    let length2 = T::dot(u, u);
    let tangential = u - n * T::dot(u, n);
    let t2 = T::dot(tangential, tangential);
    let stretch = T::pick(t2.is_zero(), || T::splat(0.0), || (length2 / t2).sqrt());
    tangential * stretch
}

/// One friction mode m ∈ {s, r, t}: the Kelvin-Voigt force -k u - c v, clipped by Coulomb's
/// law to `f_max` = μ_m |f_n|. Static: the spring grows by Δt v (Eq. 53). Kinetic: the force
/// is scaled to the Coulomb limit (Eq. 54) and the spring set to match it (Eq. 55), so the
/// force is continuous at the switch between the two.
///
/// `advance_first` says when the spring grows. The paper takes the force of the previous
/// step's spring, then advances it; the default advances it first. The difference is that
/// between creating energy and not. Take one sticking contact: a mass m on the spring k
/// with damper c, ω² = k/m, γ = c/m, moved by the semi-implicit Euler of Eqs. (45)-(46)
/// (the velocity first, the position with the new velocity), so that the spring is the
/// integral of the velocity the contact sees. Per step, the state (u, v) maps to
///
/// ```text
///   paper:          u' = u + Δt v            | 1      Δt       |   det = 1 - γΔt + ω²Δt²
///                   v' = v - Δt (ω² u + γ v) | -ω²Δt  1 - γΔt  |
///
///   advance first:  u' = u + Δt v            | 1      Δt              |   det = 1 - γΔt
///                   v' = v - Δt (ω² u' + γ v)| -ω²Δt  1 - ω²Δt² - γΔt |
/// ```
///
/// The determinant is the factor by which a step scales the area of phase space, and so
/// (for the undamped oscillator) its energy on average. The paper's order is forward
/// Euler: undamped (an elastic contact has c = 0, Eq. 18 with β = 0) it gains a factor
/// 1 + (ωΔt)² per step, and damped it still gains whenever ω²Δt > γ; with ωΔt ≈ 0.3
/// at Eq. (50)'s time step an elastic oblique impact leaves with ~20 % more energy and a
/// settled bed keeps spinning. Advancing first is symplectic Euler: undamped it keeps
/// the area exactly (|trace| < 2 for ωΔt < 2, so the energy stays bounded and returns),
/// and any damping only removes energy.
#[inline(always)]
fn coulomb_spring<T: Lanes, V: Displacement<T>>(
    u: &mut V,
    v: V,
    k: T,
    c: T,
    f_max: T,
    dt: T,
    advance_first: bool,
) -> V {
    let spring = if advance_first { *u + v * dt } else { *u }; // Eq. (53), first
    let f = -(spring * k) + -(v * c);
    let f_norm2 = f.norm_squared();
    let sticking = f_norm2.le(f_max * f_max);
    let f = V::pick(sticking, || f, || f * (f_max / f_norm2.sqrt())); // Eq. (54)
    *u = V::pick(
        sticking,
        || if advance_first { spring } else { *u + v * dt }, // Eq. (53)
        || -(f + v * c) * (T::splat(1.0) / k),               // Eq. (55)
    );
    f
}

#[cfg(test)]
mod tests;
