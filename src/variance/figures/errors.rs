//! The numbers of a variance study, as pure functions of images: error against the converged
//! reference over a region, per seed and pooled, and the bias bound. Tested on synthetic data,
//! where the right answers are known in closed form.

use crate::render::sampling::LightSampler;
use glam::Vec3;
use serde::Serialize;

/// Error statistics of K images of one (sampler, N) over one region.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct ErrorStats {
    /// Mean squared error against the reference, over images, pixels and channels.
    pub mse: f64,
    /// Mean signed error (image − reference).
    pub bias: f64,
    /// The largest |bias| that no bias explains at [`BIAS_FALSE_ALARM`] ([`bias_bound`]): a
    /// larger |bias| means the sampler (or the reference) is biased. Infinite below 2 images.
    pub bias_bound: f64,
    /// Per-pixel variance across the K images (K − 1 denominator), averaged over the region.
    pub variance: f64,
    /// Pixels in the region.
    pub pixels: usize,
}

/// Statistics of `images` (each `pixels` long) against `reference` over the pixels where
/// `region` is true. `reference_noise` is the per-pixel error variance of the reference
/// itself (added to the bias bound, since the reference's own noise moves the mean error).
pub fn error_stats(
    images: &[&[Vec3]],
    reference: &[Vec3],
    reference_noise: &[f32],
    region: &[bool],
) -> ErrorStats {
    let k = images.len();
    let [mut sum_sq, mut sum, mut sum_var, mut ref_var] = [0.0f64; 4];
    let mut pixels = 0usize;
    // Each image's summed error over the region: its mean error, times 3P.
    let mut image_sums = vec![0.0f64; k];
    for p in (0..reference.len()).filter(|&p| region[p]) {
        pixels += 1;
        ref_var += reference_noise[p] as f64;
        for c in 0..3 {
            let r = reference[p][c] as f64;
            let mut m = 0.0;
            for (img, image_sum) in images.iter().zip(&mut image_sums) {
                let e = img[p][c] as f64 - r;
                sum += e;
                sum_sq += e * e;
                m += e;
                *image_sum += e;
            }
            if k > 1 {
                m /= k as f64;
                let v: f64 = images
                    .iter()
                    .map(|img| (img[p][c] as f64 - r - m).powi(2))
                    .sum();
                sum_var += v / (k - 1) as f64;
            }
        }
    }
    if pixels == 0 || k == 0 {
        return ErrorStats::default();
    }
    let samples = (pixels * 3 * k) as f64;
    let image_means: Vec<f64> = image_sums.iter().map(|s| s / (pixels * 3) as f64).collect();
    ErrorStats {
        mse: sum_sq / samples,
        bias: sum / samples,
        bias_bound: bias_bound(&image_means, ref_var / pixels as f64, pixels),
        variance: sum_var / (pixels * 3) as f64,
        pixels,
    }
}

/// The two-sided false-alarm rate of the bias check: that of four standard errors of a normal
/// mean, 2·(1 − Φ(4)).
pub const BIAS_FALSE_ALARM: f64 = 6.334_248_366_623_996e-5;

/// The bias bound of K images whose mean errors over a region of `pixels` pixels are
/// `image_means`, when the reference's own per-pixel error variance averages `ref_variance`:
///
/// ```text
/// SE² = s²/K + σ²_ref/P      s² the variance of the K image means (K − 1 denominator)
/// bound = t(K − 1, 1 − α/2) · SE     α = BIAS_FALSE_ALARM
/// ```
///
/// The images are the independent unit, not the pixels: a sampler's errors may be correlated
/// across pixels (positively for the blue-noise tables, whose shift is shared by the whole
/// image; negatively for ZSobol), and the variance of an image's mean error holds those
/// correlations where per-pixel variances do not. With few images s² is itself uncertain, so
/// the quantile is Student's t (8.47 at K = 8, 4.6 at K = 32, 4 in the limit), not 4.
/// Infinite for K < 2: one image cannot tell bias from noise.
pub fn bias_bound(image_means: &[f64], ref_variance: f64, pixels: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let k = image_means.len();
    if k < 2 || pixels == 0 {
        return f64::INFINITY;
    }
    let mean = image_means.iter().sum::<f64>() / k as f64;
    let s2 = image_means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (k - 1) as f64;
    let se = (s2 / k as f64 + ref_variance / pixels as f64).sqrt();
    let t = StudentsT::new(0.0, 1.0, (k - 1) as f64)
        .expect("K − 1 ≥ 1 degrees of freedom")
        .inverse_cdf(1.0 - BIAS_FALSE_ALARM / 2.0);
    t * se
}

/// The squared error of each pixel against `reference`, averaged over channels and `images`:
/// the heat maps' values.
pub fn pixel_mse(images: &[&[Vec3]], reference: &[Vec3]) -> Vec<f32> {
    (0..reference.len())
        .map(|p| {
            let sq: f32 = images
                .iter()
                .map(|img| (img[p] - reference[p]).length_squared())
                .sum();
            sq / (3 * images.len().max(1)) as f32
        })
        .collect()
}

/// Mean squared error and mean signed error of each image of `images` against `reference`
/// over the pixels where `region` is true (the per-seed figures that [`error_stats`] pools):
/// one `(mse, bias)` per image, `(0, 0)` for an empty region.
pub fn per_image_errors(
    images: &[&[Vec3]],
    reference: &[Vec3],
    region: &[bool],
) -> Vec<(f64, f64)> {
    images
        .iter()
        .map(|img| {
            let (mut sum_sq, mut sum, mut count) = (0.0f64, 0.0f64, 0usize);
            for p in (0..reference.len()).filter(|&p| region[p]) {
                for c in 0..3 {
                    let e = img[p][c] as f64 - reference[p][c] as f64;
                    sum_sq += e * e;
                    sum += e;
                    count += 1;
                }
            }
            if count == 0 {
                (0.0, 0.0)
            } else {
                (sum_sq / count as f64, sum / count as f64)
            }
        })
        .collect()
}

/// True when `sampler` draws the same points at budget `n` whatever the seed, so that its
/// error there is bias, not noise, and does not lie on the N^-slope line of its noisy points:
/// the lab's strategy at N = 1 (the light's centre). Such points are left out of the fits.
pub fn deterministic(sampler: LightSampler, n: u32) -> bool {
    matches!((sampler, n), (LightSampler::Lab, 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_known_errors() {
        // Reference 0.5 everywhere; two images with errors +0.1 and −0.1 on region pixels.
        let reference = vec![Vec3::splat(0.5); 4];
        let a: Vec<Vec3> = vec![Vec3::splat(0.6); 4];
        let b: Vec<Vec3> = vec![Vec3::splat(0.4); 4];
        let region = [true, true, false, true];
        let noise = vec![0.0f32; 4];
        let s = error_stats(&[&a, &b], &reference, &noise, &region);
        assert_eq!(s.pixels, 3);
        // The images are f32 (0.6 is 0.60000002...), so compare at f32 precision.
        assert!((s.mse - 0.01).abs() < 1e-6, "{s:?}");
        assert!(s.bias.abs() < 1e-6);
        // Per pixel: values 0.6, 0.4 -> sample variance 0.02.
        assert!((s.variance - 0.02).abs() < 1e-6);
        // A constant offset is bias, and it exceeds its bound: 8 images at 0.06 ± 0.001.
        let shifted: Vec<Vec<Vec3>> = (0..8)
            .map(|k| vec![Vec3::splat(0.559 + 0.002 * (k % 2) as f32); 4])
            .collect();
        let views: Vec<&[Vec3]> = shifted.iter().map(Vec::as_slice).collect();
        let s = error_stats(&views, &reference, &noise, &region);
        assert!((s.bias - 0.06).abs() < 1e-6, "{s:?}");
        assert!(s.bias.abs() > s.bias_bound, "{s:?}");
        // Two images cannot tell it from noise: t(1) is 10050.
        let s = error_stats(&views[..2], &reference, &noise, &region);
        assert!(s.bias.abs() < s.bias_bound, "{s:?}");
        // One image cannot test at all.
        let s = error_stats(&views[..1], &reference, &noise, &region);
        assert_eq!(s.bias_bound, f64::INFINITY);
    }

    /// The quantile: 2·(1 − Φ(4)) is the false-alarm rate, t(1) and t(2) have closed forms,
    /// and many images give the normal's 4 standard errors.
    #[test]
    fn the_bound_s_quantile_is_student_s() {
        use statrs::distribution::{ContinuousCDF, Normal};
        let phi4 = Normal::new(0.0, 1.0).unwrap().cdf(4.0);
        assert!((BIAS_FALSE_ALARM / (2.0 * (1.0 - phi4)) - 1.0).abs() < 1e-6);
        let a = BIAS_FALSE_ALARM;
        // SE of K means with s² = 1: 1/√K, so the bound over it is the quantile.
        let quantile = |means: &[f64]| {
            let k = means.len() as f64;
            let mean = means.iter().sum::<f64>() / k;
            let s2 = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (k - 1.0);
            bias_bound(means, 0.0, 1) / (s2 / k).sqrt()
        };
        let t1 = 1.0 / (std::f64::consts::PI * a / 2.0).tan();
        let t2 = (1.0 - a) / (2.0 * (a / 2.0) * (1.0 - a / 2.0)).sqrt();
        assert!(
            (quantile(&[1.0, -1.0]) / t1 - 1.0).abs() < 1e-6,
            "t(1) {t1}"
        );
        assert!(
            (quantile(&[1.0, 0.0, -1.0]) / t2 - 1.0).abs() < 1e-6,
            "t(2) {t2}"
        );
        let many: Vec<f64> = (0..100_000).map(|i| f64::from(i % 2)).collect();
        assert!((quantile(&many) - 4.0).abs() < 1e-3, "{}", quantile(&many));
    }

    #[test]
    fn per_image_errors_pool_to_the_study_mse() {
        let reference = vec![Vec3::splat(0.5); 3];
        let a = vec![Vec3::splat(0.75); 3];
        let b = vec![Vec3::new(0.5, 0.5, 0.25); 3];
        let region = [true, false, true];
        let e = per_image_errors(&[&a, &b], &reference, &region);
        assert_eq!(e, vec![(0.0625, 0.25), (0.0625 / 3.0, -0.25 / 3.0)]);
        assert_eq!(
            per_image_errors(&[&a], &reference, &[false; 3]),
            vec![(0.0, 0.0)]
        );
        assert!(deterministic(LightSampler::Lab, 1));
        assert!(!deterministic(LightSampler::Lab, 4) && !deterministic(LightSampler::Random, 1));
    }

    #[test]
    fn empty_region_gives_zeros() {
        let reference = vec![Vec3::ZERO; 2];
        let s = error_stats(&[&reference], &reference, &[0.0, 0.0], &[false, false]);
        assert_eq!(s, ErrorStats::default());
    }
}
