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

use crate::motion::RigidVelocity;
use crate::scenario::Material;

/// Displacements of the three static friction springs of one contact (Table 3):
/// sliding `u_s`, rolling `u_r` and twisting `u_t`. Zero at first touch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Springs {
    pub u_s: DVec3,
    pub u_r: DVec3,
    pub u_t: f64,
}

/// Constants of the contact law derived once from the (single) material.
#[derive(Clone, Copy, Debug)]
pub struct ContactLaw {
    /// E* and G* between two particles, Eqs. (22), (23).
    e_star_pp: f64,
    g_star_pp: f64,
    /// E* and G* between a particle and a rigid wall (text after Eq. 25).
    e_star_pw: f64,
    g_star_pw: f64,
    /// Damping factor β, Eq. (21).
    beta: f64,
    /// c_s / c_n = sqrt(k_s / (30 k_n)) = sqrt((1 - ν) / (10 (2 - ν))), Eqs. (18), (19), (25);
    /// the same for particle-particle and particle-wall contacts since G*/E* is.
    c_s_per_c_n: f64,
    mu_s: f64,
    mu_r: f64,
    mu_t: f64,
    dt: f64,
}

/// What body `j` of a contact is, as far as the law is concerned.
#[derive(Clone, Copy, Debug)]
pub enum Other {
    /// Another particle, with radius R_j and mass m_j.
    Particle { r: f64, m: f64 },
    /// A mesh element: infinitely flat, stiff and heavy (R_j = E_j = m_j = ∞).
    Wall,
}

/// Position, radius and velocities of a particle entering a contact.
#[derive(Clone, Copy, Debug)]
pub struct Body {
    pub x: DVec3,
    pub radius: f64,
    pub v: DVec3,
    pub w: DVec3,
}

/// Geometry and relative motion of one contact, computed once and shared by all modes.
#[derive(Clone, Copy, Debug)]
pub struct Kinematics {
    /// Unit normal n̂ pointing from j to i, Eq. (9).
    pub n: DVec3,
    /// Overlap δ > 0, Eq. (7).
    pub delta: f64,
    /// Distances of the contact point from the centres, Eqs. (29), (30); r_j = ∞ for a wall.
    pub r_i: f64,
    pub r_j: f64,
    /// Total relative velocity of the material points at the contact, Eq. (26).
    pub v: DVec3,
    /// Relative angular velocity ω = ω_i - ω_j, Eq. (38).
    pub omega: DVec3,
}

/// Unit vector of `d` with length `dist`; two coincident centres get an arbitrary but fixed
/// normal instead of NaN.
#[inline]
fn unit(d: DVec3, dist: f64) -> DVec3 {
    if dist > 0.0 {
        d * dist.recip()
    } else {
        DVec3::Z
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
        let dist = dist2.sqrt();
        let delta = reach - dist; // Eq. (7)
        let n = unit(d, dist); // Eq. (9)
        let r_i = i.radius - delta / 2.0; // Eq. (29)
        let r_j = j.radius - delta / 2.0; // Eq. (30)
        Some(Kinematics {
            n,
            delta,
            r_i,
            r_j,
            v: i.v - j.v + n.cross(r_i * i.w + r_j * j.w), // Eq. (26), sign as in the README
            omega: i.w - j.w,                              // Eq. (38)
        })
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
        let n = unit(d, dist); // Eq. (9)
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
pub struct ContactForce {
    /// f_n + f_s on body i; body j receives the opposite, Eqs. (56), (57).
    pub f: DVec3,
    /// τ_s + τ_r + τ_t on body i.
    pub tau_i: DVec3,
    /// Torque on body j: (r_j / r_i) τ_s - τ_r - τ_t, Eqs. (58)-(60).
    pub tau_j: DVec3,
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
    pub fn new(material: &Material, dt: f64) -> Self {
        let e = material.youngs_modulus;
        let nu = material.poisson_ratio;
        let g = e / (2.0 * (1.0 + nu)); // Eq. (16), G_i
        ContactLaw {
            e_star_pp: e / (2.0 * (1.0 - nu * nu)),         // Eq. (22)
            g_star_pp: e / (4.0 * (2.0 - nu) * (1.0 + nu)), // Eq. (23)
            e_star_pw: e / (1.0 - nu * nu),
            g_star_pw: g / (2.0 - nu),
            beta: damping_factor(material.restitution), // Eq. (21)
            c_s_per_c_n: ((1.0 - nu) / (10.0 * (2.0 - nu))).sqrt(), // Eq. (25)
            mu_s: material.friction_sliding,
            mu_r: material.friction_rolling,
            mu_t: material.friction_twisting,
            dt,
        }
    }

    /// Normal stiffness k_n at overlap `delta` between two particles of radii `r_i`, `r_j`
    /// (Eqs. 12, 14, 17); used for reporting derived quantities.
    pub fn normal_stiffness(&self, r_i: f64, r_j: f64, delta: f64) -> f64 {
        let r_star = 1.0 / (1.0 / r_i + 1.0 / r_j);
        4.0 / 3.0 * self.e_star_pp * (r_star * delta).sqrt()
    }

    /// Evaluates the contact of particle `i` (radius `radius_i`, mass `m_i`) with body
    /// `other`, updating the friction springs for the next time step.
    #[inline(always)]
    pub fn evaluate(
        &self,
        radius_i: f64,
        m_i: f64,
        other: Other,
        kin: &Kinematics,
        springs: &mut Springs,
    ) -> ContactForce {
        let Kinematics {
            n,
            delta,
            r_i,
            r_j,
            v,
            omega,
        } = *kin;
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
                let inv_ab = (a * b).recip();
                let (inv_a, inv_b) = (b * inv_ab, a * inv_ab);
                (
                    radius_i * radius_j * sum_m * inv_a, // Eq. (17)
                    m_i * m_j * sum_r * inv_a,           // Eq. (20)
                    self.e_star_pp,
                    self.g_star_pp,
                    r_i * r_i * r_j * inv_b, // (1/r_i + 1/r_j)^-1 of Eq. (36)
                    r_j * sum_contact * inv_b,
                )
            }
            Other::Wall => (radius_i, m_i, self.e_star_pw, self.g_star_pw, r_i, 0.0),
        };

        let a = (r_star * delta).sqrt(); // Eq. (14)
        let k_n = 4.0 / 3.0 * e_star * a; // Eq. (12)
        let k_s = 8.0 * g_star * a; // Eq. (13)
        let c_n = (5.0 * m_star * k_n).sqrt() * self.beta; // Eq. (18)
        let c_s = c_n * self.c_s_per_c_n; // Eq. (19), as Eq. (25)

        // Normal force, along n̂: f_n = -k_n u_n - c_n v_n with u_n = -δ n̂ (Eqs. 5, 10).
        let v_dot_n = v.dot(n);
        let v_n = v_dot_n * n; // Eq. (27)
        let v_s = v - v_n; // Eq. (28)
        let f_n_scalar = k_n * delta - c_n * v_dot_n;
        let f_n = f_n_scalar * n; // Eq. (5)
        let f_n_norm = f_n_scalar.abs();

        // Sliding friction.
        springs.u_s = project_onto_tangent_plane(springs.u_s, n); // Eq. (52)
        let f_s = coulomb_spring(
            &mut springs.u_s,
            v_s,
            k_s,
            c_s,
            self.mu_s * f_n_norm,
            self.dt,
        ); // Eqs. (6), (11), (53)-(55)
        let tau_s = r_i * f_s.cross(n); // Eq. (31)

        // Rolling friction, k_r = k_n and c_r = c_n.
        let v_r = r_roll * omega.cross(n); // Eq. (36)
        springs.u_r = project_onto_tangent_plane(springs.u_r, n); // Eq. (52)
        let f_r = coulomb_spring(
            &mut springs.u_r,
            v_r,
            k_n,
            c_n,
            self.mu_r * f_n_norm,
            self.dt,
        ); // Eqs. (34), (39), (53)-(55)
        let tau_r = r_star * n.cross(f_r); // Eq. (32)

        // Twisting friction, k_t = k_s and c_t = c_s.
        let v_t = r_star * omega.dot(n); // Eq. (37)
        let f_t = coulomb_spring(
            &mut springs.u_t,
            v_t,
            k_s,
            c_s,
            self.mu_t * f_n_norm,
            self.dt,
        ); // Eqs. (35), (40), (53)-(55)
        let tau_t = f_t * r_star * n; // Eq. (33)

        ContactForce {
            f: f_n + f_s,
            tau_i: tau_s + tau_r + tau_t,
            // A wall takes no reaction torque; avoid ∞ · 0 there.
            tau_j: match other {
                Other::Particle { .. } => r_j_per_r_i * tau_s - tau_r - tau_t, // Eqs. (58)-(60)
                Other::Wall => DVec3::ZERO,
            },
        }
    }
}

/// Eq. (52): rotate a spring back into the tangent plane of the current normal, keeping its
/// length (unless it is zero or parallel to the normal).
#[inline(always)]
fn project_onto_tangent_plane(u: DVec3, n: DVec3) -> DVec3 {
    let length2 = u.length_squared();
    if length2 == 0.0 {
        return u;
    }
    let tangential = u - u.dot(n) * n;
    let t2 = tangential.length_squared();
    if t2 == 0.0 {
        DVec3::ZERO
    } else {
        tangential * (length2 / t2).sqrt()
    }
}

/// A spring displacement: a vector (sliding, rolling) or a scalar (twisting).
trait Displacement:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Neg<Output = Self>
    + std::ops::Mul<f64, Output = Self>
{
    fn norm_squared(self) -> f64;
}

impl Displacement for DVec3 {
    fn norm_squared(self) -> f64 {
        self.length_squared()
    }
}

impl Displacement for f64 {
    fn norm_squared(self) -> f64 {
        self * self
    }
}

/// One friction mode m ∈ {s, r, t}: the Kelvin-Voigt force -k u - c v, clipped by Coulomb's
/// law to `f_max` = μ_m |f_n|. Static: the spring grows by Δt v (Eq. 53). Kinetic: the force
/// is scaled to the Coulomb limit (Eq. 54) and the spring set to match it (Eq. 55).
#[inline(always)]
fn coulomb_spring<V: Displacement>(u: &mut V, v: V, k: f64, c: f64, f_max: f64, dt: f64) -> V {
    let f = -(*u * k) + -(v * c);
    let f_norm2 = f.norm_squared();
    if f_norm2 <= f_max * f_max {
        *u = *u + v * dt; // Eq. (53)
        f
    } else {
        let f = f * (f_max / f_norm2.sqrt()); // Eq. (54)
        *u = -(f + v * c) * (1.0 / k); // Eq. (55)
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beta_limits() {
        assert_eq!(damping_factor(1.0), 0.0);
        assert_eq!(damping_factor(0.0), 1.0);
        let b = damping_factor(0.5);
        assert!((b - 0.215_453_8).abs() < 1e-6, "{b}");
    }

    #[test]
    fn projection_keeps_length_and_removes_normal_part() {
        let n = DVec3::Z;
        let u = project_onto_tangent_plane(DVec3::new(3.0, 0.0, 4.0), n);
        assert!((u - DVec3::new(5.0, 0.0, 0.0)).length() < 1e-15);
        assert_eq!(project_onto_tangent_plane(DVec3::Z, n), DVec3::ZERO);
        assert_eq!(project_onto_tangent_plane(DVec3::ZERO, n), DVec3::ZERO);
    }

    #[test]
    fn static_spring_accumulates_and_kinetic_spring_matches_coulomb() {
        let mut u = 0.0;
        let f = coulomb_spring(&mut u, 2.0, 10.0, 1.0, 100.0, 0.5);
        assert_eq!((f, u), (-2.0, 1.0));
        // Kinetic: |f| is clipped to the limit and the spring reproduces it.
        let mut u = 1.0;
        let f = coulomb_spring(&mut u, 2.0, 10.0, 1.0, 3.0, 0.5);
        assert_eq!(f, -3.0);
        assert!((-10.0 * u - 2.0 - f).abs() < 1e-15);
    }
}
