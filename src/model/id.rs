//! Particle ids: a particle's identity, given at creation (0, 1, 2, ... in creation order)
//! and never reused.

/// A particle's id: 64 bits, so that a long run may create more than 4.29e9 particles
/// (files and checkpoints carry them whole).
pub type Id = u64;

/// The ids a file may give its particles are below this (2^62): far beyond any run, with
/// room above for the ids the run gives new ones.
pub const MAX_ID: Id = 1 << 62;
