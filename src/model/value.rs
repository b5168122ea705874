//! The bytes of one value of a per-particle field (or of a contact's state), little endian,
//! for the messages of a split run and for checkpoints: each type of a field says once how
//! many bytes it takes and how it reads and writes them.

use glam::{DQuat, DVec3};

use crate::model::bodies::BodyId;

/// A value of fixed size in bytes.
pub trait Value: Copy + Default {
    /// Its bytes.
    const SIZE: usize;
    /// Appends its bytes to `out`.
    fn put(&self, out: &mut Vec<u8>);
    /// The value of the first [`Self::SIZE`] bytes of `bytes`, which it moves past. Short
    /// bytes are a bug of the caller (which checks a file's length before), so it panics.
    fn take(bytes: &mut &[u8]) -> Self;
}

/// The first `N` bytes of `bytes`, moved past.
fn first<const N: usize>(bytes: &mut &[u8]) -> [u8; N] {
    let (head, rest) = bytes.split_at(N);
    *bytes = rest;
    head.try_into().expect("N bytes")
}

macro_rules! number {
    ($($t:ty),*) => {$(
        impl Value for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            fn put(&self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn take(bytes: &mut &[u8]) -> Self {
                <$t>::from_le_bytes(first(bytes))
            }
        }
    )*};
}

number!(u8, u16, u32, u64, i128, f64);

/// One byte, 1 or 0 (read: anything but 0 is true).
impl Value for bool {
    const SIZE: usize = 1;
    fn put(&self, out: &mut Vec<u8>) {
        out.push(*self as u8);
    }
    fn take(bytes: &mut &[u8]) -> Self {
        u8::take(bytes) != 0
    }
}

/// x, y, z.
impl Value for DVec3 {
    const SIZE: usize = 24;
    fn put(&self, out: &mut Vec<u8>) {
        self.to_array().iter().for_each(|c| c.put(out));
    }
    fn take(bytes: &mut &[u8]) -> Self {
        DVec3::new(f64::take(bytes), f64::take(bytes), f64::take(bytes))
    }
}

/// q0 (the real part), q1, q2, q3: the order of the frames' columns.
impl Value for DQuat {
    const SIZE: usize = 32;
    fn put(&self, out: &mut Vec<u8>) {
        [self.w, self.x, self.y, self.z]
            .iter()
            .for_each(|c| c.put(out));
    }
    fn take(bytes: &mut &[u8]) -> Self {
        let w = f64::take(bytes);
        DQuat::from_xyzw(f64::take(bytes), f64::take(bytes), f64::take(bytes), w)
    }
}

/// The id of the body's first sphere + 1, or 0 for none.
impl Value for Option<BodyId> {
    const SIZE: usize = 8;
    fn put(&self, out: &mut Vec<u8>) {
        self.map_or(0, |b| b.first() + 1).put(out);
    }
    fn take(bytes: &mut &[u8]) -> Self {
        u64::take(bytes).checked_sub(1).map(BodyId::new)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip<T: Value + PartialEq + std::fmt::Debug>(v: T) {
        let mut out = Vec::new();
        v.put(&mut out);
        assert_eq!(out.len(), T::SIZE);
        let mut bytes = &out[..];
        assert_eq!(T::take(&mut bytes), v);
        assert!(bytes.is_empty());
    }

    #[test]
    fn values_read_back_as_written() {
        round_trip(7u8);
        round_trip(65_000u16);
        round_trip(u32::MAX);
        round_trip(u64::MAX - 3);
        round_trip(-1e-300f64);
        round_trip(-(1i128 << 100) + 7);
        round_trip(true);
        round_trip(DVec3::new(1.0, -2.0, 3.5));
        round_trip(DQuat::from_rotation_y(0.3));
        round_trip(Some(BodyId::new(41)));
        round_trip(None::<BodyId>);
    }

    #[test]
    fn a_quaternion_is_written_real_part_first() {
        let mut out = Vec::new();
        DQuat::from_xyzw(0.0, 0.0, 0.0, 1.0).put(&mut out);
        assert_eq!(f64::from_le_bytes(out[..8].try_into().unwrap()), 1.0);
    }
}
