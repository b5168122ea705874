//! Tools on a run's output: render, plot, text, analyze, bench; and verify, the analytic cases.

pub mod analyze;
pub mod bench;
pub mod fields;
pub mod frames;
pub mod ledger;
pub mod plot;
pub mod render;
pub mod text;
pub mod verify;
pub mod walls;
