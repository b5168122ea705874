//! The driver: the run loop and the checks before a run.

pub mod check;
pub mod run;
