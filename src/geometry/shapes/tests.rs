use std::f64::consts::PI;

use super::*;
use crate::geometry::mesh::{Face, Primitive};

fn normal(f: &Face) -> DVec3 {
    match f.shape {
        Primitive::Triangle { n, .. } | Primitive::Rectangle { n, .. } => n,
        _ => panic!("a shape has only triangles and rectangles"),
    }
}

fn centroid(f: &Face) -> DVec3 {
    let c = f.corners();
    c.iter().sum::<DVec3>() / c.len() as f64
}

fn area(m: &Mesh) -> f64 {
    m.faces.iter().map(Face::area).sum()
}

/// The volume the faces enclose seen from `reference` (divergence theorem: a third of
/// the height of `reference` under each face times its area, by the outward normal). An
/// open end contributes nothing if `reference` lies in its plane.
fn volume(m: &Mesh, reference: DVec3) -> f64 {
    m.faces
        .iter()
        .map(|f| (centroid(f) - reference).dot(normal(f)) * f.area() / 3.0)
        .sum()
}

/// Every face's normal points away from `inside`.
fn faces_point_out(m: &Mesh, inside: DVec3) {
    for (k, f) in m.faces.iter().enumerate() {
        let out = (centroid(f) - inside).dot(normal(f));
        assert!(out > 0.0, "face {k} faces inwards ({out})");
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// The area of a regular polygon of `n` sides inscribed in the circle of radius `r`.
fn polygon(r: f64, n: u32) -> f64 {
    0.5 * n as f64 * r * r * (TAU / n as f64).sin()
}

/// The perimeter of that polygon.
fn perimeter(r: f64, n: u32) -> f64 {
    2.0 * n as f64 * r * (PI / n as f64).sin()
}

#[test]
fn frames_are_right_handed_and_orthonormal() {
    for a in [
        DVec3::Z,
        DVec3::X,
        -DVec3::Y,
        DVec3::new(1.0, 2.0, -3.0).normalize(),
    ] {
        let (u, v) = frame(a);
        assert!(u.dot(a).abs() < 1e-15 && v.dot(a).abs() < 1e-15 && u.dot(v).abs() < 1e-15);
        assert!((u.length() - 1.0).abs() < 1e-15 && (v.length() - 1.0).abs() < 1e-15);
        assert!((u.cross(v) - a).length() < 1e-15);
    }
    assert_eq!(frame(DVec3::Z), (DVec3::X, DVec3::Y));
}

#[test]
fn a_box_has_its_area_and_volume_and_open_sides() {
    let (min, max) = (DVec3::new(-0.1, 0.0, 0.2), DVec3::new(0.3, 0.5, 0.4));
    let (a, b, c) = (0.4, 0.5, 0.2);
    let closed = Shape::Box {
        min,
        max,
        open: [false; 6],
    }
    .mesh(0.001);
    assert_eq!((closed.faces.len(), closed.surfaces()), (6, 1));
    assert!(close(area(&closed), 2.0 * (a * b + b * c + a * c), 1e-12));
    assert!(close(volume(&closed, DVec3::ZERO), a * b * c, 1e-12));
    faces_point_out(&closed, 0.5 * (min + max));
    assert!(closed.faces.iter().all(|f| f.radius == 0.001));
    // Open at the top (+z): the lid is gone, the rest is one surface.
    let cup = Shape::Box {
        min,
        max,
        open: [false, false, false, false, false, true],
    }
    .mesh(0.0);
    assert_eq!((cup.faces.len(), cup.surfaces()), (5, 1));
    assert!(close(
        area(&cup),
        2.0 * (a * b + b * c + a * c) - a * b,
        1e-12
    ));
    let lid_center = DVec3::new(0.1, 0.25, 0.4);
    assert!(close(volume(&cup, lid_center), a * b * c, 1e-12));
    assert!(cup.faces.iter().all(|f| normal(f).z < 0.5));
}

#[test]
fn a_cylinder_converges_to_the_analytic_area_and_volume() {
    let (center, r, h) = (DVec3::new(0.1, -0.2, 0.0), 0.05, 0.3);
    let axis = DVec3::new(0.0, 1.0, 1.0).normalize();
    let mesh = |n, open, orifice| {
        Shape::Cylinder {
            center,
            axis,
            radius: r,
            height: h,
            open,
            orifice,
            resolution: n,
        }
        .mesh(0.0)
    };
    for n in [3, 48, 480] {
        let closed = mesh(n, [false; 2], 0.0);
        assert_eq!(closed.surfaces(), 1);
        let exact = 2.0 * polygon(r, n) + perimeter(r, n) * h;
        assert!(close(area(&closed), exact, 1e-12), "n {n}");
        assert!(close(
            volume(&closed, DVec3::ZERO),
            polygon(r, n) * h,
            1e-12
        ));
        faces_point_out(&closed, center + 0.5 * h * axis);
    }
    // Against the circle: the inscribed polygon's error falls as 1/n^2.
    let analytic = 2.0 * PI * r * r + 2.0 * PI * r * h;
    assert!(close(area(&mesh(48, [false; 2], 0.0)), analytic, 3e-3));
    assert!(close(area(&mesh(480, [false; 2], 0.0)), analytic, 3e-5));
    let v48 = volume(&mesh(48, [false; 2], 0.0), DVec3::ZERO);
    assert!(close(v48, PI * r * r * h, 3e-3));
    // Open at the top, an orifice in the bottom: one surface, the annulus' area.
    let silo = mesh(48, [false, true], 0.02);
    assert_eq!(silo.surfaces(), 1);
    let exact = polygon(r, 48) - polygon(0.02, 48) + perimeter(r, 48) * h;
    assert!(close(area(&silo), exact, 1e-12));
    // Seen from the open top's centre: the closed cylinder less the cone over the hole.
    let top = center + h * axis;
    assert!(close(
        volume(&silo, top),
        polygon(r, 48) * h - polygon(0.02, 48) * h / 3.0,
        1e-12
    ));
    // Open at both ends: a tube.
    let tube = mesh(48, [true, true], 0.0);
    assert_eq!(tube.faces.len(), 48);
    assert!(close(area(&tube), perimeter(r, 48) * h, 1e-12));
}

#[test]
fn a_drum_is_a_closed_cylinder_about_its_centre() {
    let (center, r, length) = (DVec3::new(0.0, 0.0, 0.1), 0.1, 0.04);
    let drum = Shape::Drum {
        center,
        axis: DVec3::Y,
        radius: r,
        length,
        resolution: 64,
    }
    .mesh(0.0);
    assert_eq!((drum.faces.len(), drum.surfaces()), (3 * 64, 1));
    assert!(close(
        area(&drum),
        2.0 * polygon(r, 64) + perimeter(r, 64) * length,
        1e-12
    ));
    assert!(close(volume(&drum, center), polygon(r, 64) * length, 1e-12));
    faces_point_out(&drum, center);
    let lo = drum.vertices.iter().fold(DVec3::INFINITY, |a, &v| a.min(v));
    let hi = drum
        .vertices
        .iter()
        .fold(DVec3::NEG_INFINITY, |a, &v| a.max(v));
    assert!((lo.y + 0.02).abs() < 1e-15 && (hi.y - 0.02).abs() < 1e-15);
    assert!((hi.z - 0.2).abs() < 1e-3 && (lo.z - 0.0).abs() < 1e-3);
}

#[test]
fn a_plane_is_a_square_facing_its_normal() {
    let n = DVec3::new(0.0, -1.0, 1.0).normalize();
    let plane = Shape::Plane {
        point: DVec3::new(1.0, 2.0, 3.0),
        normal: n,
        size: 0.5,
    }
    .mesh(0.002);
    assert_eq!(plane.faces.len(), 1);
    assert!(close(area(&plane), 0.25, 1e-12));
    assert!((normal(&plane.faces[0]) - n).length() < 1e-15);
    assert!((centroid(&plane.faces[0]) - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-15);
}

#[test]
fn a_hopper_is_a_frustum_open_at_both_ends() {
    let (center, r_o, r_t, h) = (DVec3::new(0.0, 0.0, 0.1), 0.01, 0.05, 0.08);
    let hopper = |outlet, top| {
        Shape::Hopper {
            center,
            axis: DVec3::Z,
            top_radius: top,
            outlet_radius: outlet,
            height: h,
            resolution: 48,
        }
        .mesh(0.0)
    };
    let funnel = hopper(r_o, r_t);
    assert_eq!((funnel.faces.len(), funnel.surfaces()), (96, 1));
    // The lateral area of the polygonal frustum: its trapezoids, each with the two chords
    // and the slant height between their midpoints.
    let apothem = |r: f64| r * (PI / 48.0).cos();
    let slant = (h * h + (apothem(r_t) - apothem(r_o)).powi(2)).sqrt();
    let exact = 0.5 * (perimeter(r_o, 48) + perimeter(r_t, 48)) * slant;
    assert!(close(area(&funnel), exact, 1e-12));
    let analytic = PI * (r_o + r_t) * (h * h + (r_t - r_o).powi(2)).sqrt();
    assert!(close(area(&funnel), analytic, 3e-3));
    // Its volume: seen from the outlet's centre, plus the open top's cone.
    let frustum = h / 3.0 * (polygon(r_o, 48) + polygon(r_t, 48))
        + h / 3.0 * (polygon(r_o, 48) * polygon(r_t, 48)).sqrt();
    let top_cone = h * polygon(r_t, 48) / 3.0;
    assert!(close(volume(&funnel, center) + top_cone, frustum, 1e-12));
    assert!(funnel.faces.iter().all(|f| normal(f).z < 0.0));
    // Closed at the outlet (a cone): the same faces meet at the apex.
    let cone = hopper(0.0, r_t);
    assert_eq!((cone.faces.len(), cone.surfaces()), (48, 1));
    // Seen from the open top's centre, the faces enclose the cone (the apex is the outlet).
    assert!(close(volume(&cone, center + h * DVec3::Z), top_cone, 1e-12));
    assert!(cone.faces.iter().all(|f| normal(f).z < 0.0));
}
