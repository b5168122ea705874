//! The numbers the contact law and the integration are written for: one contact or particle
//! at a time (`f64` with glam's `DVec3` and `DQuat`), or several at once in SIMD lanes
//! (`f64x4`, `f64x8` from `wide`, with [`V3`] and [`Q4`] of them: no vector crate has
//! 3-vectors of 8 double lanes).
//!
//! The law (`contact/`) and SPIRAL (`integrate.rs`) are generic over [`Lanes`], so both
//! read the same and do the same IEEE operations in the same order: a lane gives the bits
//! of the contact or particle alone (property tests in both files). Where the scalar code
//! branches, the lanes take both sides and blend them, unless all lanes agree
//! ([`Lanes::pick`]).

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::{DQuat, DVec3};
use wide::{f64x4, f64x8};

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
    /// Quaternions with components of this kind.
    type Quat: Copy;
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
    /// `f` applied to each lane on its own (for what has no lane version).
    fn each(self, f: impl Fn(f64) -> f64) -> Self;
    /// The quaternion (x, y, z, w) = (`v`, `w`).
    fn quat(v: Self::Vec, w: Self) -> Self::Quat;
    /// The product `a b`, as glam's `DQuat` forms it.
    fn mul_quat(a: Self::Quat, b: Self::Quat) -> Self::Quat;
    /// `q` times `s`, and the squared norm of `q`, as glam's `DQuat` forms them.
    fn scale_quat(q: Self::Quat, s: Self) -> Self::Quat;
    fn norm2_quat(q: Self::Quat) -> Self;
}

impl Lanes for f64 {
    type Vec = DVec3;
    type Quat = DQuat;
    type Mask = bool;

    #[inline(always)]
    fn each(self, f: impl Fn(f64) -> f64) -> f64 {
        f(self)
    }
    #[inline(always)]
    fn quat(v: DVec3, w: f64) -> DQuat {
        DQuat::from_xyzw(v.x, v.y, v.z, w)
    }
    #[inline(always)]
    fn mul_quat(a: DQuat, b: DQuat) -> DQuat {
        a * b
    }
    #[inline(always)]
    fn scale_quat(q: DQuat, s: f64) -> DQuat {
        q * s
    }
    #[inline(always)]
    fn norm2_quat(q: DQuat) -> f64 {
        q.length_squared()
    }

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

/// A 3-vector of lanes: component `x` holds the x of every lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V3<T> {
    pub x: T,
    pub y: T,
    pub z: T,
}

/// A quaternion of lanes (x, y, z, w as glam's `DQuat`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Q4<T> {
    pub x: T,
    pub y: T,
    pub z: T,
    pub w: T,
}

impl<T: Copy + Add<Output = T>> Add for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl<T: Copy + Sub<Output = T>> Sub for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl<T: Copy + Neg<Output = T>> Neg for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl<T: Copy + Mul<Output = T>> Mul<T> for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: T) -> Self {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

/// `Lanes` for a `wide` type of `$n` double lanes. Products and the dot product associate
/// as glam's (`x*x + y*y + z*z`; cross `a.y*b.z - b.y*a.z`, ...), so that lanes round as
/// single contacts do.
macro_rules! lanes {
    ($($t:ident: $n:literal),*) => {$(
        impl Lanes for $t {
            type Vec = V3<$t>;
            type Quat = Q4<$t>;
            type Mask = $t;

            #[inline(always)]
            fn each(self, f: impl Fn(f64) -> f64) -> $t {
                $t::new(self.to_array().map(f))
            }
            #[inline(always)]
            fn quat(v: V3<$t>, w: $t) -> Q4<$t> {
                Q4 { x: v.x, y: v.y, z: v.z, w }
            }
            #[inline(always)]
            fn mul_quat(a: Q4<$t>, b: Q4<$t>) -> Q4<$t> {
                let (x0, y0, z0, w0) = (a.x, a.y, a.z, a.w);
                let (x1, y1, z1, w1) = (b.x, b.y, b.z, b.w);
                Q4 {
                    x: w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
                    y: w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1,
                    z: w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1,
                    w: w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1,
                }
            }
            #[inline(always)]
            fn scale_quat(q: Q4<$t>, s: $t) -> Q4<$t> {
                Q4 { x: q.x * s, y: q.y * s, z: q.z * s, w: q.w * s }
            }
            #[inline(always)]
            fn norm2_quat(q: Q4<$t>) -> $t {
                q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w
            }

            #[inline(always)]
            fn splat(x: f64) -> $t {
                $t::splat(x)
            }
            #[inline(always)]
            fn splat_vec(v: DVec3) -> V3<$t> {
                V3 { x: $t::splat(v.x), y: $t::splat(v.y), z: $t::splat(v.z) }
            }
            #[inline(always)]
            fn sqrt(self) -> $t {
                $t::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> $t {
                $t::abs(self)
            }
            #[inline(always)]
            fn le(self, other: $t) -> $t {
                self.simd_le(other)
            }
            #[inline(always)]
            fn positive(self) -> $t {
                self.simd_gt($t::ZERO)
            }
            #[inline(always)]
            fn is_zero(self) -> $t {
                self.simd_eq($t::ZERO)
            }
            #[inline(always)]
            fn dot(a: V3<$t>, b: V3<$t>) -> $t {
                a.x * b.x + a.y * b.y + a.z * b.z
            }
            #[inline(always)]
            fn cross(a: V3<$t>, b: V3<$t>) -> V3<$t> {
                V3 {
                    x: a.y * b.z - b.y * a.z,
                    y: a.z * b.x - b.z * a.x,
                    z: a.x * b.y - b.x * a.y,
                }
            }
            #[inline(always)]
            fn pick(mask: $t, yes: impl FnOnce() -> $t, no: impl FnOnce() -> $t) -> $t {
                if mask.all() {
                    yes()
                } else if mask.none() {
                    no()
                } else {
                    mask.select(yes(), no())
                }
            }
            #[inline(always)]
            fn pick_vec(
                mask: $t,
                yes: impl FnOnce() -> V3<$t>,
                no: impl FnOnce() -> V3<$t>,
            ) -> V3<$t> {
                if mask.all() {
                    yes()
                } else if mask.none() {
                    no()
                } else {
                    let (a, b) = (yes(), no());
                    V3 { x: mask.select(a.x, b.x), y: mask.select(a.y, b.y), z: mask.select(a.z, b.z) }
                }
            }
        }

        impl Gather<$n> for $t {
            #[inline(always)]
            fn gather(values: [f64; $n]) -> $t {
                $t::new(values)
            }
            #[inline(always)]
            fn scatter(self) -> [f64; $n] {
                self.to_array()
            }
        }
    )*};
}
lanes!(f64x4: 4, f64x8: 8);

/// Moving values between `N` single contacts and the lanes of a group.
pub trait Gather<const N: usize>: Lanes<Vec = V3<Self>, Quat = Q4<Self>> {
    fn gather(values: [f64; N]) -> Self;
    fn scatter(self) -> [f64; N];

    #[inline(always)]
    fn gather_vec(v: [DVec3; N]) -> V3<Self> {
        Self::gather_vec_at(&v, &std::array::from_fn(|l| l))
    }

    /// `values[idx[l]]` in lane `l`.
    #[inline(always)]
    fn gather_at(values: &[f64], idx: &[usize; N]) -> Self {
        let mut a = [0.0; N];
        for l in 0..N {
            a[l] = values[idx[l]];
        }
        Self::gather(a)
    }

    /// `values[idx[l]]` in lane `l`.
    #[inline(always)]
    fn gather_vec_at(values: &[DVec3], idx: &[usize; N]) -> V3<Self> {
        let (mut x, mut y, mut z) = ([0.0; N], [0.0; N], [0.0; N]);
        for l in 0..N {
            let v = values[idx[l]];
            (x[l], y[l], z[l]) = (v.x, v.y, v.z);
        }
        V3 {
            x: Self::gather(x),
            y: Self::gather(y),
            z: Self::gather(z),
        }
    }

    #[inline(always)]
    fn scatter_vec(v: V3<Self>) -> [DVec3; N] {
        let (x, y, z) = (v.x.scatter(), v.y.scatter(), v.z.scatter());
        let mut out = [DVec3::ZERO; N];
        for l in 0..N {
            out[l] = DVec3::new(x[l], y[l], z[l]);
        }
        out
    }

    #[inline(always)]
    fn gather_quat(q: [DQuat; N]) -> Q4<Self> {
        Self::gather_quat_at(&q, &std::array::from_fn(|l| l))
    }

    /// `values[idx[l]]` in lane `l`.
    #[inline(always)]
    fn gather_quat_at(values: &[DQuat], idx: &[usize; N]) -> Q4<Self> {
        let (mut x, mut y, mut z, mut w) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        for l in 0..N {
            let q = values[idx[l]];
            (x[l], y[l], z[l], w[l]) = (q.x, q.y, q.z, q.w);
        }
        Q4 {
            x: Self::gather(x),
            y: Self::gather(y),
            z: Self::gather(z),
            w: Self::gather(w),
        }
    }

    #[inline(always)]
    fn scatter_quat(q: Q4<Self>) -> [DQuat; N] {
        let (x, y, z, w) = (q.x.scatter(), q.y.scatter(), q.z.scatter(), q.w.scatter());
        std::array::from_fn(|k| DQuat::from_xyzw(x[k], y[k], z[k], w[k]))
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
displacements!(f64 => DVec3, f64x4 => V3<f64x4>, f64x8 => V3<f64x8>);

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
        let (la, lb) = (f64x4::gather_vec(a), f64x4::gather_vec(b));
        let dot = <f64x4 as Lanes>::dot(la, lb).scatter();
        let cross = f64x4::scatter_vec(<f64x4 as Lanes>::cross(la, lb));
        for k in 0..4 {
            assert_eq!(dot[k].to_bits(), a[k].dot(b[k]).to_bits());
            assert_eq!(cross[k], a[k].cross(b[k]));
        }
    }

    #[test]
    fn pick_blends_only_where_lanes_disagree() {
        let mask = f64x4::gather([1.0, -1.0, 2.0, 0.0]).positive();
        let picked = <f64x4 as Lanes>::pick(mask, || f64x4::splat(1.0), || f64x4::splat(2.0));
        assert_eq!(picked.to_array(), [1.0, 2.0, 1.0, 2.0]);
        let all = f64x8::gather([1.0; 8]).positive();
        assert_eq!(
            <f64x8 as Lanes>::pick(all, || f64x8::splat(1.0), || unreachable!()).to_array(),
            [1.0; 8]
        );
    }
}
