//! Built-in shapes (`[[meshes]] shape = { type = ... }`): a box, a cylinder (with an
//! orifice), a drum, a plane and a hopper, made of the mesh primitives of Fig. 4, so that
//! no one has to write an OFF file for a container.
//!
//! Every shape is one connected surface (its polygons share their vertices exactly), and
//! its polygons wind counter-clockwise seen from outside, so the faces' normals point out.
//! Round shapes are polygons of `resolution` sides inscribed in their circles (vertex k at
//! the angle 2 pi k / resolution from the first in-plane axis of [`frame`]).

use std::f64::consts::TAU;

use glam::DVec3;

use crate::geometry::mesh::Mesh;

/// The sides of a box, named by their outward axis, in this order.
pub const BOX_SIDES: [&str; 6] = ["-x", "+x", "-y", "+y", "-z", "+z"];

/// The two ends of a cylinder.
pub const CYLINDER_ENDS: [&str; 2] = ["bottom", "top"];

/// A built-in shape, validated (`scenario/validate.rs`): lengths positive, axes unit.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// The faces of the box `min`-`max` but those `open` marks (by [`BOX_SIDES`]).
    Box {
        min: DVec3,
        max: DVec3,
        open: [bool; 6],
    },
    /// A cylinder standing on the disk of `radius` about `center` (its bottom) and
    /// reaching `height` along `axis`; its ends closed unless `open` (by
    /// [`CYLINDER_ENDS`]); a closed bottom with a centred hole of radius `orifice` (0:
    /// none).
    Cylinder {
        center: DVec3,
        axis: DVec3,
        radius: f64,
        height: f64,
        open: [bool; 2],
        orifice: f64,
        resolution: u32,
    },
    /// A closed cylinder of `length` along `axis`, centred at `center`.
    Drum {
        center: DVec3,
        axis: DVec3,
        radius: f64,
        length: f64,
        resolution: u32,
    },
    /// A square of side `size` centred at `point`, normal to `normal`.
    Plane {
        point: DVec3,
        normal: DVec3,
        size: f64,
    },
    /// A cone frustum open at both ends: the circle of `outlet_radius` about `center`,
    /// and `height` along `axis` the wider circle of `top_radius` (an outlet of 0: a cone
    /// closed at its apex).
    Hopper {
        center: DVec3,
        axis: DVec3,
        top_radius: f64,
        outlet_radius: f64,
        height: f64,
        resolution: u32,
    },
}

/// Two unit vectors `u`, `v` that make `(u, v, a)` a right-handed orthonormal frame for the
/// unit vector `a`: `u` is the coordinate axis least along `a` (x first on a tie) with its
/// part along `a` removed, so an axis along z gives u = x, v = y.
pub fn frame(a: DVec3) -> (DVec3, DVec3) {
    let m = a.abs();
    let e = if m.x <= m.y && m.x <= m.z {
        DVec3::X
    } else if m.y <= m.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let u = (e - e.dot(a) * a).normalize();
    (u, a.cross(u))
}

/// Polygons over shared vertices, as a shape is put together.
#[derive(Default)]
struct Polygons {
    vertices: Vec<DVec3>,
    polygons: Vec<Vec<usize>>,
}

impl Polygons {
    fn vertex(&mut self, p: DVec3) -> usize {
        self.vertices.push(p);
        self.vertices.len() - 1
    }

    /// `n` vertices on the circle of radius `r` about `c` in the plane of `(u, v)`,
    /// counter-clockwise about `u x v`.
    fn ring(&mut self, c: DVec3, (u, v): (DVec3, DVec3), r: f64, n: u32) -> Vec<usize> {
        (0..n)
            .map(|k| {
                let (s, co) = (TAU * k as f64 / n as f64).sin_cos();
                self.vertex(c + r * (co * u + s * v))
            })
            .collect()
    }

    /// The band between two rings of one count (`low` below `high` along the axis),
    /// facing away from the axis: rectangles if `rectangles`, else two triangles a side.
    fn band(&mut self, low: &[usize], high: &[usize], rectangles: bool) {
        let n = low.len();
        for k in 0..n {
            let (b0, b1, t0, t1) = (low[k], low[(k + 1) % n], high[k], high[(k + 1) % n]);
            if rectangles {
                self.polygons.push(vec![b0, b1, t1, t0]);
            } else {
                self.polygons.push(vec![b0, b1, t1]);
                self.polygons.push(vec![b0, t1, t0]);
            }
        }
    }

    /// A ring closed by a point (`apex`) or by an inner ring (an annulus); facing along
    /// the frame's axis if `up`, else against it.
    fn cap(&mut self, ring: &[usize], inner: Cap, up: bool) {
        let n = ring.len();
        for k in 0..n {
            let (r0, r1) = (ring[k], ring[(k + 1) % n]);
            let mut faces = match &inner {
                Cap::Apex(c) => vec![vec![*c, r0, r1]],
                Cap::Ring(i) => {
                    let (i0, i1) = (i[k], i[(k + 1) % n]);
                    vec![vec![i0, r0, r1], vec![i0, r1, i1]]
                }
            };
            if !up {
                faces.iter_mut().for_each(|f| f.reverse());
            }
            self.polygons.extend(faces);
        }
    }
}

/// What closes a ring in [`Polygons::cap`].
enum Cap {
    Apex(usize),
    Ring(Vec<usize>),
}

impl Shape {
    /// The shape's name in the scenario file (`type`).
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Box { .. } => "box",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Drum { .. } => "drum",
            Shape::Plane { .. } => "plane",
            Shape::Hopper { .. } => "hopper",
        }
    }

    /// Where a grain of radius `r` sits on a ring of faces all at once, and how many it
    /// touches there: in a hopper's outlet narrower than the grain or at a cone's apex (a
    /// side's two triangles are two contacts `per_face`), on the rim of a cylinder's
    /// orifice narrower than the grain. Their springs act together on the grain, as stiff
    /// as that many contacts in parallel, which the time step of Eq. 50 (made for one)
    /// may not resolve (`tinydem check` warns; `tests/shapes.rs`).
    pub fn seat(&self, r: f64, per_face: bool) -> Option<(u32, &'static str)> {
        match *self {
            Shape::Hopper {
                outlet_radius: 0.0,
                resolution,
                ..
            } => Some((resolution, "at its apex")),
            Shape::Hopper {
                top_radius,
                outlet_radius,
                resolution,
                ..
            } if outlet_radius < r && outlet_radius < top_radius => {
                let sides = if per_face { 2 } else { 1 };
                Some((sides * resolution, "in its outlet"))
            }
            Shape::Cylinder {
                open: [false, _],
                orifice,
                resolution,
                ..
            } if orifice > 0.0 && orifice < r => Some((resolution, "over its orifice")),
            _ => None,
        }
    }

    /// The shape's faces, all of radius `radius` (R_j), one connected surface; an error
    /// where its sizes or places are beyond double precision (validation makes the mesh
    /// once to find out: [`Shape::mesh`] then holds).
    pub fn try_mesh(&self, radius: f64) -> Result<Mesh, &'static str> {
        let mut p = Polygons::default();
        match *self {
            Shape::Box { min, max, open } => box_faces(&mut p, min, max, open),
            Shape::Cylinder {
                center,
                axis,
                radius: r,
                height,
                open,
                orifice,
                resolution: n,
            } => {
                let f = frame(axis);
                let bottom = p.ring(center, f, r, n);
                let top = p.ring(center + height * axis, f, r, n);
                p.band(&bottom, &top, true);
                if !open[0] {
                    let inner = match orifice > 0.0 {
                        true => Cap::Ring(p.ring(center, f, orifice, n)),
                        false => Cap::Apex(p.vertex(center)),
                    };
                    p.cap(&bottom, inner, false);
                }
                if !open[1] {
                    let c = p.vertex(center + height * axis);
                    p.cap(&top, Cap::Apex(c), true);
                }
            }
            Shape::Drum {
                center,
                axis,
                radius: r,
                length,
                resolution: n,
            } => {
                let (f, half) = (frame(axis), 0.5 * length * axis);
                let bottom = p.ring(center - half, f, r, n);
                let top = p.ring(center + half, f, r, n);
                p.band(&bottom, &top, true);
                let (b, t) = (p.vertex(center - half), p.vertex(center + half));
                p.cap(&bottom, Cap::Apex(b), false);
                p.cap(&top, Cap::Apex(t), true);
            }
            Shape::Plane {
                point,
                normal,
                size,
            } => {
                let ((u, v), h) = (frame(normal), 0.5 * size);
                let corners = [(-h, -h), (h, -h), (h, h), (-h, h)];
                let k = corners.map(|(a, b)| p.vertex(point + a * u + b * v));
                p.polygons.push(k.to_vec());
            }
            Shape::Hopper { .. } => self.hopper_faces(&mut p),
        }
        Mesh::from_polygons(p.vertices, &p.polygons, radius)
    }

    /// The shape's faces, all of radius `radius` (R_j), one connected surface, for a shape
    /// that validation made once ([`Shape::try_mesh`]).
    pub fn mesh(&self, radius: f64) -> Mesh {
        self.try_mesh(radius)
            .expect("a validated shape makes its faces")
    }

    /// A hopper's faces: a band between its two circles, or a cone where one is a point.
    fn hopper_faces(&self, p: &mut Polygons) {
        let Shape::Hopper {
            center,
            axis,
            top_radius,
            outlet_radius,
            height,
            resolution: n,
        } = *self
        else {
            unreachable!("hopper_faces is called for hoppers")
        };
        let (f, top_center) = (frame(axis), center + height * axis);
        let high = p.ring(top_center, f, top_radius, n);
        if outlet_radius > 0.0 {
            let low = p.ring(center, f, outlet_radius, n);
            p.band(&low, &high, false);
        } else {
            // A cone pointing down: its apex is the outlet (it holds everything).
            let apex = p.vertex(center);
            p.cap(&high, Cap::Apex(apex), false);
        }
    }
}

/// The sides of the box `min`-`max` that are not `open`, as rectangles over its 8
/// corners: side `+d` has the corners `o, o + P, o + P + Q, o + Q` with the other two axes
/// `p, q` in cyclic order (so its normal `p x q` is `+d`), side `-d` the reverse order.
fn box_faces(p: &mut Polygons, min: DVec3, max: DVec3, open: [bool; 6]) {
    let corner: Vec<usize> = (0..8)
        .map(|bits: usize| {
            let pick = |d: usize| if bits >> d & 1 == 1 { max[d] } else { min[d] };
            p.vertex(DVec3::new(pick(0), pick(1), pick(2)))
        })
        .collect();
    for (side, _) in BOX_SIDES.iter().enumerate().filter(|&(s, _)| !open[s]) {
        let (d, plus) = (side / 2, side % 2 == 1);
        let (a, b) = (1 << ((d + 1) % 3), 1 << ((d + 2) % 3));
        let o = if plus { 1 << d } else { 0 };
        let mut ring = vec![o, o | a, o | a | b, o | b];
        if !plus {
            ring.reverse();
            ring.rotate_right(1);
        }
        p.polygons
            .push(ring.into_iter().map(|k| corner[k]).collect());
    }
}

#[cfg(test)]
mod tests;
