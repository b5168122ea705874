//! The numbers the contact law is written for: one contact at a time (`f64` with glam's
//! `DVec3`), or four at once in SIMD lanes (`f64x4` with ultraviolet's `DVec3x4`).
//!
//! The law (`contact.rs`) is generic over [`Lanes`], so both read the same and do the same
//! IEEE operations in the same order: a contact evaluated in a lane gives the bits it gives
//! alone (tested below). Where the scalar law branches, the lanes take both sides and
//! blend them, unless all four lanes agree ([`Lanes::pick`]).

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::DVec3;
use ultraviolet::DVec3x4;
use wide::{CmpEq, CmpGt, CmpLe, f64x4};

/// A number of the contact law: one value, or one per lane.
pub trait Lanes:
    Copy
    + Debug
    + Default
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Vectors with components of this kind.
    type Vec: Copy
        + Debug
        + Default
        + PartialEq
        + Add<Output = Self::Vec>
        + Sub<Output = Self::Vec>
        + Neg<Output = Self::Vec>
        + Mul<Self, Output = Self::Vec>;
    /// The result of a comparison: a `bool`, or one per lane.
    type Mask: Copy;

    fn splat(x: f64) -> Self;
    fn splat_vec(v: DVec3) -> Self::Vec;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    fn le(self, other: Self) -> Self::Mask;
    fn positive(self) -> Self::Mask;
    fn is_zero(self) -> Self::Mask;
    fn dot(a: Self::Vec, b: Self::Vec) -> Self;
    fn cross(a: Self::Vec, b: Self::Vec) -> Self::Vec;
    /// `yes()` where `mask` holds, `no()` elsewhere; a single value evaluates only the side
    /// it takes, lanes both sides unless they all agree.
    fn pick(mask: Self::Mask, yes: impl FnOnce() -> Self, no: impl FnOnce() -> Self) -> Self;
    fn pick_vec(
        mask: Self::Mask,
        yes: impl FnOnce() -> Self::Vec,
        no: impl FnOnce() -> Self::Vec,
    ) -> Self::Vec;
}

impl Lanes for f64 {
    type Vec = DVec3;
    type Mask = bool;

    #[inline(always)]
    fn splat(x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn splat_vec(v: DVec3) -> DVec3 {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn le(self, other: f64) -> bool {
        self <= other
    }
    #[inline(always)]
    fn positive(self) -> bool {
        self > 0.0
    }
    #[inline(always)]
    fn is_zero(self) -> bool {
        self == 0.0
    }
    #[inline(always)]
    fn dot(a: DVec3, b: DVec3) -> f64 {
        a.dot(b)
    }
    #[inline(always)]
    fn cross(a: DVec3, b: DVec3) -> DVec3 {
        a.cross(b)
    }
    #[inline(always)]
    fn pick(mask: bool, yes: impl FnOnce() -> f64, no: impl FnOnce() -> f64) -> f64 {
        if mask { yes() } else { no() }
    }
    #[inline(always)]
    fn pick_vec(mask: bool, yes: impl FnOnce() -> DVec3, no: impl FnOnce() -> DVec3) -> DVec3 {
        if mask { yes() } else { no() }
    }
}

impl Lanes for f64x4 {
    type Vec = DVec3x4;
    type Mask = f64x4;

    #[inline(always)]
    fn splat(x: f64) -> f64x4 {
        f64x4::splat(x)
    }
    #[inline(always)]
    fn splat_vec(v: DVec3) -> DVec3x4 {
        DVec3x4::new(f64x4::splat(v.x), f64x4::splat(v.y), f64x4::splat(v.z))
    }
    #[inline(always)]
    fn sqrt(self) -> f64x4 {
        f64x4::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f64x4 {
        f64x4::abs(self)
    }
    #[inline(always)]
    fn le(self, other: f64x4) -> f64x4 {
        self.cmp_le(other)
    }
    #[inline(always)]
    fn positive(self) -> f64x4 {
        self.cmp_gt(f64x4::ZERO)
    }
    #[inline(always)]
    fn is_zero(self) -> f64x4 {
        self.cmp_eq(f64x4::ZERO)
    }
    #[inline(always)]
    fn dot(a: DVec3x4, b: DVec3x4) -> f64x4 {
        a.dot(b)
    }
    #[inline(always)]
    fn cross(a: DVec3x4, b: DVec3x4) -> DVec3x4 {
        a.cross(b)
    }
    #[inline(always)]
    fn pick(mask: f64x4, yes: impl FnOnce() -> f64x4, no: impl FnOnce() -> f64x4) -> f64x4 {
        if mask.all() {
            yes()
        } else if mask.none() {
            no()
        } else {
            mask.blend(yes(), no())
        }
    }
    #[inline(always)]
    fn pick_vec(
        mask: f64x4,
        yes: impl FnOnce() -> DVec3x4,
        no: impl FnOnce() -> DVec3x4,
    ) -> DVec3x4 {
        if mask.all() {
            yes()
        } else if mask.none() {
            no()
        } else {
            DVec3x4::blend(mask, yes(), no())
        }
    }
}

/// A spring displacement of a contact's lanes: a vector (sliding, rolling) or a scalar
/// (twisting).
pub trait Displacement<T: Lanes>:
    Copy + std::ops::Add<Output = Self> + std::ops::Neg<Output = Self> + std::ops::Mul<T, Output = Self>
{
    fn norm_squared(self) -> T;
    fn pick(mask: T::Mask, yes: impl FnOnce() -> Self, no: impl FnOnce() -> Self) -> Self;
}

macro_rules! displacements {
    ($($t:ty => $v:ty),*) => {$(
        impl Displacement<$t> for $v {
            #[inline(always)]
            fn norm_squared(self) -> $t {
                <$t as Lanes>::dot(self, self)
            }
            #[inline(always)]
            fn pick(mask: <$t as Lanes>::Mask, yes: impl FnOnce() -> Self, no: impl FnOnce() -> Self) -> Self {
                <$t as Lanes>::pick_vec(mask, yes, no)
            }
        }
        impl Displacement<$t> for $t {
            #[inline(always)]
            fn norm_squared(self) -> $t {
                self * self
            }
            #[inline(always)]
            fn pick(mask: <$t as Lanes>::Mask, yes: impl FnOnce() -> Self, no: impl FnOnce() -> Self) -> Self {
                <$t as Lanes>::pick(mask, yes, no)
            }
        }
    )*};
}
displacements!(f64 => DVec3, f64x4 => DVec3x4);

/// The four lanes of `f64x4` values from per-lane scalars.
#[inline(always)]
pub fn gather(values: [f64; 4]) -> f64x4 {
    f64x4::from(values)
}

/// A lane vector from four vectors.
#[inline(always)]
pub fn gather_vec(v: [DVec3; 4]) -> DVec3x4 {
    DVec3x4::new(
        gather([v[0].x, v[1].x, v[2].x, v[3].x]),
        gather([v[0].y, v[1].y, v[2].y, v[3].y]),
        gather([v[0].z, v[1].z, v[2].z, v[3].z]),
    )
}

/// The four vectors of a lane vector.
#[inline(always)]
pub fn scatter_vec(v: DVec3x4) -> [DVec3; 4] {
    let (x, y, z) = (v.x.to_array(), v.y.to_array(), v.z.to_array());
    std::array::from_fn(|k| DVec3::new(x[k], y[k], z[k]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vector_products_match_glam_bit_for_bit() {
        let a = [
            DVec3::new(0.1, -2.5, 3.3),
            DVec3::new(1e-3, 7.0, -0.2),
            DVec3::new(-4.4, 0.3, 1.1),
            DVec3::new(2.2, 2.2, -9.9),
        ];
        let b = [a[3] * 0.7, a[2] + DVec3::ONE, -a[0], a[1] * 1e5];
        let dot = <f64x4 as Lanes>::dot(gather_vec(a), gather_vec(b)).to_array();
        let cross = scatter_vec(<f64x4 as Lanes>::cross(gather_vec(a), gather_vec(b)));
        for k in 0..4 {
            assert_eq!(dot[k].to_bits(), a[k].dot(b[k]).to_bits());
            assert_eq!(cross[k], a[k].cross(b[k]));
        }
    }

    #[test]
    fn pick_blends_only_where_lanes_disagree() {
        let mask = gather([1.0, -1.0, 2.0, 0.0]).positive();
        let picked = <f64x4 as Lanes>::pick(mask, || f64x4::splat(1.0), || f64x4::splat(2.0));
        assert_eq!(picked.to_array(), [1.0, 2.0, 1.0, 2.0]);
        let all = gather([1.0; 4]).positive();
        assert_eq!(
            <f64x4 as Lanes>::pick(all, || f64x4::splat(1.0), || unreachable!()).to_array(),
            [1.0; 4]
        );
    }
}
