//! Where a (sampler, N)'s error sits in screen space, over its K seeds: the spectrum, the
//! low-band power and the low-pass error of `spectrum.rs`, each a mean over the seeds with its
//! 95% interval (bootstrap over seeds, as every figure of the study), and the low band as a
//! ratio to random's on the same seeds.

use crate::variance::Row;
use crate::variance::figures::fits::{interval, mean_at, with_random};
use crate::variance::figures::spectrum::{LOWPASS_SIGMAS, RINGS, lowpass_mse, radial_power};
use glam::Vec3;
use serde::Serialize;

/// The perceived-error figures of one row.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct Perceived {
    /// Mean square error after a Gaussian blur of σ = 1 and 2 pixels, mean over seeds.
    pub lowpass_mse: [f64; 2],
    /// 95% intervals of `lowpass_mse`.
    pub lowpass_interval: [Option<[f64; 2]>; 2],
    /// Mean error power over 0 < |f| ≤ 1/8 cycles per pixel, mean over seeds.
    pub low_band_power: f64,
    /// 95% interval of `low_band_power`.
    pub low_band_interval: Option<[f64; 2]>,
    /// The low band's share: its mean power over the whole band's, mean over seeds. 1 for
    /// white noise, below 1 where the error is blue, whatever its size.
    pub low_band_share: f64,
    /// 95% interval of `low_band_share`.
    pub low_band_share_interval: Option<[f64; 2]>,
    /// `low_band_power` over random's at the same N and region (below 1: less low-frequency
    /// error than random); None without random.
    pub low_band_vs_random: Option<f64>,
    /// 95% interval of `low_band_vs_random`, on the same seed resamples for both.
    pub low_band_vs_random_interval: Option<[f64; 2]>,
    /// Radially averaged error power per ring (`spectrum::ring_frequency`), mean over seeds;
    /// NaN (null in JSON) for a ring the image has no frequency in.
    pub spectrum: Vec<f64>,
    /// 95% interval of each ring's power.
    pub spectrum_interval: Vec<Option<[f64; 2]>>,
    /// Per seed: low-band power.
    #[serde(skip)]
    pub seed_low_band: Vec<f64>,
}

/// The error image of `image` against `reference`: the mean of the three channels' difference.
fn error_image(image: &[Vec3], reference: &[Vec3]) -> Vec<f64> {
    image
        .iter()
        .zip(reference)
        .map(|(a, b)| ((*a - *b).element_sum() / 3.0) as f64)
        .collect()
}

/// The figures of `images` (K seeds of one sampler and N) against `reference` over `region`,
/// on a `width` × `height` image. Empty (all zero) for an empty region.
pub fn measure(
    images: &[&[Vec3]],
    reference: &[Vec3],
    width: usize,
    height: usize,
    region: &[bool],
) -> Perceived {
    let mut spectra = Vec::new();
    let mut seed_lowpass: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    for image in images {
        let e = error_image(image, reference);
        let Some(s) = radial_power(&e, width, height, region) else {
            return Perceived::default();
        };
        spectra.push(s);
        for (i, &sigma) in LOWPASS_SIGMAS.iter().enumerate() {
            seed_lowpass[i].push(lowpass_mse(&e, width, height, sigma, region).unwrap_or(0.0));
        }
    }
    let k = images.len();
    let seed_low_band: Vec<f64> = spectra.iter().map(|s| s.low_band).collect();
    let seed_share: Vec<f64> = spectra.iter().map(|s| s.low_band / s.all_band).collect();
    let ring = |i: usize| -> Vec<f64> { spectra.iter().map(|s| s.power[i]).collect() };
    let lowpass_interval = [0, 1].map(|i| interval(k, |idx| mean_at(&seed_lowpass[i], Some(idx))));
    Perceived {
        lowpass_mse: [0, 1].map(|i| mean_at(&seed_lowpass[i], None)),
        lowpass_interval,
        low_band_power: mean_at(&seed_low_band, None),
        low_band_interval: interval(k, |idx| mean_at(&seed_low_band, Some(idx))),
        low_band_share: mean_at(&seed_share, None),
        low_band_share_interval: interval(k, |idx| mean_at(&seed_share, Some(idx))),
        spectrum: (0..RINGS).map(|i| mean_at(&ring(i), None)).collect(),
        spectrum_interval: (0..RINGS)
            .map(|i| {
                let powers = ring(i);
                interval(k, |idx| mean_at(&powers, Some(idx)))
            })
            .collect(),
        seed_low_band,
        ..Perceived::default()
    }
}

/// Fills every row's low band relative to random's at the same N and region.
pub(crate) fn low_band_vs_random(rows: &mut [Row], k: usize) {
    with_random(rows, |row, random| {
        let (p, base) = (&mut row.perceived, &random.perceived);
        // An empty region measured nothing: no seeds to resample.
        if p.seed_low_band.len() != k || base.seed_low_band.len() != k {
            return;
        }
        if base.low_band_power > 0.0 {
            p.low_band_vs_random = Some(p.low_band_power / base.low_band_power);
        }
        let seeds = &p.seed_low_band;
        p.low_band_vs_random_interval = interval(k, |idx| {
            mean_at(seeds, Some(idx)) / mean_at(&base.seed_low_band, Some(idx))
        });
    });
}
