//! The contact history of the model: the static friction springs of a contact (Table 3),
//! kept from step to step while the contact lasts (the contact law updates them, the
//! neighbour lists carry them across rebuilds, checkpoints store them).

use crate::model::fields::Value;
use crate::model::lanes::Lanes;

/// Displacements of the three static friction springs of one contact (Table 3):
/// sliding `u_s`, rolling `u_r` and twisting `u_t`. Zero at first touch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Springs<T: Lanes = f64> {
    pub u_s: T::Vec,
    pub u_r: T::Vec,
    pub u_t: T,
}

impl<T: Lanes> Springs<T> {
    /// Zero in the lanes of `mask` (a contact that starts afresh).
    #[inline(always)]
    pub fn forget_where(&mut self, mask: T::Mask) {
        let zero = T::splat_vec(glam::DVec3::ZERO);
        self.u_s = T::pick_vec(mask, || zero, || self.u_s);
        self.u_r = T::pick_vec(mask, || zero, || self.u_r);
        self.u_t = T::pick(mask, || T::splat(0.0), || self.u_t);
    }
}

/// u_s, u_r, u_t: 7 numbers.
impl Value for Springs {
    const SIZE: usize = 56;
    fn put(&self, out: &mut Vec<u8>) {
        self.u_s.put(out);
        self.u_r.put(out);
        self.u_t.put(out);
    }
    fn take(bytes: &mut &[u8]) -> Self {
        let (u_s, u_r) = (glam::DVec3::take(bytes), glam::DVec3::take(bytes));
        Springs {
            u_s,
            u_r,
            u_t: f64::take(bytes),
        }
    }
}
