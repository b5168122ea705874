use super::*;
use crate::model::clump::{Moments, Sphere};

/// Jacobi's elliptic functions sn, cn, dn of `u` with parameter m = k², by the arithmetic-
/// geometric mean and descending Landen transformation (Abramowitz & Stegun 16.4).
fn jacobi(u: f64, m: f64) -> (f64, f64, f64) {
    let (mut a, mut b) = (vec![1.0], (1.0 - m).sqrt());
    let mut c = vec![m.sqrt()];
    while c.last().unwrap().abs() > 1e-16 && a.len() < 40 {
        let (an, bn) = (*a.last().unwrap(), b);
        a.push((an + bn) / 2.0);
        b = (an * bn).sqrt();
        c.push((an - bn) / 2.0);
    }
    let n = a.len() - 1;
    let mut phi = vec![0.0; n + 1];
    phi[n] = 2f64.powi(n as i32) * a[n] * u;
    for k in (1..=n).rev() {
        phi[k - 1] = (phi[k] + (c[k] / a[k] * phi[k].sin()).asin()) / 2.0;
    }
    let (sn, cn) = phi[0].sin_cos();
    let dn = (1.0 - m * sn * sn).sqrt();
    (sn, cn, dn)
}

const I: DVec3 = DVec3::new(1.0, 2.0, 3.0);

/// The body-frame angular velocity at time t of the free body with moments `I`, started at
/// (w1, 0, w3) with L² > 2 E I₂ (Landau & Lifshitz §37).
fn analytic(w1: f64, w3: f64, t: f64) -> DVec3 {
    let l = I * DVec3::new(w1, 0.0, w3);
    let (l2, e2) = (l.length_squared(), 2.0 * energy(l, I));
    let (i1, i2, i3) = (I.x, I.y, I.z);
    let tau = t * ((i3 - i2) * (l2 - e2 * i1) / (i1 * i2 * i3)).sqrt();
    let m = (i2 - i1) * (e2 * i3 - l2) / ((i3 - i2) * (l2 - e2 * i1));
    let (sn, cn, dn) = jacobi(tau, m);
    DVec3::new(
        ((e2 * i3 - l2) / (i1 * (i3 - i1))).sqrt() * cn,
        ((e2 * i3 - l2) / (i2 * (i3 - i2))).sqrt() * sn,
        ((l2 - e2 * i1) / (i3 * (i3 - i1))).sqrt() * dn,
    )
}

#[test]
fn jacobi_functions_at_known_values() {
    let (sn, cn, dn) = jacobi(0.5, 0.0);
    assert!((sn - 0.5f64.sin()).abs() < 1e-15 && (cn - 0.5f64.cos()).abs() < 1e-15);
    assert!((dn - 1.0).abs() < 1e-15);
    // At the quarter period K(1/2) = 1.854074677301372: sn = 1, cn = 0, dn = sqrt(1 - m).
    let (sn, cn, dn) = jacobi(1.854_074_677_301_372, 0.5);
    assert!((sn - 1.0).abs() < 1e-14 && cn.abs() < 1e-7 && (dn - 0.5f64.sqrt()).abs() < 1e-14);
    // sn² + cn² = 1, dn² + m sn² = 1.
    let (sn, cn, dn) = jacobi(1.3, 0.6);
    assert!(
        (sn * sn + cn * cn - 1.0).abs() < 1e-15 && (dn * dn + 0.6 * sn * sn - 1.0).abs() < 1e-15
    );
}

#[test]
fn torque_free_rotation_keeps_energy_and_momentum() {
    let mut q = DQuat::from_rotation_y(0.3) * DQuat::from_rotation_x(-1.1);
    let mut l = I * DVec3::new(2.0, 0.3, 1.0);
    let (e0, l0) = (energy(l, I), q * l);
    let h = 1e-3;
    let mut worst_e = 0.0f64;
    for _ in 0..100_000 {
        (q, l) = free_rotation(q, l, I, h);
        worst_e = worst_e.max((energy(l, I) / e0 - 1.0).abs());
    }
    let drift = (q * l - l0).length() / l0.length();
    assert!(worst_e < 1e-6, "energy {worst_e}");
    assert!(drift < 1e-9, "L in space moved by {drift}");
    assert!(((q.length() - 1.0).abs()) < 1e-14);
}

#[test]
fn the_angular_velocity_follows_jacobis_solution_at_second_order() {
    let (w1, w3) = (1.0, 2.0);
    let exact = analytic(w1, w3, 2.0);
    let error = |h: f64| {
        let (mut q, mut l) = (DQuat::IDENTITY, I * DVec3::new(w1, 0.0, w3));
        for _ in 0..(2.0 / h).round() as usize {
            (q, l) = free_rotation(q, l, I, h);
        }
        (l / I - exact).length()
    };
    let (e1, e2, e3) = (error(0.02), error(0.01), error(0.005));
    let order = ((e1 / e2).log2() + (e2 / e3).log2()) / 2.0;
    assert!((order - 2.0).abs() < 0.1, "order {order}: {e1} {e2} {e3}");
    assert!(e3 < 1e-4, "{e3}");
}

/// The principal moments of a T of five unit spheres: a bar of three along x and a stem
/// of two below its middle.
fn t_shape() -> DVec3 {
    let at = |x: f64, y: f64| Sphere {
        centre: DVec3::new(x, y, 0.0),
        radius: 1.0,
    };
    let spheres = [
        at(-1.8, 0.0),
        at(0.0, 0.0),
        at(1.8, 0.0),
        at(0.0, -1.8),
        at(0.0, -3.6),
    ];
    Moments::of_union(&spheres).principal().0
}

/// Spun about principal axis `a` with a small push about the others, the largest share of
/// the angular momentum that axis loses over 30 turns (2: it turned over).
fn wobble(inertia: DVec3, a: usize) -> f64 {
    let mut w = DVec3::splat(1e-3);
    w[a] = 1.0;
    let (mut q, mut l) = (DQuat::IDENTITY, inertia * w);
    let (start, period) = (l[a], std::f64::consts::TAU / 1.0);
    let mut lost = 0.0f64;
    let h = period / 400.0;
    for _ in 0..30 * 400 {
        (q, l) = free_rotation(q, l, inertia, h);
        lost = lost.max(1.0 - l[a] / start);
    }
    lost
}

#[test]
fn a_t_shaped_clump_flips_about_its_intermediate_axis_only() {
    let moments = t_shape();
    assert!(moments.x < moments.y && moments.y < moments.z, "{moments}");
    // Dzhanibekov: the intermediate axis turns over; the minor and major axes stay.
    assert!(wobble(moments, 1) > 1.9);
    assert!(wobble(moments, 0) < 1e-3);
    assert!(wobble(moments, 2) < 1e-3);
}

#[test]
fn equal_moments_turn_at_a_constant_angular_velocity() {
    let w = DVec3::new(0.3, -2.0, 1.0);
    let (mut q, mut omega) = (DQuat::IDENTITY, w);
    for _ in 0..1000 {
        (q, omega) = step(q, omega, DVec3::ZERO, DVec3::splat(0.4), 1e-3);
    }
    assert!(
        (omega - w).length() < 1e-12 * 1000.0,
        "{}",
        (omega - w).length()
    );
    // The splitting turns about the three axes in turn: second order, not exact.
    let expected = DQuat::from_scaled_axis(w * 1.0);
    assert!(
        q.dot(expected).abs() > 1.0 - 1e-9,
        "{}",
        1.0 - q.dot(expected).abs()
    );
    // A torque about a principal axis of an asymmetric body spins it up about that axis.
    let (_, omega) = step(DQuat::IDENTITY, DVec3::ZERO, DVec3::Z * 3.0, I, 0.1);
    assert!((omega - DVec3::Z * 0.1).length() < 1e-15);
}
