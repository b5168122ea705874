//! The driver: the run loop and the checks before a run.

pub mod check;
mod materials;
mod outputs;
pub mod run;
mod status;
