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
    /// 1/m and 1/I
    pub inv_m: f64,
    pub inv_i: f64,
    /// c = 9 η / (2 ρ R²), Eq. (3)
    pub c: f64,
    /// γ = 10/3 c, Eq. (4)
    pub gamma: f64,
}

impl Inertia {
    /// One division per particle: the material's quotients are the same for all (and are
    /// hoisted out of a loop over particles).
    #[inline]
    pub fn new(radius: f64, density: f64, viscosity: f64) -> Inertia {
        let inv_r = radius.recip();
        let inv_r2 = inv_r * inv_r;
        let inv_m = inv_r2 * inv_r * (0.75 / std::f64::consts::PI / density);
        let c = 4.5 * (viscosity / density) * inv_r2; // Eq. (3)
        let m = Inertia::mass(radius, density);
        Inertia {
            m,
            i: 0.4 * m * radius * radius,
            inv_m,
            inv_i: 2.5 * inv_m * inv_r2,
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

/// The rotation quaternion (cos φ, sin φ â) by angle 2φ about the direction of `a`, where
/// φ = `scale` |a|. Small angles (every time step of a resolved run) need neither square
/// root nor division: sin φ â = scale (sin φ / φ) a, with both series in φ².
#[inline]
fn rotation(a: DVec3, scale: f64) -> DQuat {
    let phi2 = scale * scale * a.length_squared();
    const S: [f64; 4] = [1.0 / 6.0, 1.0 / 20.0, 1.0 / 42.0, 1.0 / 72.0];
    const C: [f64; 5] = [1.0 / 2.0, 1.0 / 12.0, 1.0 / 30.0, 1.0 / 56.0, 1.0 / 90.0];
    let p2 = phi2;
    let (sin_per_phi, cos) = if p2 <= 1e-5 {
        // Fewer terms: the first omitted ones, φ⁶/5040 and φ⁸/40320, are below 1e-18.
        (
            1.0 - p2 * S[0] * (1.0 - p2 * S[1]),
            1.0 - p2 * C[0] * (1.0 - p2 * C[1] * (1.0 - p2 * C[2])),
        )
    } else if p2 <= 0.01 {
        (
            1.0 - p2 * S[0] * (1.0 - p2 * S[1] * (1.0 - p2 * S[2] * (1.0 - p2 * S[3]))),
            1.0 - p2
                * C[0]
                * (1.0 - p2 * C[1] * (1.0 - p2 * C[2] * (1.0 - p2 * C[3] * (1.0 - p2 * C[4])))),
        )
    } else {
        let phi = phi2.sqrt();
        let (s, c) = phi.sin_cos();
        (s / phi, c)
    };
    let v = a * (scale * sin_per_phi);
    DQuat::from_xyzw(v.x, v.y, v.z, cos)
}

/// Eqs. (47)-(49) for world-frame ω and α. The quaternion maps body to world coordinates,
/// so the body-frame product q̂ (cos φ, sin φ ω̂_b)(cos θ, sin θ α̂_b) of Eq. (47) equals
/// (cos φ, sin φ ω̂)(cos θ, sin θ α̂) q̂ with world-frame axes: increments multiply from the
/// left. A zero vector gives the identity factor. Renormalised against drift by one Newton
/// step for 1/|q| (|q| differs from 1 by rounding only).
#[inline]
pub fn spiral(q: DQuat, w: DVec3, alpha: DVec3, dt: f64) -> DQuat {
    let half = 0.5 * dt;
    let q = rotation(alpha, half * half) * q; // Eqs. (48), (49): θ = (Δt/2)² |α|
    let q = rotation(w, half) * q; // Eqs. (48), (49): φ = Δt/2 |ω|
    q * (1.5 - 0.5 * q.length_squared())
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
    let a = f * body.inv_m + g - body.c * *s.v; // Eq. (42)
    let alpha = tau * body.inv_i - body.gamma * *s.w; // Eq. (43)
    *s.v += dt * a; // Eq. (44)
    *s.x += dt * *s.v; // Eq. (45), with the new velocity (symplectic)
    *s.q = spiral(*s.q, *s.w, alpha, dt); // Eq. (47), before ω is updated
    *s.w += dt * alpha; // Eq. (46)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_matches_the_library_on_both_sides_of_the_series() {
        let axis = DVec3::new(1.0, -2.0, 0.5).normalize();
        for k in 0..=3000 {
            let half_angle = k as f64 * 1e-4 * 1.0001; // up to 0.3 rad, past the series
            let q = rotation(axis * half_angle * 1e3, 1e-3);
            let expected = DQuat::from_axis_angle(axis, 2.0 * half_angle);
            assert!(
                (q.w - expected.w).abs() <= 2.0 * f64::EPSILON,
                "cos at {half_angle}"
            );
            let v = DVec3::new(q.x, q.y, q.z) - DVec3::new(expected.x, expected.y, expected.z);
            assert!(
                v.length() <= 4.0 * f64::EPSILON * half_angle.max(1e-300),
                "sin at {half_angle}"
            );
        }
        assert_eq!(rotation(DVec3::ZERO, 1e-3), DQuat::IDENTITY);
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
