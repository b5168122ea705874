//! The integration tests, in one binary (one link, and all their tests run side by side):
//! each file of `tests/` is a module here. `fuzz`, `mpi` (its own feature) and `memory`
//! (which reads the process's peak memory) are binaries of their own.

mod common;

mod bad_inputs;
mod beyond_touch;
mod book;
mod cli;
mod clumps;
mod cohesion;
mod contact_models;
mod decomposition;
mod domain;
mod energy_ledger;
mod examples;
mod fields;
mod fixed;
mod friction_springs;
mod heat;
mod materials;
mod mesh_contacts;
mod moving;
mod periodic;
mod physics;
mod reference;
mod robustness;
mod scenarios;
mod servo;
mod shapes;
mod spawn;
mod stages;
mod stl;
mod until;
mod vtk;
