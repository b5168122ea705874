//! What the law reads of a contact, computed once for all sub-models: the two bodies'
//! geometry and motion, the overlap, the normal and the relative velocities (Eqs. 7-9,
//! 26-30, 38).

use glam::DVec3;

use crate::model::lanes::Lanes;
use crate::model::motion::RigidVelocity;

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
    /// Overlap δ, Eq. (7): positive while touching, negative across the gap of a contact
    /// beyond touch (JKR's neck, a liquid bridge).
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
        Self::between_particles_within(i, j, 0.0)
    }

    /// The contact of particles `i` and `j`, or `None` if their gap is `gap` or more (a
    /// contact beyond touch, δ > -gap).
    #[inline]
    pub fn between_particles_within(i: &Body, j: &Body, gap: f64) -> Option<Kinematics> {
        let d = i.x - j.x; // Eq. (8)
        let within = i.radius + j.radius + gap;
        let dist2 = d.length_squared();
        if dist2 >= within * within {
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
        Self::with_wall_within(i, d, face_radius, wall, 0.0)
    }

    /// [`Kinematics::with_wall`] for a contact that lasts while the gap is less than `gap`.
    #[inline]
    pub fn with_wall_within(
        i: &Body,
        d: DVec3,
        face_radius: f64,
        wall: &RigidVelocity,
        gap: f64,
    ) -> Option<Kinematics> {
        let reach = i.radius + face_radius;
        let dist2 = d.length_squared();
        let within = reach + gap;
        if dist2 >= within * within {
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
