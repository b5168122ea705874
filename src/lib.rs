//! tinydem: a granular DEM simulator implementing the model of the TinyDEM paper
//! (R. Vetter, Comput. Phys. Commun. 2025): soft frictional spheres with Hertz-Mindlin
//! contact, sliding, rolling and twisting friction, quaternion orientations and static
//! meshes. See `ARCHITECTURE.md` for a map of the code.

pub mod analyze;
pub mod bench;
pub mod check;
pub mod checkpoint;
pub mod comm;
pub mod contact;
pub mod csv;
pub mod domain;
pub mod exact;
pub mod files;
pub mod geometry;
pub mod integrate;
pub mod lanes;
pub mod lock;
pub mod mesh;
pub mod motion;
pub mod neighbours;
pub mod output;
pub mod particles;
pub mod plot;
pub mod records;
pub mod render;
pub mod run;
pub mod scenario;
pub mod simulation;
pub mod spawn;
pub mod springs;
pub mod surface;
pub mod text;
pub mod vtk;
