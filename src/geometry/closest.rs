//! Closest-point queries between a particle centre and the four mesh primitives
//! (paper Section 3.3, Fig. 4): a point, a line segment, a triangle and a rectangle.
//!
//! Each query returns the point of the primitive nearest to `x`; the caller adds the
//! primitive's radius `R_j` (rounded edges and vertices) when it computes the overlap.
//! The planar faces also give the separation vector `x - closest` directly as its normal
//! part plus the overhang beyond the edges: then a particle moving in a plane parallel to
//! a Cartesian plane sees no rounding error across that plane (exact 2D runs).

use glam::DVec3;

/// Closest point to `x` on the segment from `a` to `b` (Fig. 4B).
pub fn closest_on_segment(x: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return a;
    }
    let t = ((x - a).dot(ab) / len2).clamp(0.0, 1.0);
    a + t * ab
}

/// Which feature of a primitive the closest point lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    Vertex,
    Edge,
    Face,
}

/// Closest point to `x` on the triangle `a, b, c` (Fig. 4C) and the feature it lies on, by
/// Voronoi regions of its vertices, edges and face (Ericson, Real-Time Collision
/// Detection, Sec. 5.1.5).
pub fn closest_on_triangle(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, Feature) {
    let ab = b - a;
    let ac = c - a;
    let ax = x - a;
    let d1 = ab.dot(ax);
    let d2 = ac.dot(ax);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex);
    }
    let bx = x - b;
    let d3 = ab.dot(bx);
    let d4 = ac.dot(bx);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + d1 / (d1 - d3) * ab, Feature::Edge); // edge ab
    }
    let cx = x - c;
    let d5 = ab.dot(cx);
    let d6 = ac.dot(cx);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + d2 / (d2 - d6) * ac, Feature::Edge); // edge ac
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + t * (c - b), Feature::Edge); // edge bc
    }
    let denom = 1.0 / (va + vb + vc);
    (a + ab * (vb * denom) + ac * (vc * denom), Feature::Face)
}

/// Separation `x - closest` from the triangle `a, b, c` with unit normal `n`, and the
/// feature of the closest point: in the face region exactly the normal part of `x - a`.
#[inline]
pub fn separation_from_triangle(
    x: DVec3,
    a: DVec3,
    b: DVec3,
    c: DVec3,
    n: DVec3,
) -> (DVec3, Feature) {
    match closest_on_triangle(x, a, b, c) {
        (_, Feature::Face) => ((x - a).dot(n) * n, Feature::Face),
        (p, feature) => (x - p, feature),
    }
}

/// Separation `x - closest` from the rectangle with corner `o`, perpendicular edges `e1`,
/// `e2` and unit normal `n` (Fig. 4D): the normal part of `x - o` plus the overhang of the
/// in-plane coordinates beyond [0, 1]; and the feature of the closest point.
#[inline]
pub fn separation_from_rectangle(
    x: DVec3,
    o: DVec3,
    e1: DVec3,
    e2: DVec3,
    n: DVec3,
) -> (DVec3, Feature) {
    let d = x - o;
    let s = d.dot(e1) / e1.length_squared();
    let t = d.dot(e2) / e2.length_squared();
    let overhang = |u: f64| {
        if u < 0.0 {
            u
        } else if u > 1.0 {
            u - 1.0
        } else {
            0.0
        }
    };
    let (os, ot) = (overhang(s), overhang(t));
    let feature = match (os == 0.0, ot == 0.0) {
        (true, true) => Feature::Face,
        (false, false) => Feature::Vertex,
        _ => Feature::Edge,
    };
    (d.dot(n) * n + os * e1 + ot * e2, feature)
}

/// Closest point to `x` on the rectangle (see [`separation_from_rectangle`]).
pub fn closest_on_rectangle(x: DVec3, o: DVec3, e1: DVec3, e2: DVec3) -> DVec3 {
    x - separation_from_rectangle(x, o, e1, e2, e1.cross(e2).normalize()).0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator so the brute-force tests need no extra crate.
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn vec(&mut self, scale: f64) -> DVec3 {
            DVec3::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5) * 2.0 * scale
        }
    }

    /// Brute force: the nearest of many points sampled on the primitive (given by a
    /// parametrisation over the unit square) is never closer than the query's answer,
    /// and the answer is within sampling resolution of the sampled minimum.
    fn check(x: DVec3, answer: DVec3, sample: impl Fn(f64, f64) -> Option<DVec3>, res: f64) {
        let n = 400;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n {
                if let Some(p) = sample(i as f64 / n as f64, j as f64 / n as f64) {
                    best = best.min(p.distance(x));
                }
            }
        }
        let d = answer.distance(x);
        assert!(d <= best + 1e-12, "answer {d} farther than sample {best}");
        assert!(d >= best - res, "answer {d} much closer than sample {best}");
    }

    #[test]
    fn segment_matches_sampling() {
        let mut rng = Lcg(1);
        for _ in 0..50 {
            let (a, b, x) = (rng.vec(1.0), rng.vec(1.0), rng.vec(2.0));
            let p = closest_on_segment(x, a, b);
            check(x, p, |s, _| Some(a + s * (b - a)), 1e-2);
        }
        let a = DVec3::ONE;
        assert_eq!(closest_on_segment(DVec3::ZERO, a, a), a);
    }

    #[test]
    fn triangle_matches_sampling() {
        let mut rng = Lcg(2);
        for _ in 0..50 {
            let (a, b, c, x) = (rng.vec(1.0), rng.vec(1.0), rng.vec(1.0), rng.vec(2.0));
            let (p, _) = closest_on_triangle(x, a, b, c);
            check(
                x,
                p,
                |s, t| (s + t <= 1.0).then(|| a + s * (b - a) + t * (c - a)),
                2e-2,
            );
        }
    }

    #[test]
    fn rectangle_matches_sampling() {
        let mut rng = Lcg(3);
        for _ in 0..50 {
            let o = rng.vec(1.0);
            let e1 = rng.vec(1.0);
            let e2 = e1.normalize().any_orthonormal_vector() * rng.next() * 2.0;
            let x = rng.vec(2.0);
            let p = closest_on_rectangle(x, o, e1, e2);
            check(x, p, |s, t| Some(o + s * e1 + t * e2), 2e-2);
        }
    }

    #[test]
    fn face_region_projects_onto_plane() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let (p, f) = closest_on_triangle(DVec3::new(0.2, 0.3, 0.7), a, b, c);
        assert_eq!(f, Feature::Face);
        assert!(p.distance(DVec3::new(0.2, 0.3, 0.0)) < 1e-15);
    }
}
