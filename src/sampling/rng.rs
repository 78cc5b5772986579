//! `rand`'s generator interface over the sample stream, so that `rand`'s distributions (ranges,
//! booleans, shuffles, `StandardUniform`) can draw from it and stay order-independent.
//!
//! ```text
//! SampleRng { key, dim }: next_u32 = hash(key, dim); dim += 1
//! ```
//!
//! A `SampleRng` is a cursor over one `SampleKey`'s dimensions, not a state machine: two
//! cursors at the same (key, dim) give the same numbers whatever else ran before, on any
//! thread. Its `f32`s from `StandardUniform` (the top 24 bits of a `u32`) are exactly
//! `uniform(key, dim)`.

use super::{SampleKey, hash};
use rand::TryRng;
use rand::rand_core::utils;
use std::convert::Infallible;

/// The random numbers of one `SampleKey` from a given dimension on, as a `rand` generator.
/// Not `Copy`, as `rand` advises: a copy would silently repeat the same numbers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SampleRng {
    key: SampleKey,
    dim: u32,
}

impl SampleRng {
    /// The stream of `key` starting at dimension `dim`.
    pub fn new(key: SampleKey, dim: u32) -> Self {
        SampleRng { key, dim }
    }

    /// The dimension the next `u32` comes from (a `u64` takes two, the low half first).
    pub fn dim(&self) -> u32 {
        self.dim
    }
}

impl TryRng for SampleRng {
    type Error = Infallible;

    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        let bits = hash(&self.key, self.dim);
        self.dim = self.dim.wrapping_add(1);
        Ok(bits)
    }

    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        utils::next_u64_via_u32(self)
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        utils::fill_bytes_via_next_word(dst, || self.try_next_u32())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::uniform;
    use rand::{Rng, RngExt};

    const KEY: SampleKey = SampleKey {
        pixel: 1234,
        sample: 3,
        bounce: 1,
        light: 2,
        seed: 7,
    };

    #[test]
    fn draws_the_sample_stream_in_dimension_order() {
        let mut rng = SampleRng::new(KEY, 5);
        for dim in 5..69 {
            assert_eq!(rng.next_u32(), hash(&KEY, dim));
        }
        assert_eq!(rng.dim(), 69);
        // StandardUniform's f32 keeps the top 24 bits, as `uniform` does: the same floats.
        let mut rng = SampleRng::new(KEY, 0);
        for dim in 0..64 {
            let x: f32 = rng.random();
            assert_eq!(x.to_bits(), uniform(&KEY, dim).to_bits(), "dim {dim}");
        }
    }

    #[test]
    fn words_and_bytes_come_from_the_same_dimensions() {
        let mut rng = SampleRng::new(KEY, 10);
        let low = u64::from(hash(&KEY, 10));
        let high = u64::from(hash(&KEY, 11));
        assert_eq!(rng.next_u64(), low | high << 32);
        let mut bytes = [0u8; 6];
        rng.fill_bytes(&mut bytes);
        let words = [hash(&KEY, 12).to_le_bytes(), hash(&KEY, 13).to_le_bytes()];
        assert_eq!(bytes[..4], words[0]);
        assert_eq!(bytes[4..], words[1][..2]);
        assert_eq!(rng.dim(), 14);
    }

    #[test]
    fn pixels_drawn_in_any_order_get_the_same_numbers() {
        // Two pixels' streams, drawn one after the other in both orders (as two tile orders or
        // thread counts would): each pixel gets the same numbers either way.
        let other = SampleKey { pixel: 99, ..KEY };
        let draw = |key: SampleKey| -> Vec<u32> {
            let mut rng = SampleRng::new(key, 2);
            (0..16).map(|_| rng.random_range(0..1000)).collect()
        };
        let (a1, b1) = (draw(KEY), draw(other));
        let (b2, a2) = (draw(other), draw(KEY));
        assert_eq!((a1.clone(), b1.clone()), (a2, b2));
        assert_ne!(a1, b1, "two pixels drew the same numbers");
    }

    #[test]
    fn rand_distributions_draw_in_range_and_cover_it() {
        let mut rng = SampleRng::new(KEY, 0);
        let mut seen = [0u32; 6];
        for _ in 0..6000 {
            let face = rng.random_range(1..=6);
            seen[face - 1] += 1;
        }
        // 1000 expected per face; 6 sigma is about 0.2 of that.
        assert!(seen.iter().all(|&n| (800..1200).contains(&n)), "{seen:?}");
    }
}
