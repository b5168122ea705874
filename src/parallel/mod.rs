//! A run split over processes: the communicator and the decomposition of space.

pub mod comm;
pub mod decomposition;
