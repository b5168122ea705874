//! Time integration (paper Section 2.3): semi-implicit Euler for translation and rotation,
//! Eqs. (42)-(46), and the SPIRAL quaternion update, Eqs. (47)-(49).
//!
//! Written over [`Lanes`]: one particle at a time, or a group in SIMD lanes (the simulation
//! advances eight at once), with the same bits either way.

use crate::model::lanes::Lanes;

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
    #[inline]
    pub fn new(radius: f64, density: f64, viscosity: f64) -> Inertia {
        let Response {
            inv_m,
            inv_i,
            c,
            gamma,
        } = Response::new(radius, density, viscosity);
        let m = Inertia::mass(radius, density);
        Inertia {
            m,
            i: 0.4 * m * radius * radius,
            inv_m,
            inv_i,
            c,
            gamma,
        }
    }

    /// Mass alone (for contact partners), of one particle or of lanes: (4/3 π ρ) R³, with
    /// R³ = (R R) R, the bits of `radius.powi(3)`.
    #[inline(always)]
    pub fn mass<T: Lanes>(radius: T, density: f64) -> T {
        Inertia::mass_with(radius, T::splat(Density::new(density, 0.0).mass_per_r3))
    }

    /// Mass from 4/3 π ρ (`Density::mass_per_r3`, in lanes: each particle's material's).
    #[inline(always)]
    pub fn mass_with<T: Lanes>(radius: T, mass_per_r3: T) -> T {
        mass_per_r3 * (radius * radius * radius)
    }
}

/// The quotients of a material's density (and the fluid's viscosity) that Eqs. (1)-(4)
/// need, computed once per material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Density {
    /// 4/3 π ρ: m = (4/3 π ρ) R³
    pub mass_per_r3: f64,
    /// 3 / (4 π ρ): 1/m = R⁻³ 3 / (4 π ρ)
    pub inv_mass_r3: f64,
    /// 4.5 η / ρ: c = (4.5 η / ρ) / R², Eq. (3)
    pub drag: f64,
}

impl Density {
    pub fn new(density: f64, viscosity: f64) -> Density {
        Density {
            mass_per_r3: 4.0 / 3.0 * std::f64::consts::PI * density,
            inv_mass_r3: 0.75 / std::f64::consts::PI / density,
            drag: 4.5 * (viscosity / density),
        }
    }
}

/// What the integration needs of [`Inertia`]: how a particle (or each of a group, in
/// lanes) responds to force, torque and drag.
#[derive(Clone, Copy, Debug)]
pub struct Response<T: Lanes = f64> {
    /// 1/m and 1/I
    pub inv_m: T,
    pub inv_i: T,
    /// c, Eq. (3), and γ, Eq. (4)
    pub c: T,
    pub gamma: T,
}

impl<T: Lanes> Response<T> {
    /// One division per particle: the material's quotients are the same for all (and are
    /// hoisted out of a loop over particles).
    #[inline(always)]
    pub fn new(radius: T, density: f64, viscosity: f64) -> Self {
        let d = Density::new(density, viscosity);
        Response::with(radius, T::splat(d.inv_mass_r3), T::splat(d.drag))
    }

    /// The response from a material's quotients (`Density`; in lanes, each particle's).
    #[inline(always)]
    pub fn with(radius: T, inv_mass_r3: T, drag: T) -> Self {
        let k = T::splat;
        let inv_r = k(1.0) / radius;
        let inv_r2 = inv_r * inv_r;
        let inv_m = inv_r2 * inv_r * inv_mass_r3;
        let c = drag * inv_r2; // Eq. (3)
        Response {
            inv_m,
            inv_i: k(2.5) * inv_m * inv_r2,
            c,
            gamma: k(10.0 / 3.0) * c, // Eq. (4)
        }
    }
}

/// The rotation quaternion (cos φ, sin φ â) by angle 2φ about the direction of `a`, where
/// φ = `scale` |a|. Small angles (every time step of a resolved run) need neither square
/// root nor division: sin φ â = scale (sin φ / φ) a, with both series in φ².
#[inline(always)]
fn rotation<T: Lanes>(a: T::Vec, scale: T) -> T::Quat {
    let k = T::splat;
    let p2 = scale * scale * T::dot(a, a);
    const S: [f64; 4] = [1.0 / 6.0, 1.0 / 20.0, 1.0 / 42.0, 1.0 / 72.0];
    const C: [f64; 5] = [1.0 / 2.0, 1.0 / 12.0, 1.0 / 30.0, 1.0 / 56.0, 1.0 / 90.0];
    let (s, c) = (|i: usize| k(S[i]), |i: usize| k(C[i]));
    // Fewer terms below 1e-5: the first omitted ones, φ⁶/5040 and φ⁸/40320, are below 1e-18.
    let (short, medium) = (p2.le(k(1e-5)), p2.le(k(0.01)));
    let one = k(1.0);
    let sin_per_phi = T::pick(
        short,
        || one - p2 * s(0) * (one - p2 * s(1)),
        || {
            T::pick(
                medium,
                || one - p2 * s(0) * (one - p2 * s(1) * (one - p2 * s(2) * (one - p2 * s(3)))),
                || p2.each(|p2| p2.sqrt().sin() / p2.sqrt()),
            )
        },
    );
    let cos = T::pick(
        short,
        || one - p2 * c(0) * (one - p2 * c(1) * (one - p2 * c(2))),
        || {
            T::pick(
                medium,
                || {
                    one - p2
                        * c(0)
                        * (one
                            - p2 * c(1) * (one - p2 * c(2) * (one - p2 * c(3) * (one - p2 * c(4)))))
                },
                || p2.each(|p2| p2.sqrt().cos()),
            )
        },
    );
    T::quat(a * (scale * sin_per_phi), cos)
}

/// Eqs. (47)-(49) for world-frame ω and α. The quaternion maps body to world coordinates,
/// so the body-frame product q̂ (cos φ, sin φ ω̂_b)(cos θ, sin θ α̂_b) of Eq. (47) equals
/// (cos φ, sin φ ω̂)(cos θ, sin θ α̂) q̂ with world-frame axes: increments multiply from the
/// left. A zero vector gives the identity factor. Renormalised against drift by one Newton
/// step for 1/|q| (|q| differs from 1 by rounding only).
#[inline(always)]
pub fn spiral<T: Lanes>(q: T::Quat, w: T::Vec, alpha: T::Vec, dt: T) -> T::Quat {
    let half = T::splat(0.5) * dt;
    let q = T::mul_quat(rotation::<T>(alpha, half * half), q); // Eqs. (48), (49): θ = (Δt/2)² |α|
    let q = T::mul_quat(rotation::<T>(w, half), q); // Eqs. (48), (49): φ = Δt/2 |ω|
    T::scale_quat(q, T::splat(1.5) - T::splat(0.5) * T::norm2_quat(q))
}

/// The state of a particle (or of each of a group, in lanes) during the update.
#[derive(Clone, Copy, Debug)]
pub struct State<T: Lanes = f64> {
    pub x: T::Vec,
    pub v: T::Vec,
    pub q: T::Quat,
    pub w: T::Vec,
}

/// Advances a particle by Δt under total contact force `f` and torque `tau`.
#[inline(always)]
pub fn advance<T: Lanes>(
    s: State<T>,
    body: &Response<T>,
    f: T::Vec,
    tau: T::Vec,
    g: T::Vec,
    dt: T,
) -> State<T> {
    let a = f * body.inv_m + g - s.v * body.c; // Eq. (42)
    let alpha = tau * body.inv_i - s.w * body.gamma; // Eq. (43)
    let v = s.v + a * dt; // Eq. (44)
    State {
        x: s.x + v * dt, // Eq. (45), with the new velocity (symplectic)
        v,
        q: spiral::<T>(s.q, s.w, alpha, dt), // Eq. (47), before ω is updated
        w: s.w + alpha * dt,                 // Eq. (46)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DQuat, DVec3};

    #[test]
    fn rotation_matches_the_library_on_both_sides_of_the_series() {
        let axis = DVec3::new(1.0, -2.0, 0.5).normalize();
        for k in 0..=3000 {
            let half_angle = k as f64 * 1e-4 * 1.0001; // up to 0.3 rad, past the series
            let q = rotation::<f64>(axis * half_angle * 1e3, 1e-3);
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
        assert_eq!(rotation::<f64>(DVec3::ZERO, 1e-3), DQuat::IDENTITY);
    }

    #[test]
    fn spiral_about_a_fixed_axis_is_exact() {
        let w = DVec3::new(0.0, 0.0, 3.0);
        let mut q = DQuat::IDENTITY;
        for _ in 0..1000 {
            q = spiral::<f64>(q, w, DVec3::ZERO, 1e-3);
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
            q = spiral::<f64>(q, DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, 1e-3);
        }
        let expected = DQuat::from_rotation_z(1.0) * q0;
        assert!(q.dot(expected).abs() > 1.0 - 1e-14, "{q:?} vs {expected:?}");
    }

    mod lanes {
        use super::*;
        use crate::model::lanes::Gather;
        use proptest::prelude::*;
        use wide::f64x8;

        fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
            (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
        }

        /// A particle with angular velocity and torque from none to far past the series
        /// (|ω| Δt/2 up to 0.5 rad at Δt = 1e-3), and the force and torque on it.
        fn particle() -> impl Strategy<Value = (f64, State, DVec3, DVec3)> {
            let spin = prop_oneof![Just(DVec3::ZERO), vec3(1.0), vec3(100.0), vec3(1000.0)];
            (
                1e-3..1e-2f64,
                (vec3(1.0), vec3(1.0), vec3(1.0), 0.0..6.0f64, spin),
                (
                    vec3(1e-2),
                    prop_oneof![Just(DVec3::ZERO), vec3(1e-7), vec3(1e-3)],
                ),
            )
                .prop_map(|(r, (x, v, axis, angle, w), (f, tau))| {
                    let axis = axis.try_normalize().unwrap_or(DVec3::X);
                    let q = DQuat::from_axis_angle(axis, angle);
                    (r, State { x, v, q, w }, f, tau)
                })
        }

        proptest! {
            /// The mass in lanes (and alone) has the bits of (4/3 π ρ) R.powi(3), the
            /// formula of the original program.
            #[test]
            fn masses_in_lanes_are_those_of_the_formula(
                radii in proptest::array::uniform8(1e-6..1.0f64),
                density in 1.0..1e5f64,
            ) {
                let lanes = Inertia::mass(f64x8::gather(radii), density).scatter();
                for (r, m) in radii.iter().zip(lanes) {
                    let formula = 4.0 / 3.0 * std::f64::consts::PI * density * r.powi(3);
                    prop_assert_eq!(m.to_bits(), formula.to_bits());
                    prop_assert_eq!(Inertia::mass(*r, density).to_bits(), formula.to_bits());
                }
            }

            /// The integration advances eight particles at once; each lane must give the
            /// bits of the particle advanced alone, on every branch of the rotation series.
            #[test]
            fn eight_lanes_advance_as_eight_single_particles(
                particles in proptest::array::uniform8(particle()),
                viscosity in prop_oneof![Just(0.0), 1e-5..1e-3f64],
            ) {
                let (density, dt, g) = (2500.0, 1e-3, DVec3::new(0.0, 0.0, -9.81));
                let single = particles.map(|(r, s, f, tau)| {
                    advance(s, &Response::new(r, density, viscosity), f, tau, g, dt)
                });
                let state = State::<f64x8> {
                    x: f64x8::gather_vec(particles.map(|p| p.1.x)),
                    v: f64x8::gather_vec(particles.map(|p| p.1.v)),
                    q: f64x8::gather_quat(particles.map(|p| p.1.q)),
                    w: f64x8::gather_vec(particles.map(|p| p.1.w)),
                };
                let body = Response::new(f64x8::gather(particles.map(|p| p.0)), density, viscosity);
                let (f, tau) = (particles.map(|p| p.2), particles.map(|p| p.3));
                let new = advance(
                    state,
                    &body,
                    f64x8::gather_vec(f),
                    f64x8::gather_vec(tau),
                    f64x8::splat_vec(g),
                    f64x8::splat(dt),
                );
                let (x, v, q, w) = (
                    f64x8::scatter_vec(new.x),
                    f64x8::scatter_vec(new.v),
                    f64x8::scatter_quat(new.q),
                    f64x8::scatter_vec(new.w),
                );
                let bits = |v: DVec3| v.to_array().map(f64::to_bits);
                for (l, alone) in single.iter().enumerate() {
                    prop_assert_eq!(bits(x[l]), bits(alone.x), "x, lane {}", l);
                    prop_assert_eq!(bits(v[l]), bits(alone.v), "v, lane {}", l);
                    prop_assert_eq!(bits(w[l]), bits(alone.w), "w, lane {}", l);
                    prop_assert_eq!(
                        q[l].to_array().map(f64::to_bits),
                        alone.q.to_array().map(f64::to_bits),
                        "q, lane {}",
                        l
                    );
                }
            }
        }
    }
}
