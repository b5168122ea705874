//! Geometry: closest points on triangles, meshes and their faces, analytic surfaces.

pub mod closest;
pub mod mesh;
pub mod shapes;
pub mod surface;
