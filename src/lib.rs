//! tinydem: a granular DEM simulator implementing the model of the TinyDEM paper
//! (R. Vetter, Comput. Phys. Commun. 2025): soft frictional spheres with Hertz-Mindlin
//! contact, sliding, rolling and twisting friction, quaternion orientations and static
//! meshes. See `ARCHITECTURE.md` for a map of the code.
//!
//! The folders are layers, listed here from the bottom up; a module imports only from
//! its own layer and those below it (`bench/modgraph.py` checks it).

// Layer 1: lanes, exact sums, particles, springs, the contact law, integration, motion.
pub mod model;

// Layer 2: closest points, meshes, analytic surfaces.
pub mod geometry;

// Layer 3: the cell grid, contact lists and their history.
pub mod neighbours;

// Layer 4: the communicator and the decomposition of space.
pub mod parallel;

// Layer 5: the one parser of scenario files.
pub mod scenario;

// Layer 6: the simulation and one file per stage of the step.
pub mod engine;

// Layer 7: every file read or written.
pub mod io;

// Layer 8: the run loop and the checks before a run.
pub mod driver;

// Layer 9: render, plot, text, analyze, bench.
pub mod tools;
