//! The contact history of the model: the static friction springs of a contact (Table 3),
//! kept from step to step while the contact lasts (the contact law updates them, the
//! neighbour lists carry them across rebuilds, checkpoints store them).

use crate::model::lanes::Lanes;

/// Displacements of the three static friction springs of one contact (Table 3):
/// sliding `u_s`, rolling `u_r` and twisting `u_t`. Zero at first touch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Springs<T: Lanes = f64> {
    pub u_s: T::Vec,
    pub u_r: T::Vec,
    pub u_t: T,
}
