//! Sums whose result does not depend on the order of their terms.
//!
//! Floating-point addition is not associative: a particle's force summed over its contacts in
//! another order differs in the last bits, and a granular flow amplifies such differences
//! until the runs part. The order of the terms is the storage order, the slabs of the pair
//! stage, the times of the neighbour-list rebuilds, and (split over processes) which process
//! holds which particle. Rather than fix an order, the loads are summed exactly: each term
//! is cut to a fixed point (a multiple of the resolution 2^-s of its [`Scale`]) and kept as
//! two 64-bit integers, which add exactly and in any order. The sum is turned back into a
//! float once, when the load is used.
//!
//! A scale covers magnitudes up to `2^104` resolutions per term (each of its integers then
//! stays below 2^52, so they hold the sum of 2048 terms of the largest size); the scale is
//! set from the largest force (or torque) the scenario can produce, with room to spare (see
//! `Simulation`), so the resolution lies some 90 binary orders below it: far below the
//! rounding of a float sum of the small forces.

// With `plain-sums` the exact sums stand unused beside the float ones.
#![cfg_attr(feature = "plain-sums", allow(dead_code, unused_imports))]

use wide::{f64x8, i64x4, i64x8};

/// Terms up to this many resolutions (2^104).
const RANGE: f64 = 20282409603651670423947251286016.0;
/// Where a term is split: `hi` counts units of 2^52 resolutions, `lo` the rest.
const SPLIT: f64 = 4503599627370496.0;
const INV_SPLIT: f64 = 1.0 / SPLIT;

/// The resolution of the sums of one quantity: terms are multiples of `2^-s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// 2^s: a term in resolutions is `x * up`.
    up: f64,
    /// 2^-s.
    down: f64,
}

impl Scale {
    /// The scale whose range (2^104 resolutions) is the smallest power of two at least
    /// `largest`.
    pub fn for_largest(largest: f64) -> Scale {
        assert!(
            largest.is_finite() && largest > 0.0,
            "largest term {largest}"
        );
        let s = 104 - largest.log2().ceil() as i32;
        Scale {
            up: 2f64.powi(s),
            down: 2f64.powi(-s),
        }
    }

    /// The largest term this scale holds.
    pub fn largest(self) -> f64 {
        RANGE * self.down
    }
}

/// The scales of the up to 8 components of a [`Sum6`] (unused components: any).
#[derive(Clone, Copy, Debug)]
pub struct Scales8 {
    up: f64x8,
    down: f64x8,
}

impl Scales8 {
    pub fn new(scales: [Scale; 8]) -> Scales8 {
        Scales8 {
            up: f64x8::from(scales.map(|s| s.up)),
            down: f64x8::from(scales.map(|s| s.down)),
        }
    }
}

// Float sums in their place, to measure what exactness costs (`bench/exact.sh`).
#[cfg(feature = "plain-sums")]
mod plain;
#[cfg(feature = "plain-sums")]
pub use plain::Sum6;

/// An exact sum of 6 components (a force and a torque in lanes 0-2 and 3-5 of the terms):
/// each term `x` becomes `a = x 2^s` cut towards zero to whole resolutions, kept as `hi`
/// units of 2^52 resolutions (words 0-5) and `lo` resolutions (words 6-11), two integers
/// that add exactly in any order.
#[cfg(not(feature = "plain-sums"))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sum6 {
    words: [i64; 12],
}

#[cfg(not(feature = "plain-sums"))]
impl Sum6 {
    /// Adds components 0-5 of `x`, each in its scale; false if some component was beyond
    /// its range or not finite (the sum is then meaningless).
    #[inline(always)]
    pub fn add(&mut self, x: f64x8, scales: &Scales8) -> bool {
        let (hi, lo, beyond) = split(x, scales.up);
        let (hi, lo) = (hi.to_array(), lo.to_array());
        // Words 0-7 (hi 0-5, lo 0-1) and 8-11 (lo 2-5) as two vector adds (wrapping).
        let first = i64x8::from([hi[0], hi[1], hi[2], hi[3], hi[4], hi[5], lo[0], lo[1]]);
        let (head, tail) = self.words.split_at_mut(8);
        let head: &mut [i64; 8] = head.try_into().expect("8 words");
        let tail: &mut [i64; 4] = tail.try_into().expect("4 words");
        *head = (i64x8::from(*head) + first).to_array();
        *tail = (i64x4::from(*tail) + i64x4::from([lo[2], lo[3], lo[4], lo[5]])).to_array();
        !beyond
    }

    /// Adds another sum (exactly) and carries the low words into the high ones, so that
    /// any number of sums can be merged one after another (each term adds less than 2^52
    /// to a low word: a sum of up to 2048 terms may be merged).
    pub fn merge(&mut self, other: &Sum6) {
        for (w, o) in self.words.iter_mut().zip(other.words) {
            *w = w.wrapping_add(o);
        }
        self.carry();
    }

    /// The same value with each low word in [0, 2^52): one representation per value, so
    /// that merged sums turn into the same float whatever their grouping.
    pub fn carry(&mut self) {
        for c in 0..6 {
            let lo = self.words[6 + c];
            let up = lo >> 52;
            self.words[c] = self.words[c].wrapping_add(up);
            self.words[6 + c] = lo - (up << 52);
        }
    }

    /// The integers of the sum (to send them to another process).
    pub fn words(&self) -> [i64; 12] {
        self.words
    }

    pub fn from_words(words: [i64; 12]) -> Sum6 {
        Sum6 { words }
    }

    /// The value of each component.
    #[inline]
    pub fn value(&self, scales: &Scales8) -> [f64; 6] {
        let down = scales.down.to_array();
        let w = &self.words;
        std::array::from_fn(|c| (w[c] as f64 * SPLIT + w[6 + c] as f64) * down[c])
    }
}

/// `x up` as (units of 2^52 resolutions, resolutions), cut towards zero, and whether some
/// lane was beyond the range or not finite. Each lane on its own: the same bits for a term
/// in any lane.
#[inline(always)]
fn split(x: f64x8, up: f64x8) -> (i64x8, i64x8, bool) {
    let a = x * up; // exact: powers of two
    let beyond = !(a.abs().simd_lt(f64x8::splat(RANGE))).all();
    let hi = (a * f64x8::splat(INV_SPLIT)).trunc();
    // Exact: hi 2^52 is a multiple of the last bit of `a`, and |a - hi 2^52| < 2^52.
    let lo = a - hi * f64x8::splat(SPLIT);
    (whole(hi), whole(lo), beyond)
}

/// The lanes of `x`, whole numbers below 2^52 in magnitude when in range, as integers. With
/// AVX-512 the plain conversion (no saturation of NaN or huge lanes, which stop the run as
/// beyond the range anyway): the same integers for every lane in range.
#[inline(always)]
fn whole(x: f64x8) -> i64x8 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512dq"))]
    {
        use std::arch::x86_64::{__m512d, __m512i, _mm512_cvttpd_epi64};
        // SAFETY: the target has AVX-512DQ (checked at compile time); f64x8 and i64x8 are
        // 64-byte vectors with the layout of __m512d and __m512i.
        unsafe {
            let v: __m512d = std::mem::transmute::<f64x8, __m512d>(x);
            std::mem::transmute::<__m512i, i64x8>(_mm512_cvttpd_epi64(v))
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512dq")))]
    {
        whole_by_bits(x)
    }
}

/// [`whole`] where there is no vector conversion to 64-bit integers (AVX2, SSE, NEON; `wide`
/// would convert lane by lane, which made the exact sums 30 % of an AVX2 build's step): for a
/// whole `t` below 2^52 in magnitude, `|t| + 2^52` is exact and its bits are those of 2^52
/// plus `|t|`; the sign is put back in two's complement. The same integers as the conversion
/// for every lane below 2^52 in magnitude (cut towards zero first); lanes beyond it are
/// garbage, as they are beyond the range of the sum anyway.
#[cfg(any(test, not(all(target_arch = "x86_64", target_feature = "avx512dq"))))]
#[inline(always)]
fn whole_by_bits(x: f64x8) -> i64x8 {
    use wide::bytemuck::cast;
    let t = x.trunc();
    let biased: i64x8 = cast(t.abs() + f64x8::splat(SPLIT));
    let magnitude = biased - i64x8::splat(SPLIT.to_bits() as i64);
    let negative: i64x8 = cast(t.simd_lt(f64x8::ZERO)); // all ones where t < 0
    (magnitude ^ negative) - negative
}

/// A force and a torque in the lanes of one vector (components 0-2 and 3-5).
#[inline(always)]
pub fn pack(f: glam::DVec3, tau: glam::DVec3) -> f64x8 {
    f64x8::from([f.x, f.y, f.z, tau.x, tau.y, tau.z, 0.0, 0.0])
}

#[cfg(all(test, not(feature = "plain-sums")))]
mod tests {
    use super::*;
    use glam::DVec3;
    use proptest::prelude::*;

    fn scales(largest: f64) -> Scales8 {
        Scales8::new([Scale::for_largest(largest); 8])
    }

    #[test]
    fn a_scale_holds_its_largest_term_and_not_twice_it() {
        let s = Scale::for_largest(3.0);
        assert!(s.largest() >= 3.0 && s.largest() < 6.0 + 1e-9);
        let all = scales(3.0);
        let mut sum = Sum6::default();
        assert!(sum.add(f64x8::splat(3.0), &all) && sum.add(f64x8::splat(-3.0), &all));
        assert_eq!(sum, Sum6::default());
        for bad in [2.0 * s.largest(), f64::NAN, f64::INFINITY] {
            assert!(!Sum6::default().add(pack(DVec3::new(0.0, bad, 0.0), DVec3::ZERO), &all));
        }
    }

    #[test]
    fn merged_sums_carry_to_one_representation() {
        let s = scales(1e3);
        let terms: Vec<f64x8> = (0..3000)
            .map(|k| {
                pack(
                    DVec3::splat(0.999 - (k % 7) as f64),
                    DVec3::splat(-0.5 * k as f64 / 3000.0),
                )
            })
            .collect();
        // The same terms in pieces of different sizes, merged.
        let merged = |piece: usize| {
            let mut total = Sum6::default();
            for chunk in terms.chunks(piece) {
                let mut part = Sum6::default();
                chunk.iter().for_each(|t| assert!(part.add(*t, &s)));
                total.merge(&part);
            }
            total
        };
        let (a, b) = (merged(100), merged(1000));
        assert_eq!(a, b);
        let float: f64 = (0..3000).map(|k| 0.999 - (k % 7) as f64).sum();
        assert!((a.value(&s)[0] - float).abs() < 1e-9 * float.abs());
    }

    #[test]
    fn the_conversion_by_bits_cuts_towards_zero_as_a_plain_conversion_below_2_to_the_52() {
        let big = SPLIT - 1.0;
        let mut values = vec![0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.7, -2.7, big, -big];
        values.extend([
            big - 0.5,
            -(big - 0.5),
            2f64.powi(51) + 0.5,
            -(2f64.powi(51) + 0.5),
        ]);
        let mut r = 0x2545f4914f6cdd1du64;
        for _ in 0..4000 {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            let scale = 2f64.powi((r % 53) as i32);
            let unit = (r >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            values.push((unit * scale).clamp(-big, big));
        }
        for chunk in values.chunks(8) {
            let mut lanes = [0.0; 8];
            lanes[..chunk.len()].copy_from_slice(chunk);
            let got = whole_by_bits(f64x8::from(lanes)).to_array();
            for (x, g) in lanes.iter().zip(got) {
                assert_eq!(g, *x as i64, "{x}");
            }
        }
    }

    proptest! {
        /// A sum of many terms is the same integers in any order, each term is exact to the
        /// resolution, and the value is close to the float sum.
        #[test]
        fn a_sum_does_not_depend_on_the_order_of_its_terms(
            terms in prop::collection::vec((-1e2f64..1e2, -30i32..3), 1..40),
            seed in any::<u64>(),
        ) {
            let s = scales(1e3);
            let down = Scale::for_largest(1e3).largest() / RANGE;
            let v: Vec<f64x8> = terms
                .iter()
                .map(|&(x, e)| {
                    let x = x * 2f64.powi(e);
                    pack(DVec3::new(x, -x * 0.3, x * 1e-7), DVec3::new(-x, 1.0, x * x * 1e-3))
                })
                .collect();
            let mut forward = Sum6::default();
            for t in &v {
                prop_assert!(forward.add(*t, &s));
            }
            let mut order: Vec<usize> = (0..v.len()).collect();
            let mut r = seed;
            for k in (1..order.len()).rev() {
                r = r.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                order.swap(k, (r >> 33) as usize % (k + 1));
            }
            let mut shuffled = Sum6::default();
            for &k in &order {
                shuffled.add(v[k], &s);
            }
            prop_assert_eq!(forward, shuffled);
            let float = v.iter().fold(f64x8::ZERO, |a, b| a + *b).to_array();
            let exact = forward.value(&s);
            for c in 0..6 {
                prop_assert!((exact[c] - float[c]).abs() <= 1e-12 * float[c].abs().max(1.0) + 40.0 * down);
            }
        }
    }
}
