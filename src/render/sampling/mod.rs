//! Sample placement shared by every engine.
//!
//! Every random number is a pure function of (pixel, sample, bounce, light, dimension, seed):
//! there is no generator state, so any engine, tile order or thread count draws the same
//! numbers and renders the same bytes.
//!
//! Dimensions: the camera ray uses 0 and 1 (pixel jitter, light = `CAMERA_LIGHT`); light sample
//! j uses 2j and 2j + 1 of its (bounce, light) stream.
//!
//! The point sets on a light are [`LightSampler`]s, one file each for those that are more than
//! a few lines: `halton.rs`, `pmj02.rs`, `zsobol.rs`, `bluenoise.rs`. [`PointSet`] is a render's
//! choice of one, with what it needs of the render (the image's width for the screen-space
//! samplers, the tables), and [`check`] says when a render asks more of one than it holds.

pub mod bluenoise;
pub mod halton;
pub mod pmj02;
pub mod stream;
pub mod zsobol;

pub use stream::Stream;

use serde::{Deserialize, Serialize};

/// The `light` value used for the camera's own dimensions.
pub const CAMERA_LIGHT: u32 = u32::MAX;

/// How points are chosen on an area light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum LightSampler {
    /// N independent uniform points on the light.
    Random,
    /// Jittered: the light's (u, v) square split into N strata (nx × ny, see `strata_grid`),
    /// one uniform point in each.
    #[default]
    Stratified,
    /// Owen-scrambled Sobol points (Burley 2020), scrambled independently for every
    /// (pixel, sample, bounce, light): low discrepancy for any N, best at powers of two.
    Sobol,
    /// The lab's own strategy: the centre of the light's (u, v) square (its centroid, for a
    /// parallelogram) when N = 1, independent random points otherwise.
    Lab,
    /// Halton points in bases 2 and 3, Owen-scrambled independently for every stream
    /// (`halton.rs`).
    Halton,
    /// Progressive multi-jittered (0,2) points (Christensen et al. 2018), from tables of our
    /// own generator, digitally shifted for every stream: at most 4096 points (`pmj02.rs`).
    Pmj02,
    /// Sobol points indexed through the pixel's Morton order (Ahmed and Wonka 2020, pbrt-v4's
    /// ZSobolSampler): the error as blue noise in screen space; image and samples together
    /// within 32 index bits (`zsobol.rs`).
    Zsobol,
    /// The blue-noise sampler of Heitz et al. 2019, from the paper's tables: at most 256
    /// samples per pixel (aa samples × points) (`bluenoise.rs`).
    Bluenoise,
}

impl LightSampler {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            LightSampler::Random => "random",
            LightSampler::Stratified => "stratified",
            LightSampler::Sobol => "sobol",
            LightSampler::Lab => "lab",
            LightSampler::Halton => "halton",
            LightSampler::Pmj02 => "pmj02",
            LightSampler::Zsobol => "zsobol",
            LightSampler::Bluenoise => "bluenoise",
        }
    }

    /// Every sampler, in the order reports list them: the lab's four, then the rest of the
    /// point sets pbrt-v4 offers and the blue-noise tables.
    pub const ALL: [LightSampler; 8] = [
        LightSampler::Random,
        LightSampler::Stratified,
        LightSampler::Sobol,
        LightSampler::Lab,
        LightSampler::Halton,
        LightSampler::Pmj02,
        LightSampler::Zsobol,
        LightSampler::Bluenoise,
    ];

    /// The most points per light a stream of this sampler holds, and why; `None` for no limit
    /// below the command line's 65536.
    fn max_points(self) -> Option<(u32, &'static str)> {
        match self {
            LightSampler::Sobol => Some((65_536, "its Sobol indices are 16 bits")),
            LightSampler::Pmj02 => {
                Some((pmj02::TABLE_POINTS as u32, "its tables hold 4096 points"))
            }
            LightSampler::Bluenoise => Some((
                bluenoise::MAX_SAMPLES,
                "the paper's tables hold 256 samples per pixel",
            )),
            _ => None,
        }
    }
}

/// A render that asks a sampler for more than it holds: the message names the sampler, its
/// limit and why.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SamplerLimit {
    /// No points per light.
    #[error("--shadow-samples 0 with --sampler {}: expected {}", .0.name(), range(*.0))]
    NoPoints(LightSampler),
    /// More points per stream than the sampler holds.
    #[error("--sampler {} with {asked}: expected {}", sampler.name(), range(*sampler))]
    TooManyPoints {
        /// The sampler.
        sampler: LightSampler,
        /// The points asked for, in words.
        asked: String,
    },
    /// An image and sample count whose ZSobol indices pass 32 bits.
    #[error(
        "--sampler zsobol on a {image} image with {samples} samples per pixel needs {bits}-bit \
         sample indices: expected at most 32 (2 bits per doubling of the image's larger \
         side, plus those of the aa samples × points per light, each rounded up to a \
         power of two); use a smaller image or fewer points"
    )]
    IndexBits {
        /// The bits the render needs.
        bits: u32,
        /// The image's size, W×H.
        image: String,
        /// Samples per pixel (aa × points, each rounded up to a power of two).
        samples: u64,
    },
}

/// The points per light `sampler` takes, in words.
fn range(sampler: LightSampler) -> String {
    match sampler.max_points() {
        Some((n, why)) => format!("1 to {n} points per light ({why})"),
        None => "1 to 65536 points per light".to_string(),
    }
}

/// Whether `n` points per light of `sampler`, with `aa` samples per pixel of a `size` image,
/// ask the sampler for no more than it holds (`RenderSettings::check_sampler` adds that a
/// render asks for at least one point).
pub fn check(sampler: LightSampler, n: u32, aa: u32, size: (u32, u32)) -> Result<(), SamplerLimit> {
    let aa = aa.max(1);
    match sampler {
        LightSampler::Bluenoise
            if u64::from(n) * u64::from(aa) > u64::from(bluenoise::MAX_SAMPLES) =>
        {
            Err(SamplerLimit::TooManyPoints {
                sampler,
                asked: if aa > 1 {
                    format!(
                        "{n} points per light × {aa} aa samples = {} per pixel",
                        u64::from(n) * u64::from(aa)
                    )
                } else {
                    format!("{n} points per light")
                },
            })
        }
        LightSampler::Zsobol => {
            let layout = zsobol::Layout::new(size.0, size.1, aa, n);
            let bits = layout.index_bits();
            if bits > 32 {
                Err(SamplerLimit::IndexBits {
                    bits,
                    image: format!("{}×{}", size.0, size.1),
                    samples: 1u64 << (layout.aa_bits + layout.point_bits),
                })
            } else {
                Ok(())
            }
        }
        _ => match sampler.max_points() {
            Some((max, _)) if n > max => Err(SamplerLimit::TooManyPoints {
                sampler,
                asked: format!("{n} points per light"),
            }),
            _ => Ok(()),
        },
    }
}

/// The point set of one render: its sampler, its points per light, and what the sampler needs
/// of the render. Built once per render (both engines), then [`PointSet::point`] per point.
/// Within [`check`]'s limits every point is what the sampler defines; past them the tables and
/// indices wrap (never a panic).
#[derive(Clone, Copy, Debug)]
pub struct PointSet {
    /// The sampler.
    pub sampler: LightSampler,
    /// Points per light, N.
    pub count: u32,
    pub(crate) width: u32,
    pub(crate) halton_digits: (u32, u32),
    pub(crate) pmj02: Option<&'static [pmj02::Table]>,
    pub(crate) zsobol: zsobol::Layout,
    pub(crate) bluenoise: Option<bluenoise::Tables>,
}

impl PointSet {
    /// `count` points per light of `sampler` on an image of `size` pixels with `aa` samples
    /// per pixel (the image and aa matter to zsobol and bluenoise only).
    pub fn with(sampler: LightSampler, count: u32, size: (u32, u32), aa: u32) -> Self {
        let aa = aa.max(1);
        PointSet {
            sampler,
            count,
            width: size.0.max(1),
            halton_digits: halton::digits(count),
            pmj02: (sampler == LightSampler::Pmj02).then(|| pmj02::tables(count)),
            zsobol: zsobol::Layout::new(size.0, size.1, aa, count),
            bluenoise: (sampler == LightSampler::Bluenoise)
                .then(|| bluenoise::Tables::for_samples(count.saturating_mul(aa))),
        }
    }

    /// A point set that needs nothing of an image: for the samplers whose points depend on the
    /// stream alone (on a 1×1 image for the others).
    pub fn of(sampler: LightSampler, count: u32) -> Self {
        Self::with(sampler, count, (1, 1), 1)
    }

    /// The point in [0, 1)² for sample `index` of `key`'s stream.
    #[inline(always)]
    pub fn point(&self, key: &SampleKey, index: u32) -> (f32, f32) {
        let count = self.count;
        match self.sampler {
            LightSampler::Random => (uniform(key, 2 * index), uniform(key, 2 * index + 1)),
            LightSampler::Lab if count == 1 => (0.5, 0.5),
            LightSampler::Lab => (uniform(key, 2 * index), uniform(key, 2 * index + 1)),
            LightSampler::Sobol => {
                // One scramble seed per stream; the index is the sample number (< 2^16: `check`).
                // `sample_4d` gives `sample(index, 0 | 1, scramble)`'s values at about half the
                // cost, shuffling the index once for dimensions 0–3 (tests/sampling/sampling.rs).
                let scramble = hash(key, SOBOL_SEED_DIM);
                let [u, v, _, _] = sobol_burley::sample_4d(index, 0, scramble);
                (u, v)
            }
            LightSampler::Stratified => {
                let xi0 = uniform(key, 2 * index);
                let xi1 = uniform(key, 2 * index + 1);
                let (nx, ny) = strata_grid(count);
                let (cx, cy) = (index % nx, index / nx);
                // `min` keeps (c + ξ)/n below 1 when rounding would land exactly on it.
                let u = ((cx as f32 + xi0) / nx as f32).min(ONE_MINUS_EPS);
                let v = ((cy as f32 + xi1) / ny as f32).min(ONE_MINUS_EPS);
                (u, v)
            }
            LightSampler::Halton
            | LightSampler::Pmj02
            | LightSampler::Zsobol
            | LightSampler::Bluenoise => self.table_point(key, index),
        }
    }

    /// [`PointSet::point`] for the samplers of digit loops and table reads (through their
    /// [`Stream`]), out of line: inlined beside the lab's four, their code cost those 3–8% more
    /// instructions (tests/gates/icount.rs). A loop over a stream should take it once instead.
    #[inline(never)]
    fn table_point(&self, key: &SampleKey, index: u32) -> (f32, f32) {
        match self.stream(key) {
            Some(stream) => stream.point(index),
            None => self.point(key, index),
        }
    }
}

/// A small fixed-seed generator (SplitMix64) for inputs that are not samples: the PMJ02
/// tables and the peer benchmark's ray sets, which must not depend on `rand`'s version or
/// platform. A render's samples come from [`hash`] alone.
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 24 bits.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Below `n` (n > 0), with the modulo's bias of at most n/2^64.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// The hash dimensions that seed a stream's Halton scrambles and its PMJ02 table and shift
/// (far above the 2j, 2j + 1 range, below Sobol's).
pub const HALTON_SEED_DIM: u32 = u32::MAX - 2;
/// See [`HALTON_SEED_DIM`].
pub const PMJ02_SEED_DIM: u32 = u32::MAX - 3;

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
                let (u, v) = PointSet::of(LightSampler::Stratified, n).point(&key, j);
                assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                let cell = (v * ny as f32) as u32 * nx + (u * nx as f32) as u32;
                seen[cell as usize] += 1;
            }
            assert!(seen.iter().all(|&c| c == 1), "n = {n}: {seen:?}");
        }
    }
}
