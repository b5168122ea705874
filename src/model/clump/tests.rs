use super::*;
use std::f64::consts::PI;

fn sphere(x: f64, y: f64, z: f64, r: f64) -> Sphere {
    Sphere {
        centre: DVec3::new(x, y, z),
        radius: r,
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

#[test]
fn gauss_legendre_integrates_polynomials_exactly() {
    let rule = gauss_legendre(5);
    let sum = |f: &dyn Fn(f64) -> f64| rule.iter().map(|&(x, w)| w * f(x)).sum::<f64>();
    assert!(close(sum(&|_| 1.0), 2.0, 1e-14));
    assert!(close(sum(&|x| x.powi(8)), 2.0 / 9.0, 1e-13));
    assert!(sum(&|x| x.powi(7)).abs() < 1e-15);
}

#[test]
fn spheres_apart_have_the_sum_of_their_moments() {
    let r = 0.5;
    let m = Moments::of_union(&[sphere(-1.0, 0.0, 0.0, r), sphere(1.0, 0.0, 0.0, r)]);
    let v = 4.0 / 3.0 * PI * r.powi(3);
    assert!(close(m.volume, 2.0 * v, 1e-12), "{}", m.volume);
    assert!(m.centroid.length() < 1e-12);
    let own = 0.4 * v * r * r;
    let i = m.inertia;
    assert!(close(i.x_axis.x, 2.0 * own, 1e-12));
    assert!(
        close(i.y_axis.y, 2.0 * own + 2.0 * v, 1e-12),
        "{}",
        i.y_axis.y
    );
    assert!(i.x_axis.y.abs() < 1e-12 && m.error < 1e-12);
}

/// The union of two spheres of radius r with centres at z = ±d/2 as a solid of revolution:
/// the cross-section radius at z is that of the nearer sphere. Volume, axial and
/// transverse moments about the centre, by Simpson's rule on each smooth half.
fn dumbbell_reference(r: f64, d: f64) -> (f64, f64, f64) {
    let h = d / 2.0;
    let rho2 = |z: f64| (r * r - (z - h) * (z - h)).max(0.0);
    let n = 200_000;
    let (mut v, mut ia, mut it) = (0.0, 0.0, 0.0);
    for k in 0..=n {
        let z = (h + r) * k as f64 / n as f64;
        let w = if k == 0 || k == n {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let a = rho2(z);
        v += w * PI * a;
        ia += w * PI / 2.0 * a * a;
        it += w * (PI / 4.0 * a * a + PI * a * z * z);
    }
    let dz = (h + r) / n as f64 / 3.0;
    // Both halves (z < 0 mirrors z > 0).
    (2.0 * v * dz, 2.0 * ia * dz, 2.0 * it * dz)
}

#[test]
fn a_dumbbell_of_overlapping_spheres_counts_the_lens_once() {
    let (r, d) = (1.0, 1.2);
    let m = Moments::of_union(&[sphere(0.0, 0.0, -d / 2.0, r), sphere(0.0, 0.0, d / 2.0, r)]);
    // The lens: V = π (4r + d)(2r - d)² / 12.
    let lens = PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
    let exact = 2.0 * 4.0 / 3.0 * PI * r.powi(3) - lens;
    assert!(close(m.volume, exact, 1e-3), "{} vs {exact}", m.volume);
    let (v, axial, transverse) = dumbbell_reference(r, d);
    assert!(close(v, exact, 1e-9), "reference {v} vs {exact}");
    let i = m.inertia;
    assert!(close(i.z_axis.z, axial, 1e-3), "{} vs {axial}", i.z_axis.z);
    assert!(
        close(i.x_axis.x, transverse, 1e-3),
        "{} vs {transverse}",
        i.x_axis.x
    );
    assert!(close(i.y_axis.y, transverse, 1e-3));
    assert!(m.centroid.length() < 1e-4 && m.error < 1e-3, "{m:?}");
    // Counting both spheres whole would overstate the mass by the lens.
    assert!(lens / exact > 0.1);
}

#[test]
fn a_sphere_inside_another_adds_nothing() {
    let m = Moments::of_union(&[sphere(0.0, 0.0, 0.0, 1.0), sphere(0.2, 0.1, 0.0, 0.5)]);
    assert!(close(m.volume, 4.0 / 3.0 * PI, 1e-9), "{}", m.volume);
    // In either order.
    let m = Moments::of_union(&[sphere(0.2, 0.1, 0.0, 0.5), sphere(0.0, 0.0, 0.0, 1.0)]);
    assert!(close(m.volume, 4.0 / 3.0 * PI, 1e-3), "{}", m.volume);
}

#[test]
fn the_principal_frame_of_a_skew_trimer() {
    // Three spheres along a skew line: the smallest moment is about that line.
    let axis = DVec3::new(1.0, 2.0, 2.0) / 3.0;
    let spheres: Vec<Sphere> = [-1.0, 0.0, 1.0]
        .iter()
        .map(|&t| Sphere {
            centre: DVec3::new(0.3, -0.2, 0.1) + axis * 0.8 * t,
            radius: 0.5,
        })
        .collect();
    let m = Moments::of_union(&spheres);
    assert!((m.centroid - DVec3::new(0.3, -0.2, 0.1)).length() < 1e-5);
    let (moments, rotation) = m.principal();
    assert!(moments.x < moments.y && (moments.y - moments.z).abs() < 1e-3 * moments.z);
    let first = rotation * DVec3::X;
    assert!(first.dot(axis).abs() > 1.0 - 1e-6, "{first}");
    // The rotation diagonalises the tensor.
    let r = DMat3::from_quat(rotation);
    let d = r.transpose() * m.inertia * r;
    assert!(d.x_axis.y.abs() < 1e-9 * moments.z && d.y_axis.z.abs() < 1e-9 * moments.z);
    assert!(close(d.x_axis.x, moments.x, 1e-12));
}
