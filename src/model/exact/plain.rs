//! Plain float sums in place of the exact ones (`--features plain-sums`), only for
//! `bench/exact.sh` to measure what the exact sums cost. A load is then the float sum of its
//! terms in the order they come, which depends on the thread count, the storage order and the
//! split over processes: the bits are no longer the same for any number of threads or
//! processes, and the tests of that do not hold. Never for a run whose results matter.

use super::Scales8;
use wide::f64x8;

/// Six components summed as floats (lanes 0-5; 6 and 7 unused), as a code without exact sums
/// keeps a force and a torque.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sum6 {
    sum: f64x8,
}

impl Sum6 {
    /// Adds components 0-5 of `x`; always true (the advance stage finds loads that are not
    /// finite).
    #[inline(always)]
    pub fn add(&mut self, x: f64x8, _scales: &Scales8) -> bool {
        self.sum += x;
        true
    }

    pub fn merge(&mut self, other: &Sum6) {
        self.sum += other.sum;
    }

    pub fn carry(&mut self) {}

    /// The components' bits (to send them to another process).
    pub fn words(&self) -> [i64; 12] {
        let v = self.sum.to_array();
        std::array::from_fn(|c| if c < 6 { v[c].to_bits() as i64 } else { 0 })
    }

    pub fn from_words(words: [i64; 12]) -> Sum6 {
        let lanes: [f64; 8] = std::array::from_fn(|c| {
            if c < 6 {
                f64::from_bits(words[c] as u64)
            } else {
                0.0
            }
        });
        Sum6 {
            sum: f64x8::from(lanes),
        }
    }

    #[inline]
    pub fn value(&self, _scales: &Scales8) -> [f64; 6] {
        let v = self.sum.to_array();
        std::array::from_fn(|c| v[c])
    }
}
