//! Sample placement shared by every engine.
//!
//! Every random number is a pure function of (pixel, sample, bounce, light, dimension, seed):
//! there is no generator state, so any engine, tile order or thread count draws the same
//! numbers and renders the same bytes.
//!
//! Dimensions: the camera ray uses 0 and 1 (pixel jitter, light = `CAMERA_LIGHT`); light sample
//! j uses 2j and 2j + 1 of its (bounce, light) stream.

use serde::{Deserialize, Serialize};

/// The `light` value used for the camera's own dimensions.
pub const CAMERA_LIGHT: u32 = u32::MAX;

/// How points are chosen on an area light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum LightSampler {
    /// N independent uniform points on the light.
    Random,
    /// Jittered: the light's (u, v) square split into N strata (nx × ny, see `strata_grid`),
    /// one uniform point in each.
    Stratified,
    /// Owen-scrambled Sobol points (Burley 2020), scrambled independently for every
    /// (pixel, sample, bounce, light): low discrepancy for any N, best at powers of two.
    Sobol,
    /// The lab's own strategy: the centre of the light's (u, v) square (its centroid, for a
    /// parallelogram) when N = 1, independent random points otherwise.
    Lab,
}

impl LightSampler {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            LightSampler::Random => "random",
            LightSampler::Stratified => "stratified",
            LightSampler::Sobol => "sobol",
            LightSampler::Lab => "lab",
        }
    }

    /// Every sampler, in the order reports list them.
    pub const ALL: [LightSampler; 4] = [
        LightSampler::Random,
        LightSampler::Stratified,
        LightSampler::Sobol,
        LightSampler::Lab,
    ];
}

/// Identifies one stream of random numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleKey {
    /// Pixel index, row-major from the top-left.
    pub pixel: u32,
    /// Antialiasing sample index within the pixel.
    pub sample: u32,
    /// Path depth: 0 for the camera hit, 1 after one reflection, ...
    pub bounce: u32,
    /// Light index, or `CAMERA_LIGHT`.
    pub light: u32,
    /// The render's seed.
    pub seed: u32,
}

/// Chris Wellons' `lowbias32` integer finaliser: a bijection on u32 with very low bias.
#[inline(always)]
pub fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Hashes the key and a dimension to 32 random bits.
#[inline(always)]
pub fn hash(key: &SampleKey, dim: u32) -> u32 {
    let mut h = mix32(key.seed ^ 0x9e37_79b9);
    h = mix32(h ^ key.pixel);
    h = mix32(h ^ key.sample);
    h = mix32(h ^ key.bounce);
    h = mix32(h ^ key.light);
    mix32(h ^ dim)
}

/// A uniform number in [0, 1) for (key, dim): the top 24 bits, so the float is exact.
#[inline(always)]
pub fn uniform(key: &SampleKey, dim: u32) -> f32 {
    (hash(key, dim) >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Splits n strata into an nx × ny grid with nx·ny = n and nx ≥ ny as close to square as n's
/// divisors allow: 16 → 4×4, 8 → 4×2, 10 → 5×2, 7 → 7×1 (a prime gives strips, which are
/// still strata: unbiased, but only one-dimensional).
pub fn strata_grid(n: u32) -> (u32, u32) {
    let n = n.max(1);
    let mut ny = (n as f64).sqrt() as u32;
    while ny > 1 && !n.is_multiple_of(ny) {
        ny -= 1;
    }
    (n / ny.max(1), ny.max(1))
}

/// The point in [0, 1)² for sample `index` of `count` with the given sampler.
#[inline(always)]
pub fn square_sample(sampler: LightSampler, key: &SampleKey, index: u32, count: u32) -> (f32, f32) {
    let xi0 = uniform(key, 2 * index);
    let xi1 = uniform(key, 2 * index + 1);
    match sampler {
        LightSampler::Random => (xi0, xi1),
        LightSampler::Lab if count == 1 => (0.5, 0.5),
        LightSampler::Lab => (xi0, xi1),
        LightSampler::Sobol => {
            // One scramble seed per stream; the Sobol index is the sample number (< 2^16,
            // which the command line's limit on N guarantees).
            // `sample_4d` computes dimensions 0–3 together, with the index shuffle done once:
            // the same values as `sample(index, 0 | 1, scramble)` (tests/sampling/sampling.rs), at
            // about half the cost.
            let scramble = hash(key, SOBOL_SEED_DIM);
            let [u, v, _, _] = sobol_burley::sample_4d(index, 0, scramble);
            (u, v)
        }
        LightSampler::Stratified => {
            let (nx, ny) = strata_grid(count);
            let (cx, cy) = (index % nx, index / nx);
            // `min` keeps (c + ξ)/n below 1 when rounding would land exactly on it.
            let u = ((cx as f32 + xi0) / nx as f32).min(ONE_MINUS_EPS);
            let v = ((cy as f32 + xi1) / ny as f32).min(ONE_MINUS_EPS);
            (u, v)
        }
    }
}

/// The hash dimension that seeds a stream's Sobol scramble (far above the 2j, 2j + 1 range).
pub const SOBOL_SEED_DIM: u32 = u32::MAX;

/// The largest f32 below 1.
pub const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// Sub-pixel offset in [0, 1)² for antialiasing sample `index` of `count`: the pixel centre for
/// one sample, jittered strata for more.
#[inline]
pub fn pixel_offset(key: &SampleKey, index: u32, count: u32) -> (f32, f32) {
    if count <= 1 {
        return (0.5, 0.5);
    }
    let key = SampleKey {
        light: CAMERA_LIGHT,
        bounce: 0,
        ..*key
    };
    // The camera stream uses dimensions 0 and 1 only: the stratum is chosen by `index`.
    let (nx, ny) = strata_grid(count);
    let (cx, cy) = (index % nx, index / nx);
    let u = ((cx as f32 + uniform(&key, 0)) / nx as f32).min(ONE_MINUS_EPS);
    let v = ((cy as f32 + uniform(&key, 1)) / ny as f32).min(ONE_MINUS_EPS);
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_grids_multiply_back_to_n() {
        for n in 1..300 {
            let (nx, ny) = strata_grid(n);
            assert_eq!(nx * ny, n, "n = {n}");
            assert!(nx >= ny);
        }
        assert_eq!(strata_grid(16), (4, 4));
        assert_eq!(strata_grid(8), (4, 2));
        assert_eq!(strata_grid(7), (7, 1));
    }

    #[test]
    fn uniform_is_in_unit_interval_and_depends_on_every_field() {
        let key = SampleKey {
            pixel: 3,
            sample: 1,
            bounce: 2,
            light: 0,
            seed: 7,
        };
        let base = uniform(&key, 5);
        assert!((0.0..1.0).contains(&base));
        let variants = [
            SampleKey { pixel: 4, ..key },
            SampleKey { sample: 2, ..key },
            SampleKey { bounce: 3, ..key },
            SampleKey { light: 1, ..key },
            SampleKey { seed: 8, ..key },
        ];
        for v in variants {
            assert_ne!(uniform(&v, 5), base, "{v:?}");
        }
        assert_ne!(uniform(&key, 6), base);
    }

    #[test]
    fn stratified_puts_one_point_in_every_stratum() {
        for n in [1u32, 2, 3, 4, 7, 9, 10, 16, 64] {
            let key = SampleKey {
                pixel: 11,
                sample: 0,
                bounce: 0,
                light: 0,
                seed: 1,
            };
            let (nx, ny) = strata_grid(n);
            let mut seen = vec![0u32; n as usize];
            for j in 0..n {
                let (u, v) = square_sample(LightSampler::Stratified, &key, j, n);
                assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                let cell = (v * ny as f32) as u32 * nx + (u * nx as f32) as u32;
                seen[cell as usize] += 1;
            }
            assert!(seen.iter().all(|&c| c == 1), "n = {n}: {seen:?}");
        }
    }
}
