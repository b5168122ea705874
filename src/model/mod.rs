//! The model: lanes of particles, exact sums, particles, springs, the contact law (Sec. 2.2 of the paper), materials and their mixing, integration and rigid motion, clumps (mass properties) and rigid-body rotation. Imports nothing of the crate above it.

pub mod bodies;
pub mod clump;
pub mod contact;
pub mod contact_state;
pub mod exact;
pub mod fields;
pub mod heat;
pub mod id;
pub mod integrate;
pub mod lanes;
pub mod ledger;
pub mod materials;
pub mod motion;
pub mod particles;
pub mod registry;
pub mod rigid;
pub mod servo;
pub mod springs;
pub mod value;
