//! Files: the only layer that reads or writes them (inputs, frames, checkpoints, the output directory).

pub mod checkpoint;
pub mod csv;
pub mod files;
pub mod inputs;
pub mod lock;
pub mod output;
pub mod pieces;
pub mod vtk;
