//! One contact per touch: which of a particle's face contacts with one connected surface
//! are contacts of their own (the "merged" mode of `mesh_contacts`).
//!
//! A surface S is the union of the faces of one mesh file that share vertices and have the
//! same radius R_j (`mesh.rs`). The original program sums a contact for every face within
//! reach, so a sphere resting on the diagonal shared by two triangles of a flat plate feels
//! two contacts, on the centre of a fan of six triangles six, and near an edge a contact
//! with the neighbouring face's edge on top of the one with the face it rests on.
//!
//! # The rule
//!
//! A particle with centre x touches S where the distance from x to S has a local minimum
//! (below R_i + R_j). For each face F within reach let p_F be its closest point to x.
//! 1. A candidate whose point p_F lies on another face G of the surface (within `tol`) while
//!    G's own closest point p_G is elsewhere (farther than `tol`) is not a touch of its
//!    own: it is covered (an edge or vertex of a neighbouring face, covered by G).
//! 2. Of the others, taken face interiors first and then in order of increasing distance
//!    |x - p_F|, one whose point coincides (within `tol`) with that of a contact taken
//!    before it is the same touch: it is merged into that contact. Interiors first: within
//!    `tol` of an edge of a flat plate the edge point and the face point are one touch, and
//!    the face's normal is the right one (the edge's would tilt by the offset over the
//!    height and balance the sphere as on a knife edge).
//! 3. Any other candidate is a contact. A surface's nearest candidate always is.
//!
//! Covered and merged candidates hand their friction springs to the contact that absorbs
//! them (for a covered one the nearest), if that contact has none of its own: so a sphere
//! rolling from one triangle across an edge onto the next keeps its history.
//!
//! # Why this counts each touch once
//!
//! Faces are convex, so the distance from x to one face is a convex function on that face,
//! and its only local minimum is the closest point p_F. Near a point q of S, S is the union
//! of the faces that contain q, so q is a local minimum of the distance to S exactly when
//! it is the closest point of every face that contains it. A candidate p_F that lies on a
//! face G with p_G != p_F is therefore no local minimum (rule 1; G's point is nearer, but
//! rule 1 does not rely on that: near an edge the two distances differ by less than their
//! rounding). A candidate that passes is the closest point of every face containing it: a
//! local minimum, reported once however many faces share it (rule 2). Local minima that
//! are apart (a sphere in a groove touches both walls, in a box corner three) are
//! distinct contacts. On a flat plate, across a convex ridge and on a
//! convex body (a tessellated sphere) the distance has a single local minimum, so there is
//! exactly one contact, whose overlap is that of the surface's nearest point.
//!
//! Limits: a concave fold that is nearly flat (a finely tessellated drum wall) gives two
//! contacts within a band about R_i times the fold angle wide around the fold line: both
//! are local minima. The rules are geometric, so a T-junction (a vertex in the middle
//! of a neighbour's edge) is handled as long as the faces are one surface, that is, linked
//! by shared vertices somewhere; pieces of a file that share no vertex are separate
//! surfaces, as are separate files.

use glam::DVec3;

use crate::geometry::closest::Feature;
use crate::geometry::mesh::{Contacts, Face, Primitive};

/// A face within reach of a particle: the face, and its closest point to the centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    pub face: u32,
    /// Closest point p_F of the undilated face.
    pub point: DVec3,
    /// |x - p_F|².
    pub dist2: f64,
    /// Whether p_F lies inside the face (not on an edge or vertex), so that x - p_F is
    /// along the face normal.
    pub interior: bool,
}

/// What becomes of a candidate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fate {
    /// A contact of its own.
    Contact,
    /// The same touch as contact `k` (an index into the candidates), which takes over its
    /// springs.
    Absorbed(usize),
}

/// The separation to use for `face` at separation `d` = x - p_F (`feature` of p_F) from a
/// particle at `x` of radius `radius`, and whether p_F counts as inside the face.
///
/// With merged contacts, a closest point on an edge or vertex of a triangle or a rectangle
/// whose separation leans less than [`tolerance`] off the face normal is taken as inside
/// the face, with the separation along the normal: on a flat plate the closest points of
/// coplanar triangles near their shared edge may all land on it by rounding, and their
/// separations then lean by the rounding over the height, which balances a sphere rolling
/// along the edge as on a knife edge. Per face, the separation is the original program's.
#[inline]
pub fn snap(face: &Face, x: DVec3, radius: f64, d: DVec3, feature: Feature) -> (DVec3, bool) {
    if feature == Feature::Face {
        return (d, true);
    }
    let normal = match face.shape {
        Primitive::Triangle { n, .. } | Primitive::Rectangle { n, .. }
            if face.contacts == Contacts::Merged =>
        {
            n
        }
        _ => return (d, false),
    };
    let along = d.dot(normal) * normal;
    let tol = tolerance(x, radius);
    match (d - along).length_squared() <= tol * tol {
        true => (along, true),
        false => (d, false),
    }
}

/// The tolerance of "coincide" and "lies on" for a particle of radius `radius` at `x`:
/// far below any physical length, far above the rounding of closest points.
#[inline]
pub fn tolerance(x: DVec3, radius: f64) -> f64 {
    1e-9 * radius + 1e-13 * x.abs().max_element()
}

/// Decides the fate of each of one particle's `candidates` (see the module comment);
/// `order` is scratch space. Candidates of different surfaces never affect each other.
pub fn resolve(
    candidates: &[Candidate],
    faces: &[Face],
    tol: f64,
    order: &mut Vec<usize>,
    fates: &mut Vec<Fate>,
) {
    fates.clear();
    fates.resize(candidates.len(), Fate::Contact);
    let n = candidates.len();
    let surface = |k: usize| faces[candidates[k].face as usize].surface;
    if !(1..n).any(|k| (0..k).any(|m| surface(m) == surface(k))) {
        return;
    }
    let tol2 = tol * tol;
    let apart =
        |a: usize, b: usize| candidates[a].point.distance_squared(candidates[b].point) > tol2;
    // Rule 1, whatever the order: the distances of a covered edge point and of the face
    // point covering it may differ by less than their rounding.
    const COVERED: Fate = Fate::Absorbed(usize::MAX);
    for k in 0..n {
        let p = candidates[k].point;
        let covered = (0..n).any(|m| {
            m != k
                && surface(m) == surface(k)
                && apart(m, k)
                && faces[candidates[m].face as usize]
                    .separation(p)
                    .length_squared()
                    <= tol2
        });
        if covered {
            fates[k] = COVERED;
        }
    }
    order.clear();
    order.extend(0..n);
    order.sort_by(|&a, &b| {
        let (ca, cb) = (&candidates[a], &candidates[b]);
        cb.interior
            .cmp(&ca.interior)
            .then(ca.dist2.total_cmp(&cb.dist2))
            .then(a.cmp(&b))
    });
    for (rank, &k) in order.iter().enumerate() {
        let mut earlier = order[..rank]
            .iter()
            .copied()
            .filter(|&m| surface(m) == surface(k));
        if fates[k] == COVERED {
            // A surface's nearest candidate is a contact even if rounding made every one
            // of them look covered.
            let first = earlier.next().is_none();
            if first && (0..n).all(|m| surface(m) != surface(k) || fates[m] == COVERED) {
                fates[k] = Fate::Contact;
            }
            continue;
        }
        // Rule 2: the same point as a contact taken before.
        if let Some(s) = earlier.find(|&s| fates[s] == Fate::Contact && !apart(s, k)) {
            fates[k] = Fate::Absorbed(s);
        }
    }
    // The covered hand their springs to the nearest contact.
    for k in 0..n {
        if fates[k] == COVERED {
            let p = candidates[k].point;
            let nearest = order
                .iter()
                .copied()
                .filter(|&s| surface(s) == surface(k) && fates[s] == Fate::Contact)
                .min_by(|&a, &b| {
                    let d = |s: usize| candidates[s].point.distance_squared(p);
                    d(a).total_cmp(&d(b))
                })
                .expect("every surface keeps a contact");
            fates[k] = Fate::Absorbed(nearest);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mesh::Mesh;

    fn mesh(off: &str) -> Mesh {
        Mesh::parse_off(off, "test", &[0.0]).unwrap()
    }

    /// The fates of a particle at `x` with reach `reach` (all faces within it).
    fn fates(mesh: &Mesh, x: DVec3, reach: f64) -> Vec<(u32, Fate)> {
        let candidates: Vec<Candidate> = mesh
            .faces
            .iter()
            .enumerate()
            .filter_map(|(f, face)| {
                let (d, feature) = face.separation_and_feature(x);
                let (d, interior) = snap(face, x, reach, d, feature);
                (d.length_squared() < reach * reach).then_some(Candidate {
                    face: f as u32,
                    point: x - d,
                    dist2: d.length_squared(),
                    interior,
                })
            })
            .collect();
        let mut fates = Vec::new();
        resolve(
            &candidates,
            &mesh.faces,
            tolerance(x, reach),
            &mut Vec::new(),
            &mut fates,
        );
        candidates.iter().map(|c| c.face).zip(fates).collect()
    }

    fn contacts(f: &[(u32, Fate)]) -> Vec<u32> {
        f.iter()
            .filter(|(_, fate)| *fate == Fate::Contact)
            .map(|(face, _)| *face)
            .collect()
    }

    /// A unit square split along its diagonal from (0,0) to (1,1).
    const SQUARE: &str = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";

    #[test]
    fn a_shared_diagonal_is_one_contact() {
        let m = mesh(SQUARE);
        assert_eq!(m.surfaces(), 1);
        // On the diagonal: both faces give the same point.
        let f = fates(&m, DVec3::new(0.4, 0.4, 0.01), 0.02);
        assert_eq!(f.len(), 2);
        assert_eq!(contacts(&f).len(), 1, "{f:?}");
        // Just beside it, over face 0: face 1's edge point is covered by face 0.
        let f = fates(&m, DVec3::new(0.401, 0.4, 0.01), 0.02);
        assert_eq!(f, vec![(0, Fate::Contact), (1, Fate::Absorbed(0))]);
        let f = fates(&m, DVec3::new(0.4, 0.401, 0.01), 0.02);
        assert_eq!(f, vec![(0, Fate::Absorbed(1)), (1, Fate::Contact)]);
    }

    #[test]
    fn per_face_keeps_every_contact() {
        let m = mesh(SQUARE).with_contacts(crate::geometry::mesh::Contacts::PerFace);
        assert_eq!(m.surfaces(), 2);
        let f = fates(&m, DVec3::new(0.4, 0.4, 0.01), 0.02);
        assert_eq!(contacts(&f).len(), 2);
    }

    #[test]
    fn the_walls_of_a_groove_are_two_contacts() {
        // Floor z = 0 (x >= 0) and wall x = 0 (z >= 0), sharing the edge along y.
        let m = mesh(
            "OFF\n6 2 0\n0 -1 0\n1 -1 0\n1 1 0\n0 1 0\n0 -1 1\n0 1 1\n\
             4 0 1 2 3\n4 0 3 5 4\n",
        );
        assert_eq!(m.surfaces(), 1);
        let f = fates(&m, DVec3::new(0.009, 0.0, 0.009), 0.01);
        assert_eq!(contacts(&f).len(), 2, "{f:?}");
    }

    #[test]
    fn different_radii_or_files_are_different_surfaces() {
        let m = Mesh::parse_off(
            "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 0\n3 0 2 3 1\n",
            "test",
            &[0.0, 0.001],
        )
        .unwrap();
        assert_eq!(m.surfaces(), 2);
        let mut two = mesh(SQUARE);
        two.append(mesh(SQUARE));
        assert_eq!(two.surfaces(), 2);
        assert_eq!(
            contacts(&fates(&two, DVec3::new(0.4, 0.4, 0.01), 0.02)).len(),
            2
        );
    }

    mod brute_force {
        //! The contacts against the local minima of the distance to the surface, found
        //! without the rule: flat and folded sheets of random triangles, a tessellated
        //! sphere.
        use super::*;
        use proptest::prelude::*;

        /// A mesh from vertices and triangles.
        fn triangles(vertices: &[DVec3], faces: &[[usize; 3]]) -> Mesh {
            let mut off = format!("OFF\n{} {} 0\n", vertices.len(), faces.len());
            for v in vertices {
                off += &format!("{:?} {:?} {:?}\n", v.x, v.y, v.z);
            }
            for f in faces {
                off += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
            }
            mesh(&off)
        }

        /// A sheet over the unit square of (u, v): a grid of `n` x `n` cells, inner vertices
        /// moved by up to a third of a cell (`jitter`, in [-1, 1]), each cell split along a
        /// diagonal chosen by `flip`; `place` maps (u, v) into space. Vertices and triangles.
        fn sheet(
            n: usize,
            jitter: &[f64],
            flip: &[bool],
            place: impl Fn(f64, f64) -> DVec3,
        ) -> (Vec<DVec3>, Vec<[usize; 3]>) {
            let h = 1.0 / n as f64;
            let mut vertices = Vec::new();
            for j in 0..=n {
                for i in 0..=n {
                    let inner = i > 0 && i < n && j > 0 && j < n;
                    let k = j * (n + 1) + i;
                    let (du, dv) = match inner {
                        true => (
                            jitter[2 * k % jitter.len()],
                            jitter[(2 * k + 1) % jitter.len()],
                        ),
                        false => (0.0, 0.0),
                    };
                    vertices.push(place((i as f64 + du / 3.0) * h, (j as f64 + dv / 3.0) * h));
                }
            }
            let at = |i: usize, j: usize| j * (n + 1) + i;
            let mut faces = Vec::new();
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    if flip[(j * n + i) % flip.len()] {
                        faces.extend([[a, b, c], [a, c, d]]);
                    } else {
                        faces.extend([[a, b, d], [b, c, d]]);
                    }
                }
            }
            (vertices, faces)
        }

        /// The points of the contacts of a particle at `x` with reach `reach`.
        fn contact_points(m: &Mesh, x: DVec3, reach: f64) -> Vec<DVec3> {
            let f = fates(m, x, reach);
            let point = |face: u32| x - m.faces[face as usize].separation(x);
            f.iter()
                .filter(|(_, fate)| *fate == Fate::Contact)
                .map(|&(face, _)| point(face))
                .collect()
        }

        proptest! {
            #[test]
            fn a_flat_sheet_is_touched_once_at_the_foot_of_the_centre(
                n in 1usize..6,
                jitter in prop::collection::vec(-1.0..1.0f64, 72),
                flip in prop::collection::vec(any::<bool>(), 36),
                (u, v, h) in (0.05..0.95f64, 0.05..0.95f64, 1e-4..0.05f64),
            ) {
                let (v0, f0) = sheet(n, &jitter, &flip, |u, v| DVec3::new(u, v, 0.0));
                let m = triangles(&v0, &f0);
                let x = DVec3::new(u, v, h);
                let points = contact_points(&m, x, 0.05);
                prop_assert_eq!(points.len(), 1, "{:?}", fates(&m, x, 0.05));
                prop_assert!(points[0].distance(DVec3::new(u, v, 0.0)) < 1e-12, "{:?}", points);
            }

            #[test]
            fn a_folded_sheet_is_touched_at_each_local_minimum(
                (n, angle) in (1usize..5, -60.0..60.0f64),
                jitter in prop::collection::vec(-1.0..1.0f64, 72),
                flip in prop::collection::vec(any::<bool>(), 36),
                (x0, y0, z0) in (-0.3..0.3f64, 0.1..0.9f64, 1e-3..0.2f64),
            ) {
                // Half-plane A: z = 0, x in [-1, 0]; half-plane B: from the fold line x = z = 0
                // along e = (cos, 0, sin), tilted up (concave) or down (convex).
                let e = DVec3::new(angle.to_radians().cos(), 0.0, angle.to_radians().sin());
                // One file: the sheets share the vertices of the fold line (as 0 and -0).
                let (mut vs, mut fs) = sheet(n, &jitter, &flip, |u, v| DVec3::new(u - 1.0, v, 0.0));
                let (vb, fb) = sheet(n, &jitter, &flip, |u, v| e * u + DVec3::Y * v);
                fs.extend(fb.iter().map(|f| f.map(|k| k + vs.len())));
                vs.extend(vb);
                let m = triangles(&vs, &fs);
                prop_assert_eq!(m.surfaces(), 1);
                let x = DVec3::new(x0, y0, z0);
                let reach = 0.15;
                // The local minima of the distance to A ∪ B: each projection that falls
                // inside its half-plane, else the fold line's point if neither does.
                let normal_b = DVec3::new(-e.z, 0.0, e.x);
                let (on_a, on_b) = (x.x <= 0.0, x.dot(e) >= 0.0);
                let mut expected = Vec::new();
                if on_a {
                    expected.push(DVec3::new(x.x, x.y, 0.0));
                }
                if on_b {
                    expected.push(x - x.dot(normal_b) * normal_b);
                }
                if !on_a && !on_b {
                    expected.push(DVec3::new(0.0, x.y, 0.0));
                }
                // Keep away from the boundaries of reach and of the Voronoi regions, and
                // from the far side of B.
                prop_assume!(x.dot(normal_b) > 1e-3);
                prop_assume!(x.x.abs() > 1e-6 && x.dot(e).abs() > 1e-6);
                let expected: Vec<DVec3> =
                    expected.into_iter().filter(|p| p.distance(x) < reach).collect();
                prop_assume!(expected.iter().all(|p| (p.distance(x) - reach).abs() > 1e-6));
                let mut points = contact_points(&m, x, reach);
                points.sort_by(|a, b| a.x.total_cmp(&b.x));
                prop_assert_eq!(points.len(), expected.len(), "{:?} vs {:?}", points, expected);
                for (p, q) in points.iter().zip(&expected) {
                    prop_assert!(p.distance(*q) < 1e-12, "{:?} vs {:?}", points, expected);
                }
            }

            #[test]
            fn a_tessellated_sphere_is_touched_once_like_a_sphere(
                (theta, phi) in (0.0..std::f64::consts::PI, 0.0..std::f64::consts::TAU),
                depth in -0.2..0.8f64,
            ) {
                let (m, facet_error) = icosphere(0.1);
                prop_assert_eq!(m.faces.len(), 320);
                let r = 0.01;
                let dir = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                // Overlap with the true sphere: depth * r.
                let x = dir * (0.1 + r - depth * r);
                let nearest = m
                    .faces
                    .iter()
                    .map(|f| f.separation(x).length())
                    .fold(f64::INFINITY, f64::min);
                let points = contact_points(&m, x, r);
                if nearest < r {
                    prop_assert_eq!(points.len(), 1);
                    let overlap = r - points[0].distance(x);
                    prop_assert!((overlap - (r - nearest)).abs() < 1e-12);
                    prop_assert!(
                        (overlap - depth * r).abs() <= facet_error + 1e-12,
                        "overlap {} vs {} on the sphere", overlap, depth * r
                    );
                } else {
                    prop_assert!(points.is_empty());
                }
            }
        }

        /// An icosahedron subdivided twice (320 triangles) on a sphere of radius `radius`
        /// about the origin, and its faceting error: how far inside the sphere its faces
        /// reach (the radius less the nearest face plane's distance).
        fn icosphere(radius: f64) -> (Mesh, f64) {
            let t = (1.0 + 5f64.sqrt()) / 2.0;
            let mut v: Vec<DVec3> = [
                (-1.0, t, 0.0),
                (1.0, t, 0.0),
                (-1.0, -t, 0.0),
                (1.0, -t, 0.0),
                (0.0, -1.0, t),
                (0.0, 1.0, t),
                (0.0, -1.0, -t),
                (0.0, 1.0, -t),
                (t, 0.0, -1.0),
                (t, 0.0, 1.0),
                (-t, 0.0, -1.0),
                (-t, 0.0, 1.0),
            ]
            .iter()
            .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
            .collect();
            let mut f: Vec<[usize; 3]> = vec![
                [0, 11, 5],
                [0, 5, 1],
                [0, 1, 7],
                [0, 7, 10],
                [0, 10, 11],
                [1, 5, 9],
                [5, 11, 4],
                [11, 10, 2],
                [10, 7, 6],
                [7, 1, 8],
                [3, 9, 4],
                [3, 4, 2],
                [3, 2, 6],
                [3, 6, 8],
                [3, 8, 9],
                [4, 9, 5],
                [2, 4, 11],
                [6, 2, 10],
                [8, 6, 7],
                [9, 8, 1],
            ];
            for _ in 0..2 {
                let mut mid = std::collections::HashMap::new();
                let mut split = |a: usize, b: usize, v: &mut Vec<DVec3>| {
                    *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                        v.push(((v[a] + v[b]) / 2.0).normalize());
                        v.len() - 1
                    })
                };
                f = f
                    .iter()
                    .flat_map(|&[a, b, c]| {
                        let (ab, bc, ca) = (
                            split(a, b, &mut v),
                            split(b, c, &mut v),
                            split(c, a, &mut v),
                        );
                        [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
                    })
                    .collect();
            }
            let v: Vec<DVec3> = v.iter().map(|p| *p * radius).collect();
            let m = triangles(&v, &f);
            let inset = m
                .faces
                .iter()
                .map(|face| match face.shape {
                    Primitive::Triangle { a, n, .. } => radius - a.dot(n).abs(),
                    _ => unreachable!(),
                })
                .fold(0.0, f64::max);
            (m, inset)
        }
    }
}
