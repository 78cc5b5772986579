//! The blue-noise sampler of Heitz, Belcour, Ostromoukhov, Coeurjolly and Iehl (2019), "A
//! Low-Discrepancy Sampler that Distributes Monte Carlo Errors as a Blue Noise in Screen
//! Space", from the paper's published tables (the `blue-noise-sampler` crate).
//!
//! ```text
//! tables for 2^k samples per pixel (k = 0..8): a 256-point, 256-dimension Sobol sequence of
//! 8-bit values, and per pixel of a 128 × 128 tile, for its first 8 dimensions, a scrambling
//! mask and a ranking mask, optimised so that neighbouring pixels' errors cancel
//! value(x, y, i, d) = sobol[d, i ⊕ ranking(x, y, d)] ⊕ scrambling(x, y, d)       (8 bits)
//! ```
//!
//! A stream takes the tables for the next power of two of (samples per pixel × points per
//! light), dimensions 0 and 1 (the pair whose 2-D points are a (0,2)-net; the later optimised
//! pairs are Sobol dimensions with worse 2-D stratification, which measured a larger MSE), and
//! its point index i = aa sample · N + j. The tables alone are one fixed
//! pattern: every render would draw the same points, and a pixel's estimate would be biased
//! (its 8-bit values are cell centres). So each render's seed also moves the tile by a hashed
//! offset, and adds to every coordinate one hashed rotation (Cranley–Patterson, modulo 1) per
//! seed, bounce and light, the same for all pixels: each point becomes uniform on the square,
//! which makes the estimate unbiased, and neighbouring pixels keep the tables' relation to each
//! other, which is what puts their error at high frequencies.
//!
//! Its limit is the tables': at most 256 samples per pixel, so aa samples × N ≤ 256.

use super::{ONE_MINUS_EPS, SampleKey, mix32};

/// The most samples per pixel (antialiasing samples × points per light) the tables hold.
pub const MAX_SAMPLES: u32 = 256;

/// One of the paper's tables, for a power-of-two number of samples per pixel.
#[derive(Clone, Copy, Debug)]
pub struct Tables {
    sobol: &'static [i32],
    scrambling: &'static [i32],
    ranking: &'static [i32],
}

impl Tables {
    /// The tables for `samples` per pixel (rounded up to a power of two; at most
    /// [`MAX_SAMPLES`], above which the 256-sample tables are returned).
    pub fn for_samples(samples: u32) -> Self {
        macro_rules! tables {
            ($spp:ident) => {
                Tables {
                    sobol: blue_noise_sampler::$spp::SOBOL,
                    scrambling: blue_noise_sampler::$spp::SCRAMBLING_TILE,
                    ranking: blue_noise_sampler::$spp::RANKING_TILE,
                }
            };
        }
        match samples.max(1).next_power_of_two() {
            1 => tables!(spp1),
            2 => tables!(spp2),
            4 => tables!(spp4),
            8 => tables!(spp8),
            16 => tables!(spp16),
            32 => tables!(spp32),
            64 => tables!(spp64),
            128 => tables!(spp128),
            _ => tables!(spp256),
        }
    }

    /// The paper's `samplerBlueNoise`, before its conversion to a float: the 8-bit value of
    /// dimension `dim` (below 256) of sample `index` (below 256) at pixel (x, y) of the tile.
    #[inline]
    pub fn value(&self, x: u32, y: u32, index: u32, dim: u32) -> u32 {
        let (x, y, index, dim) = (
            (x & 127) as usize,
            (y & 127) as usize,
            (index & 255) as usize,
            (dim & 255) as usize,
        );
        let tile = (x + y * 128) * 8;
        let ranked = index ^ self.ranking[dim % 8 + tile] as usize;
        let value = self.sobol[dim + ranked * 256] ^ self.scrambling[dim % 8 + tile];
        (value & 255) as u32
    }
}

/// Where a stream reads the tables (dimensions 0 and 1): the tile offset and the rotation of
/// its render's seed and its (bounce, light).
#[derive(Clone, Copy, Debug)]
pub struct Stream {
    x: u32,
    y: u32,
    rotation: (f32, f32),
    first: u32,
}

impl Stream {
    /// The stream of `key` on an image `width` pixels wide, with `points` per light.
    #[inline]
    pub fn new(key: &SampleKey, width: u32, points: u32) -> Self {
        let width = width.max(1);
        let tile = mix32(key.seed ^ 0x1b87_3593);
        let mut h = mix32(key.seed ^ 0xcc9e_2d51);
        h = mix32(h ^ key.bounce);
        h = mix32(h ^ key.light);
        let unit = |bits: u32| (bits >> 8) as f32 * (1.0 / 16_777_216.0);
        Stream {
            x: key.pixel % width + (tile & 127),
            y: key.pixel / width + ((tile >> 7) & 127),
            rotation: (unit(mix32(h ^ 1)), unit(mix32(h ^ 2))),
            first: key.sample.wrapping_mul(points),
        }
    }

    /// Point `j` of the stream, from `tables`.
    #[inline]
    pub fn point(&self, tables: &Tables, j: u32) -> (f32, f32) {
        let index = self.first.wrapping_add(j);
        let coordinate = |dim: u32, rotation: f32| {
            let v = (tables.value(self.x, self.y, index, dim) as f32 + 0.5) * (1.0 / 256.0);
            let r = v + rotation;
            (if r >= 1.0 { r - 1.0 } else { r }).min(ONE_MINUS_EPS)
        };
        (
            coordinate(0, self.rotation.0),
            coordinate(1, self.rotation.1),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_table_has_the_papers_shape() {
        for k in 0..=8 {
            let t = Tables::for_samples(1 << k);
            assert_eq!(t.sobol.len(), 256 * 256);
            assert_eq!(t.scrambling.len(), 128 * 128 * 8);
            assert_eq!(t.ranking.len(), 128 * 128 * 8);
            assert!(t.sobol.iter().all(|v| (0..256).contains(v)));
        }
    }

    /// The paper's points are stratified per pixel: the first 2^k samples of a pixel in one
    /// dimension take 2^k distinct strata of [0, 1).
    #[test]
    fn a_pixels_samples_stratify_each_dimension() {
        for k in [2u32, 4, 6] {
            let n = 1u32 << k;
            let t = Tables::for_samples(n);
            for (x, y, dim) in [(0, 0, 0), (5, 9, 1), (127, 64, 6)] {
                let mut strata: Vec<u32> =
                    (0..n).map(|i| t.value(x, y, i, dim) >> (8 - k)).collect();
                strata.sort_unstable();
                assert_eq!(
                    strata,
                    (0..n).collect::<Vec<_>>(),
                    "{n} samples, ({x}, {y}), dim {dim}"
                );
            }
        }
    }
}
