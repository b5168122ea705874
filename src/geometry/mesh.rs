//! Meshes (paper Section 3.3): faces of one to four vertices are points, rounded edges,
//! triangles and rectangles, each with its own radius R_j. Read from OFF or STL files.
//!
//! Faces of one file that share a vertex (the same position) and have the same radius form
//! one connected surface; a particle's contacts with one surface count each touch once
//! (see `surface.rs`).

use anyhow::{Result, bail};
use glam::DVec3;

use crate::geometry::closest::{
    Feature, closest_on_segment, separation_from_rectangle, separation_from_triangle,
};
use crate::model::motion::Pose;

/// The shape of one mesh face (Fig. 4A-D).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    Point(DVec3),
    Segment(DVec3, DVec3),
    /// Vertices and unit normal.
    Triangle {
        a: DVec3,
        b: DVec3,
        c: DVec3,
        n: DVec3,
    },
    /// Corner `o`, perpendicular edges `e1`, `e2` (vertices o, o+e1, o+e1+e2, o+e2) and
    /// unit normal `n`.
    Rectangle {
        o: DVec3,
        e1: DVec3,
        e2: DVec3,
        n: DVec3,
    },
}

/// One mesh element: a primitive dilated by its radius R_j.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    pub shape: Primitive,
    /// R_j \[L\], from the scenario's `mesh_radii`.
    pub radius: f64,
    /// The connected surface the face belongs to (an index unique within a [`Mesh`]).
    pub surface: u32,
    /// Whether the contacts of the face's file are merged per surface or counted per face.
    pub contacts: Contacts,
}

impl Face {
    /// Separation vector `x - p` from the closest point `p` of the (undilated) primitive.
    #[inline]
    pub fn separation(&self, x: DVec3) -> DVec3 {
        self.separation_and_feature(x).0
    }

    /// Separation vector `x - p` from the closest point `p`, and the feature `p` lies on:
    /// `Face` (the interior of a triangle or rectangle: `x - p` is along the normal), `Edge`
    /// or `Vertex`. A segment's interior is an edge, a point a vertex.
    #[inline]
    pub fn separation_and_feature(&self, x: DVec3) -> (DVec3, Feature) {
        match self.shape {
            Primitive::Point(p) => (x - p, Feature::Vertex),
            Primitive::Segment(a, b) => (x - closest_on_segment(x, a, b), Feature::Edge),
            Primitive::Triangle { a, b, c, n } => separation_from_triangle(x, a, b, c, n),
            Primitive::Rectangle { o, e1, e2, n } => separation_from_rectangle(x, o, e1, e2, n),
        }
    }

    /// Whether `x` is certainly farther than `reach` from the primitive: for a triangle or
    /// a rectangle, from the distance to its plane alone (a cheap first test).
    #[inline]
    pub fn certainly_beyond(&self, x: DVec3, reach: f64) -> bool {
        match self.shape {
            Primitive::Triangle { a: p, n, .. } | Primitive::Rectangle { o: p, n, .. } => {
                (x - p).dot(n).abs() >= reach
            }
            Primitive::Point(_) | Primitive::Segment(..) => false,
        }
    }

    /// Closest point of the (undilated) primitive to `x`.
    pub fn closest_point(&self, x: DVec3) -> DVec3 {
        x - self.separation(x)
    }

    /// The face moved rigidly to `pose`.
    pub fn moved(&self, pose: &Pose) -> Face {
        let (p, v) = (|x| pose.point(x), |x| pose.vector(x));
        let shape = match self.shape {
            Primitive::Point(a) => Primitive::Point(p(a)),
            Primitive::Segment(a, b) => Primitive::Segment(p(a), p(b)),
            Primitive::Triangle { a, b, c, n } => Primitive::Triangle {
                a: p(a),
                b: p(b),
                c: p(c),
                n: v(n),
            },
            Primitive::Rectangle { o, e1, e2, n } => Primitive::Rectangle {
                o: p(o),
                e1: v(e1),
                e2: v(e2),
                n: v(n),
            },
        };
        Face { shape, ..*self }
    }

    /// The corner points of the primitive.
    pub fn corners(&self) -> Vec<DVec3> {
        match self.shape {
            Primitive::Point(a) => vec![a],
            Primitive::Segment(a, b) => vec![a, b],
            Primitive::Triangle { a, b, c, .. } => vec![a, b, c],
            Primitive::Rectangle { o, e1, e2, .. } => vec![o, o + e1, o + e1 + e2, o + e2],
        }
    }

    /// The unit normal of a triangle or rectangle (`None` for points and segments).
    pub fn normal(&self) -> Option<DVec3> {
        match self.shape {
            Primitive::Triangle { n, .. } | Primitive::Rectangle { n, .. } => Some(n),
            Primitive::Point(_) | Primitive::Segment(..) => None,
        }
    }

    /// Area of the (undilated) primitive: 0 for points and segments.
    pub fn area(&self) -> f64 {
        match self.shape {
            Primitive::Point(_) | Primitive::Segment(..) => 0.0,
            Primitive::Triangle { a, b, c, .. } => 0.5 * (b - a).cross(c - a).length(),
            Primitive::Rectangle { e1, e2, .. } => e1.cross(e2).length(),
        }
    }

    /// Axis-aligned bounding box of the dilated face.
    pub fn bounding_box(&self) -> (DVec3, DVec3) {
        let (lo, hi) = match self.shape {
            Primitive::Point(p) => (p, p),
            Primitive::Segment(a, b) => (a.min(b), a.max(b)),
            Primitive::Triangle { a, b, c, .. } => (a.min(b).min(c), a.max(b).max(c)),
            Primitive::Rectangle { o, e1, e2, .. } => {
                let c = [o, o + e1, o + e1 + e2, o + e2];
                (
                    c[0].min(c[1]).min(c[2]).min(c[3]),
                    c[0].max(c[1]).max(c[2]).max(c[3]),
                )
            }
        };
        (
            lo - DVec3::splat(self.radius),
            hi + DVec3::splat(self.radius),
        )
    }
}

/// A mesh: a list of faces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub faces: Vec<Face>,
    /// All vertices, for output and pictures.
    pub vertices: Vec<DVec3>,
}

/// How a mesh file's faces are grouped into surfaces (`mesh_contacts`, `[[meshes]]
/// contacts`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Contacts {
    /// Faces that share a vertex and a radius form one surface, touched once per touch.
    #[default]
    Merged,
    /// Every face is a surface of its own: a contact per face touched, as in the original
    /// program.
    PerFace,
}

/// Labels each face with its connected surface: faces whose corners `corners(f)` share a
/// position and whose radii are equal get the same label; labels count up from 0 in the
/// order of first appearance.
fn connect<'a>(faces: &mut [Face], corners: impl Fn(usize) -> &'a [DVec3]) {
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn root(parent: &mut [usize], mut f: usize) -> usize {
        while parent[f] != f {
            parent[f] = parent[parent[f]];
            f = parent[f];
        }
        f
    }
    // `+ 0.0` makes -0 and 0 one position.
    let bits = |v: DVec3| (v + DVec3::ZERO).to_array().map(f64::to_bits);
    let mut first = rustc_hash::FxHashMap::default();
    for (f, face) in faces.iter().enumerate() {
        for &v in corners(f) {
            let other = *first.entry((bits(v), face.radius.to_bits())).or_insert(f);
            let (a, b) = (root(&mut parent, f), root(&mut parent, other));
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut label = rustc_hash::FxHashMap::default();
    for (f, face) in faces.iter_mut().enumerate() {
        let r = root(&mut parent, f);
        let next = label.len() as u32;
        face.surface = *label.entry(r).or_insert(next);
    }
}

/// Strips an OFF comment (`#` to the end of the line).
fn strip_comment(line: &str) -> &str {
    line.split('#').next().unwrap_or("").trim()
}

fn parse_numbers<T: std::str::FromStr>(
    file: &str,
    lineno: usize,
    line: &str,
    what: &str,
) -> Result<Vec<T>> {
    line.split_whitespace()
        .map(|tok| {
            tok.parse::<T>().map_err(|_| {
                anyhow::anyhow!("{file}:{lineno}: expected {what}, found '{tok}' in line '{line}'")
            })
        })
        .collect()
}

impl Mesh {
    /// Parses OFF text (GeomView Object File Format): a line `OFF`, a line with the numbers
    /// of vertices, faces and edges, one line `x y z` per vertex, and one line
    /// `k v_1 ... v_k [i]` per face with 1 <= k <= 4 vertices and an optional index `i`
    /// into `radii` (default 0). Rectangles list their corners in order around them.
    pub fn parse_off(text: &str, file: &str, radii: &[f64]) -> Result<Mesh> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(k, l)| (k + 1, strip_comment(l)))
            .filter(|(_, l)| !l.is_empty());
        let (nv, nf) = off_counts(&mut lines, text.len(), file)?;
        let mut vertices = Vec::with_capacity(nv);
        for k in 0..nv {
            let Some((n, line)) = lines.next() else {
                bail!("{file}: ends after {k} of {nv} vertices");
            };
            vertices.push(off_vertex(line, file, n)?);
        }
        let mut faces = Vec::with_capacity(nf);
        let mut corners = Vec::with_capacity(nf);
        for k in 0..nf {
            let Some((n, line)) = lines.next() else {
                bail!("{file}: ends after {k} of {nf} faces");
            };
            let (face, v) = off_face(line, (file, n), &vertices, radii)?;
            faces.push(face);
            corners.push(v);
        }
        if let Some((n, line)) = lines.next() {
            bail!("{file}:{n}: unexpected line '{line}' after the {nf} faces the header announced");
        }
        connect(&mut faces, |f| &corners[f]);
        Ok(Mesh { faces, vertices })
    }

    /// A mesh of polygons given as indices into `vertices` (one to four corners each, as
    /// `primitive` takes them), all of radius `radius`; faces that share a vertex form
    /// one surface. For meshes made in code (`shapes.rs`): a polygon is refused only where
    /// the numbers it was made of are beyond double precision (an axis of 1e200).
    pub fn from_polygons(
        vertices: Vec<DVec3>,
        polygons: &[Vec<usize>],
        radius: f64,
    ) -> std::result::Result<Mesh, &'static str> {
        let corners: Vec<Vec<DVec3>> = polygons
            .iter()
            .map(|p| p.iter().map(|&k| vertices[k]).collect())
            .collect();
        let mut faces = Vec::with_capacity(corners.len());
        for c in &corners {
            if !c.iter().all(|v| v.is_finite()) {
                return Err("a corner is not a finite point (its coordinates overflow)");
            }
            faces.push(Face {
                shape: primitive(c)?,
                radius,
                surface: 0,
                contacts: Contacts::Merged,
            });
        }
        connect(&mut faces, |f| &corners[f]);
        Ok(Mesh { faces, vertices })
    }

    /// Number of surfaces (one more than the largest label).
    pub fn surfaces(&self) -> u32 {
        self.faces.iter().map(|f| f.surface + 1).max().unwrap_or(0)
    }

    /// Groups the faces as `contacts` says: `PerFace` makes every face a surface of its own.
    pub fn with_contacts(mut self, contacts: Contacts) -> Mesh {
        for (k, f) in self.faces.iter_mut().enumerate() {
            f.contacts = contacts;
            if contacts == Contacts::PerFace {
                f.surface = k as u32;
            }
        }
        self
    }

    /// Adds the faces and vertices of `other`, its surfaces after this mesh's own.
    pub fn append(&mut self, other: Mesh) {
        let offset = self.surfaces();
        self.faces.extend(other.faces.into_iter().map(|f| Face {
            surface: f.surface + offset,
            ..f
        }));
        self.vertices.extend(other.vertices);
    }

    /// Parses an STL file, binary (80-byte header, triangle count, 50 bytes per triangle) or
    /// ASCII (`solid`, then `facet normal ... outer loop vertex x y z (3x) endloop endfacet`,
    /// `endsolid`). Every triangle gets the radius `radius` (STL has no per-face data).
    pub fn parse_stl(bytes: &[u8], file: &str, radius: f64) -> Result<Mesh> {
        let binary_size = |n: u64| 84 + 50 * n;
        let looks_binary = bytes.len() >= 84
            && binary_size(u32::from_le_bytes(bytes[80..84].try_into()?) as u64)
                == bytes.len() as u64;
        let triangles = if looks_binary || !bytes.trim_ascii_start().starts_with(b"solid") {
            stl_binary(bytes, file)?
        } else {
            let text = std::str::from_utf8(bytes).map_err(|_| {
                anyhow::anyhow!("{file}: starts with 'solid' but is neither ASCII STL nor binary STL of the right size")
            })?;
            stl_ascii(text, file)?
        };
        let mut mesh = Mesh::default();
        for (k, (v, where_)) in triangles.into_iter().enumerate() {
            let normal = (v[1] - v[0]).cross(v[2] - v[0]);
            if normal.length_squared() == 0.0 {
                bail!("{file}:{where_}: degenerate triangle {k} (its vertices are collinear)");
            }
            mesh.vertices.extend_from_slice(&v);
            mesh.faces.push(Face {
                shape: Primitive::Triangle {
                    a: v[0],
                    b: v[1],
                    c: v[2],
                    n: normal.normalize(),
                },
                radius,
                surface: 0,
                contacts: Contacts::Merged,
            });
        }
        let vertices = &mesh.vertices;
        connect(&mut mesh.faces, |f| &vertices[3 * f..3 * f + 3]);
        Ok(mesh)
    }
}

/// Triangles of a binary STL file, each with a description of where it is.
fn stl_binary(bytes: &[u8], file: &str) -> Result<Vec<([DVec3; 3], String)>> {
    if bytes.len() < 84 {
        bail!(
            "{file}: too short for binary STL ({} bytes, expected at least 84) and not ASCII STL",
            bytes.len()
        );
    }
    let n = u32::from_le_bytes(bytes[80..84].try_into()?) as u64;
    if 84 + 50 * n != bytes.len() as u64 {
        bail!(
            "{file}: binary STL announces {n} triangles, which take {} bytes, but the file has {} bytes",
            84 + 50 * n,
            bytes.len()
        );
    }
    let f = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as f64;
    (0..n as usize)
        .map(|k| {
            let base = 84 + 50 * k + 12; // skip the normal
            let mut v = [DVec3::ZERO; 3];
            for (i, slot) in v.iter_mut().enumerate() {
                let at = base + 12 * i;
                *slot = DVec3::new(f(at), f(at + 4), f(at + 8));
            }
            if !v.iter().all(|p| p.is_finite()) {
                bail!(
                    "{file}: triangle {k} (byte {}) has a non-finite vertex",
                    84 + 50 * k
                );
            }
            Ok((v, format!("byte {}", 84 + 50 * k)))
        })
        .collect()
}

/// Triangles of an ASCII STL file, each with its line number.
fn stl_ascii(text: &str, file: &str) -> Result<Vec<([DVec3; 3], String)>> {
    let mut out = Vec::new();
    let mut vertices: Vec<DVec3> = Vec::with_capacity(3);
    let mut facet_line = 0;
    let mut ended = false;
    for (k, line) in text.lines().enumerate() {
        let n = k + 1;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first().copied() {
            None => {}
            Some("solid") => ended = false, // files may hold several solids
            Some("facet") => {
                facet_line = n;
                vertices.clear();
            }
            Some("outer") | Some("endloop") => {}
            Some("vertex") => {
                let xyz: Vec<f64> = words[1..].iter().filter_map(|w| w.parse().ok()).collect();
                if words.len() != 4 || xyz.len() != 3 || xyz.iter().any(|x| !x.is_finite()) {
                    bail!(
                        "{file}:{n}: expected 'vertex x y z' with three finite numbers, found '{}'",
                        line.trim()
                    );
                }
                if vertices.len() == 3 {
                    bail!("{file}:{n}: a facet has more than three vertices");
                }
                vertices.push(DVec3::new(xyz[0], xyz[1], xyz[2]));
            }
            Some("endfacet") => {
                if vertices.len() != 3 {
                    bail!(
                        "{file}:{n}: facet of line {facet_line} has {} vertices, expected 3",
                        vertices.len()
                    );
                }
                out.push((
                    [vertices[0], vertices[1], vertices[2]],
                    facet_line.to_string(),
                ));
            }
            Some("endsolid") => ended = true,
            Some(other) => bail!("{file}:{n}: unexpected '{other}' in ASCII STL"),
        }
    }
    if !ended {
        bail!("{file}: ASCII STL ends without 'endsolid' (truncated?)");
    }
    Ok(out)
}

/// The primitive with corners `v` (one to four, in order around the face): a point, a
/// segment, a triangle (normal by the right-hand rule) or a rectangle (normal `e1 x e2`),
/// or what is wrong with them.
pub(crate) fn primitive(v: &[DVec3]) -> std::result::Result<Primitive, &'static str> {
    match *v {
        [a] => Ok(Primitive::Point(a)),
        [a, b] => Ok(Primitive::Segment(a, b)),
        [a, b, c] => {
            let normal = (b - a).cross(c - a);
            if normal.length_squared() == 0.0 {
                return Err("degenerate triangle (its vertices are collinear)");
            }
            Ok(Primitive::Triangle {
                a,
                b,
                c,
                n: unit_normal(normal)?,
            })
        }
        [v0, v1, v2, v3] => rectangle([v0, v1, v2, v3]),
        _ => Err("a face has 1 to 4 vertices (point, edge, triangle, rectangle)"),
    }
}

/// Checks that four vertices, in order around the face, form a rectangle.
fn rectangle(v: [DVec3; 4]) -> std::result::Result<Primitive, &'static str> {
    let (o, e1, e2) = (v[0], v[1] - v[0], v[3] - v[0]);
    let scale = e1.length().max(e2.length());
    if !scale.is_finite() {
        return Err(TOO_LARGE);
    }
    let tol = 1e-9 * scale;
    if scale == 0.0 || e1.length() <= tol || e2.length() <= tol {
        return Err("degenerate rectangle (two corners coincide)");
    }
    if (o + e1 + e2 - v[2]).length() > tol || e1.dot(e2).abs() > tol * scale {
        return Err(
            "the four vertices do not form a rectangle (v0, v1, v2, v3 in order around it); split other quadrilaterals into two triangles",
        );
    }
    Ok(Primitive::Rectangle {
        o,
        e1,
        e2,
        n: unit_normal(e1.cross(e2))?,
    })
}

/// The unit vector along a face's normal, refused where the face's size is beyond what
/// double precision squares (lengths above about 1e150) and no direction comes out.
fn unit_normal(normal: DVec3) -> std::result::Result<DVec3, &'static str> {
    let n = normal.normalize();
    match n.is_finite() && (n.length() - 1.0).abs() < 1e-6 {
        true => Ok(n),
        false => Err(TOO_LARGE),
    }
}

const TOO_LARGE: &str =
    "a face too large or too far out for double precision (its squared lengths overflow)";

/// The numbers of vertices and faces of an OFF file of `size` bytes, from its header lines.
fn off_counts<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    size: usize,
    file: &str,
) -> Result<(usize, usize)> {
    let Some((n0, header)) = lines.next() else {
        bail!("{file}: empty file, expected an OFF mesh starting with the line 'OFF'");
    };
    // The counts may follow the keyword on the same line.
    let rest = match header.strip_prefix("OFF") {
        Some(rest) => rest.trim(),
        None => bail!("{file}:{n0}: expected the keyword 'OFF', found '{header}'"),
    };
    let (n1, counts_line) = if rest.is_empty() {
        match lines.next() {
            Some(l) => l,
            None => bail!("{file}: ends after 'OFF', expected the line 'vertices faces edges'"),
        }
    } else {
        (n0, rest)
    };
    let counts: Vec<u64> = parse_numbers(
        file,
        n1,
        counts_line,
        "the counts 'vertices faces edges' (whole numbers)",
    )?;
    if counts.len() < 2 || counts.len() > 3 {
        bail!("{file}:{n1}: expected the counts 'vertices faces edges', found '{counts_line}'");
    }
    let (nv, nf) = (counts[0] as usize, counts[1] as usize);
    let remaining = size;
    if nv > remaining || nf > remaining {
        bail!(
            "{file}:{n1}: the header announces {nv} vertices and {nf} faces, more than the file can hold"
        );
    }

    Ok((nv, nf))
}

/// A vertex line `x y z` (line `n` of `file`).
fn off_vertex(line: &str, file: &str, n: usize) -> Result<DVec3> {
    let xyz: Vec<f64> = parse_numbers(file, n, line, "a vertex 'x y z'")?;
    if xyz.len() != 3 || xyz.iter().any(|x| !x.is_finite()) {
        bail!("{file}:{n}: expected a vertex as three finite numbers 'x y z', found '{line}'");
    }
    Ok(DVec3::new(xyz[0], xyz[1], xyz[2]))
}

/// A face line `k v_1 ... v_k [i]` (line `n` of `file`): the face, with the radius of
/// index `i` of `radii`, and its corners.
fn off_face(
    line: &str,
    (file, n): (&str, usize),
    vertices: &[DVec3],
    radii: &[f64],
) -> Result<(Face, Vec<DVec3>)> {
    let nv = vertices.len();
    let ints: Vec<i64> = parse_numbers(
        file,
        n,
        line,
        "a face 'k v_1 ... v_k [radius index]' (whole numbers)",
    )?;
    let count = ints[0];
    if !(1..=4).contains(&count) {
        bail!(
            "{file}:{n}: a face has 1 to 4 vertices (point, edge, triangle, rectangle), found {count}"
        );
    }
    let count = count as usize;
    let extra = ints.len() - 1;
    if extra < count || extra > count + 1 {
        bail!(
            "{file}:{n}: expected {count} vertex indices and an optional radius index, found {extra} numbers after the vertex count"
        );
    }
    let mut v = [DVec3::ZERO; 4];
    for (slot, &idx) in v.iter_mut().zip(&ints[1..=count]) {
        if idx < 0 || idx as usize >= nv {
            bail!("{file}:{n}: vertex index {idx} is out of range 0..{nv}");
        }
        *slot = vertices[idx as usize];
    }
    let ri = if extra == count + 1 {
        ints[count + 1]
    } else {
        0
    };
    if ri < 0 || ri as usize >= radii.len() {
        bail!(
            "{file}:{n}: radius index {ri} is out of range: mesh_radii has {} entries",
            radii.len()
        );
    }
    let shape = primitive(&v[..count]).map_err(|e| anyhow::anyhow!("{file}:{n}: {e}"))?;
    let face = Face {
        shape,
        radius: radii[ri as usize],
        surface: 0,
        contacts: Contacts::Merged,
    };
    Ok((face, v[..count].to_vec()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hourglass() -> Mesh {
        Mesh::parse_off(
            crate::scenario::HOURGLASS_OFF,
            "hourglass",
            &[0.002, 0.02, 0.01],
        )
        .unwrap()
    }

    #[test]
    fn hourglass_parses() {
        let m = hourglass();
        assert_eq!(m.faces.len(), 19);
        assert_eq!(m.faces[17].radius, 0.02);
        assert!(matches!(m.faces[17].shape, Primitive::Point(_)));
        assert!(matches!(m.faces[18].shape, Primitive::Segment(..)));
        assert!(matches!(m.faces[0].shape, Primitive::Rectangle { .. }));
    }

    #[test]
    fn the_plane_test_never_rejects_a_face_within_reach() {
        let m = hourglass();
        let mut s = 3u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut rejected = 0;
        for _ in 0..20_000 {
            let x = DVec3::new(rnd() * 0.3 - 0.15, rnd() * 0.3 - 0.15, rnd() * 0.35 - 0.02);
            let reach = 0.05 * rnd();
            for face in &m.faces {
                if face.certainly_beyond(x, reach) {
                    rejected += 1;
                    assert!(face.separation(x).length() >= reach, "{x} {face:?}");
                }
            }
        }
        assert!(rejected > 10_000, "the test rejects something: {rejected}");
    }

    #[test]
    fn faces_that_share_a_position_and_a_radius_form_one_surface() {
        // Two squares side by side (the shared corners written twice, once as -0), and a
        // third apart; a rounded edge along the shared side with another radius.
        let m = Mesh::parse_off(
            "OFF\n12 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n1 -0 0\n2 0 0\n2 1 0\n1 1 0\n\
             5 0 0\n6 0 0\n6 1 0\n5 1 0\n4 0 1 2 3\n4 4 5 6 7\n4 8 9 10 11\n2 1 2 1\n",
            "m.off",
            &[0.0, 0.001],
        )
        .unwrap();
        let s: Vec<u32> = m.faces.iter().map(|f| f.surface).collect();
        assert_eq!(s, vec![0, 0, 1, 2]);
        assert_eq!(m.surfaces(), 3);
        let m = m.with_contacts(Contacts::PerFace);
        let s: Vec<u32> = m.faces.iter().map(|f| f.surface).collect();
        assert_eq!(s, vec![0, 1, 2, 3]);
        // STL repeats every vertex: triangles are joined by position.
        let stl = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n\
                   endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\n\
                   vertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
        assert_eq!(
            Mesh::parse_stl(stl.as_bytes(), "s.stl", 0.0)
                .unwrap()
                .surfaces(),
            1
        );
    }

    fn err(text: &str) -> String {
        format!("{:#}", Mesh::parse_off(text, "m.off", &[0.0]).unwrap_err())
    }

    #[test]
    fn bad_faces_are_named() {
        let base = "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
        assert!(err(&format!("{base}5 0 1 2 3 0\n")).contains("m.off:7: a face has 1 to 4"));
        assert!(err(&format!("{base}3 0 1 9\n")).contains("vertex index 9 is out of range"));
        assert!(err(&format!("{base}3 0 1 2 4\n")).contains("radius index 4"));
        assert!(err(&format!("{base}4 0 1 3 2\n")).contains("do not form a rectangle"));
        assert!(err(&format!("{base}3 0 x 2\n")).contains("found 'x'"));
        assert!(err("OFF\n4 1 0\n0 0 0\n").contains("ends after 1 of 4 vertices"));
        assert!(err("").contains("empty file"));
        assert!(err("OFF\n4 1 0\n0 0 0\n1 0 nan\n").contains("m.off:4"));
    }
}
