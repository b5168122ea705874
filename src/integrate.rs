//! Time integration (paper Section 2.3): semi-implicit Euler for translation and rotation,
//! Eqs. (42)-(46), and the SPIRAL quaternion update, Eqs. (47)-(49).

use glam::{DQuat, DVec3};

/// Per-particle constants of Eqs. (1)-(4), from the radius and the shared material.
#[derive(Clone, Copy, Debug)]
pub struct Inertia {
    /// m = 4/3 π ρ R³
    pub m: f64,
    /// I = 2/5 m R²
    pub i: f64,
    /// c = 9 η / (2 ρ R²), Eq. (3)
    pub c: f64,
    /// γ = 10/3 c, Eq. (4)
    pub gamma: f64,
}

impl Inertia {
    #[inline]
    pub fn new(radius: f64, density: f64, viscosity: f64) -> Inertia {
        let m = Inertia::mass(radius, density);
        let c = 9.0 * viscosity / (2.0 * density * radius * radius); // Eq. (3)
        Inertia {
            m,
            i: 0.4 * m * radius * radius,
            c,
            gamma: 10.0 / 3.0 * c, // Eq. (4)
        }
    }

    /// Mass alone (for contact partners).
    #[inline]
    pub fn mass(radius: f64, density: f64) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * density * radius.powi(3)
    }
}

/// sin φ and cos φ; for |φ| <= 0.1 (every time step of a resolved run) by their Taylor
/// series, whose truncation error there is below 1e-17 relative, at a fraction of the cost
/// of the library call. The coefficients are multiplied, not divided by (a division costs
/// several multiplications).
#[inline]
pub fn sin_cos(phi: f64) -> (f64, f64) {
    if phi.abs() > 0.1 {
        return phi.sin_cos();
    }
    const S: [f64; 4] = [1.0 / 6.0, 1.0 / 20.0, 1.0 / 42.0, 1.0 / 72.0];
    const C: [f64; 5] = [1.0 / 2.0, 1.0 / 12.0, 1.0 / 30.0, 1.0 / 56.0, 1.0 / 90.0];
    let p2 = phi * phi;
    let s = phi * (1.0 - p2 * S[0] * (1.0 - p2 * S[1] * (1.0 - p2 * S[2] * (1.0 - p2 * S[3]))));
    let c = 1.0
        - p2 * C[0] * (1.0 - p2 * C[1] * (1.0 - p2 * C[2] * (1.0 - p2 * C[3] * (1.0 - p2 * C[4]))));
    (s, c)
}

/// The rotation quaternion (cos φ, sin φ â) by angle 2φ about the direction of `a`.
#[inline]
fn rotation(a: DVec3, norm: f64, phi: f64) -> DQuat {
    let (s, c) = sin_cos(phi);
    let axis = a * (s / norm);
    DQuat::from_xyzw(axis.x, axis.y, axis.z, c)
}

/// Eqs. (47)-(49) for world-frame ω and α. The quaternion maps body to world coordinates,
/// so the body-frame product q̂ (cos φ, sin φ ω̂_b)(cos θ, sin θ α̂_b) of Eq. (47) equals
/// (cos φ, sin φ ω̂)(cos θ, sin θ α̂) q̂ with world-frame axes: increments multiply from the
/// left. Each factor is applied only if its vector is non-zero. Renormalised against drift.
#[inline]
pub fn spiral(q: DQuat, w: DVec3, alpha: DVec3, dt: f64) -> DQuat {
    let mut q = q;
    let alpha_norm = alpha.length();
    if alpha_norm > 0.0 {
        let theta = (dt / 2.0).powi(2) * alpha_norm; // Eq. (48)
        q = rotation(alpha, alpha_norm, theta) * q; // Eq. (49)
    }
    let w_norm = w.length();
    if w_norm > 0.0 {
        let phi = dt / 2.0 * w_norm; // Eq. (48)
        q = rotation(w, w_norm, phi) * q; // Eq. (49)
    }
    q.normalize()
}

/// One particle's state during the update.
pub struct State<'a> {
    pub x: &'a mut DVec3,
    pub v: &'a mut DVec3,
    pub q: &'a mut DQuat,
    pub w: &'a mut DVec3,
}

/// Advances one particle by Δt under total contact force `f` and torque `tau`.
#[inline]
pub fn advance(s: State, body: &Inertia, f: DVec3, tau: DVec3, g: DVec3, dt: f64) {
    let a = f * body.m.recip() + g - body.c * *s.v; // Eq. (42)
    let alpha = tau * body.i.recip() - body.gamma * *s.w; // Eq. (43)
    *s.v += dt * a; // Eq. (44)
    *s.x += dt * *s.v; // Eq. (45), with the new velocity (symplectic)
    *s.q = spiral(*s.q, *s.w, alpha, dt); // Eq. (47), before ω is updated
    *s.w += dt * alpha; // Eq. (46)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_angle_sin_cos_matches_the_library() {
        for k in 0..=2000 {
            let phi = (k as f64 - 1000.0) * 1e-4 * 1.0001;
            let (s, c) = sin_cos(phi);
            assert!(
                (s - phi.sin()).abs() <= 2.0 * f64::EPSILON * phi.abs(),
                "{phi}"
            );
            assert!((c - phi.cos()).abs() <= 2.0 * f64::EPSILON, "{phi}");
        }
        assert_eq!(sin_cos(0.5), 0.5f64.sin_cos());
    }

    #[test]
    fn spiral_about_a_fixed_axis_is_exact() {
        let w = DVec3::new(0.0, 0.0, 3.0);
        let mut q = DQuat::IDENTITY;
        for _ in 0..1000 {
            q = spiral(q, w, DVec3::ZERO, 1e-3);
        }
        let expected = DQuat::from_rotation_z(3.0);
        assert!(q.dot(expected).abs() > 1.0 - 1e-14);
    }

    #[test]
    fn world_frame_increments_multiply_from_the_left() {
        // Start rotated 90° about x, spin about world z: q = R_z(ω t) R_x(90°).
        let q0 = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let mut q = q0;
        for _ in 0..500 {
            q = spiral(q, DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, 1e-3);
        }
        let expected = DQuat::from_rotation_z(1.0) * q0;
        assert!(q.dot(expected).abs() > 1.0 - 1e-14, "{q:?} vs {expected:?}");
    }
}
