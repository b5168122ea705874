//! Tools on a run's output: render, plot, text, analyze, bench.

pub mod analyze;
pub mod bench;
pub mod fields;
pub mod frames;
pub mod plot;
pub mod render;
pub mod text;
pub mod walls;
