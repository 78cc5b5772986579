//! The error's spectrum and the error a viewer perceives: two measures of *where* the error
//! sits in screen space, beside the MSE, which says only how much there is.
//!
//! ```text
//! e        = render − reference, the mean of the channels, per pixel
//! spectrum: e' = (e − mean of e over the region) on the region, 0 elsewhere
//!           P(f) = |DFT(e')(f)|² / (pixels in the region)        white noise of variance σ²: P = σ²
//!           radially averaged over rings of |f| in (0, ½] cycles per pixel (the DC term left out)
//! low band: the mean of P over the rings' lowest quarter, 0 < |f| ≤ ⅛
//! low-pass: e blurred by a Gaussian of σ = 1 and 2 pixels (normalised within the image), its
//!           mean square over the region: what a viewer sees at a distance (Heitz et al. 2019)
//! ```
//!
//! A sampler whose neighbouring pixels' errors cancel (blue noise) has little power at low
//! frequencies and a small low-pass error, even at the same MSE. The measurement is checked on
//! inputs whose spectra are known (tests below): white noise is flat, a Laplacian of white
//! noise has almost no low-frequency power.

// The scalar planner: the spectra are of small images and take microseconds, while the
// default planner's SIMD algorithms, instantiated in this crate, cost 13 CPU-seconds of
// every build of the library.
use rustfft::FftPlannerScalar;
use rustfft::num_complex::Complex;

/// Rings of the radially averaged spectrum over (0, ½] cycles per pixel.
pub const RINGS: usize = 32;

/// The lowest quarter of the band: |f| ≤ this, in cycles per pixel.
pub const LOW_BAND: f64 = 0.125;

/// The blur widths of the perceived error, in pixels.
pub const LOWPASS_SIGMAS: [f64; 2] = [1.0, 2.0];

/// The radially averaged power spectrum of one error image over one region.
#[derive(Clone, Debug, PartialEq)]
pub struct Radial {
    /// Mean power per ring; NaN for a ring with no frequency in it (tiny images).
    pub power: Vec<f64>,
    /// Mean power over 0 < |f| ≤ [`LOW_BAND`].
    pub low_band: f64,
    /// Mean power over the whole disc, 0 < |f| ≤ ½: `low_band` over it is the low band's share
    /// (1 for white noise, below 1 for blue noise), whatever the error's size.
    pub all_band: f64,
}

/// The centre of ring `i`, in cycles per pixel.
pub fn ring_frequency(i: usize) -> f64 {
    (i as f64 + 0.5) * 0.5 / RINGS as f64
}

/// The power spectrum of `error` (width × height, row-major) over the pixels where `region`
/// is true, radially averaged (see the module's diagram). `None` for an empty region.
pub fn radial_power(error: &[f64], width: usize, height: usize, region: &[bool]) -> Option<Radial> {
    assert_eq!(error.len(), width * height);
    assert_eq!(region.len(), error.len());
    let count = region.iter().filter(|&&r| r).count();
    if count == 0 {
        return None;
    }
    let sum: f64 = (error.iter().zip(region))
        .filter_map(|(e, &r)| r.then_some(e))
        .sum();
    let mean = sum / count as f64;
    let mut data: Vec<Complex<f64>> = error
        .iter()
        .zip(region)
        .map(|(&e, &r)| Complex::new(if r { e - mean } else { 0.0 }, 0.0))
        .collect();
    fft_2d(&mut data, width, height);
    let mut sums = vec![0.0f64; RINGS];
    let mut counts = vec![0usize; RINGS];
    let (mut low_sum, mut low_count) = (0.0, 0usize);
    let (mut all_sum, mut all_count) = (0.0, 0usize);
    // |f| of DFT index k of n: k/n up to n/2, (n − k)/n above (only its square is used).
    let frequency = |k: usize, n: usize| k.min(n - k) as f64 / n as f64;
    for ky in 0..height {
        let fy = frequency(ky, height);
        for kx in 0..width {
            let fx = frequency(kx, width);
            let r = (fx * fx + fy * fy).sqrt();
            if r == 0.0 || r > 0.5 {
                continue;
            }
            let p = data[ky * width + kx].norm_sqr() / count as f64;
            let ring = ((r / 0.5 * RINGS as f64) as usize).min(RINGS - 1);
            sums[ring] += p;
            counts[ring] += 1;
            all_sum += p;
            all_count += 1;
            if r <= LOW_BAND {
                low_sum += p;
                low_count += 1;
            }
        }
    }
    let mean = |s: f64, c: usize| if c == 0 { f64::NAN } else { s / c as f64 };
    Some(Radial {
        power: sums
            .iter()
            .zip(&counts)
            .map(|(&s, &c)| mean(s, c))
            .collect(),
        low_band: mean(low_sum, low_count),
        all_band: mean(all_sum, all_count),
    })
}

/// The 2-D DFT of `data` in place: every row, then every column.
fn fft_2d(data: &mut [Complex<f64>], width: usize, height: usize) {
    let mut planner = FftPlannerScalar::new();
    let rows = planner.plan_fft_forward(width);
    for row in data.chunks_exact_mut(width) {
        rows.process(row);
    }
    let columns = planner.plan_fft_forward(height);
    let mut column = vec![Complex::new(0.0, 0.0); height];
    for x in 0..width {
        for (y, c) in column.iter_mut().enumerate() {
            *c = data[y * width + x];
        }
        columns.process(&mut column);
        for (y, c) in column.iter().enumerate() {
            data[y * width + x] = *c;
        }
    }
}

/// The mean square of `error` blurred by a Gaussian of `sigma` pixels, over the pixels where
/// `region` is true. The kernel reaches 3σ and is normalised over the pixels inside the image,
/// so a constant error stays itself at the edges. `None` for an empty region.
pub fn lowpass_mse(
    error: &[f64],
    width: usize,
    height: usize,
    sigma: f64,
    region: &[bool],
) -> Option<f64> {
    let count = region.iter().filter(|&&r| r).count();
    if count == 0 {
        return None;
    }
    let radius = (3.0 * sigma).ceil() as isize;
    let weights: Vec<f64> = (-radius..=radius)
        .map(|d| (-(d * d) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let blur_1d = |get: &dyn Fn(isize) -> f64, at: isize, n: isize| {
        let (mut sum, mut norm) = (0.0, 0.0);
        for (i, w) in weights.iter().enumerate() {
            let p = at + i as isize - radius;
            if (0..n).contains(&p) {
                sum += w * get(p);
                norm += w;
            }
        }
        sum / norm
    };
    let (w, h) = (width as isize, height as isize);
    let mut rows = vec![0.0; error.len()];
    for y in 0..h {
        for x in 0..w {
            let get = |p: isize| error[(y * w + p) as usize];
            rows[(y * w + x) as usize] = blur_1d(&get, x, w);
        }
    }
    let mut sum = 0.0;
    for y in 0..h {
        for x in 0..w {
            if region[(y * w + x) as usize] {
                let get = |p: isize| rows[(p * w + x) as usize];
                let b = blur_1d(&get, y, h);
                sum += b * b;
            }
        }
    }
    Some(sum / count as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    /// White noise of variance 1 (uniform on ±√3).
    fn white(width: usize, height: usize, seed: u64) -> Vec<f64> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        (0..width * height)
            .map(|_| (rng.random::<f64>() * 2.0 - 1.0) * 3f64.sqrt())
            .collect()
    }

    /// The periodic Laplacian of `e`: its power is (4 − 2cos 2πfx − 2cos 2πfy)² times e's,
    /// 0 at DC, 64 at the corner: a known blue-noise pattern.
    fn laplacian(e: &[f64], width: usize, height: usize) -> Vec<f64> {
        let at = |x: usize, y: usize| e[(y % height) * width + x % width];
        (0..height)
            .flat_map(|y| {
                (0..width).map(move |x| {
                    4.0 * at(x, y)
                        - at(x + 1, y)
                        - at(x + width - 1, y)
                        - at(x, y + 1)
                        - at(x, y + height - 1)
                })
            })
            .collect()
    }

    fn mean_spectrum(images: &[Vec<f64>], width: usize, height: usize) -> Radial {
        let all = vec![true; width * height];
        let spectra: Vec<Radial> = images
            .iter()
            .map(|e| radial_power(e, width, height, &all).expect("pixels"))
            .collect();
        let k = spectra.len() as f64;
        Radial {
            power: (0..RINGS)
                .map(|i| spectra.iter().map(|s| s.power[i]).sum::<f64>() / k)
                .collect(),
            low_band: spectra.iter().map(|s| s.low_band).sum::<f64>() / k,
            all_band: spectra.iter().map(|s| s.all_band).sum::<f64>() / k,
        }
    }

    #[test]
    fn white_noise_has_a_flat_spectrum_at_its_variance() {
        let (w, h) = (128, 96);
        let images: Vec<Vec<f64>> = (0..16).map(|s| white(w, h, s)).collect();
        let s = mean_spectrum(&images, w, h);
        // Each ring holds at least a few dozen coefficients × 16 images: within 25% of 1,
        // and the whole band within 3%.
        for (i, p) in s.power.iter().enumerate() {
            assert!(
                (p - 1.0).abs() < 0.25,
                "ring {i} at {:.3}: {p}",
                ring_frequency(i)
            );
        }
        assert!((s.low_band - 1.0).abs() < 0.1, "low band {}", s.low_band);
        assert!(
            (s.low_band / s.all_band - 1.0).abs() < 0.1,
            "share {}",
            s.low_band / s.all_band
        );
        let all: f64 = s.power.iter().sum::<f64>() / RINGS as f64;
        assert!((all - 1.0).abs() < 0.03, "mean over rings {all}");
    }

    #[test]
    fn a_laplacian_of_white_noise_has_its_low_frequencies_suppressed() {
        let (w, h) = (128, 128);
        let images: Vec<Vec<f64>> = (0..8)
            .map(|s| laplacian(&white(w, h, 100 + s), w, h))
            .collect();
        let s = mean_spectrum(&images, w, h);
        // Expected power at |f| on the axis: (2 − 2cos 2πf)²; ring by ring it rises.
        let expected = |f: f64| (2.0 - 2.0 * (std::f64::consts::TAU * f).cos()).powi(2);
        let low = s.low_band;
        assert!(low < 0.2 * expected(0.5), "low band {low}");
        for i in 1..RINGS {
            assert!(
                s.power[i] > s.power[i - 1] * 0.9,
                "ring {i} falls: {:?}",
                s.power
            );
        }
        // Near the origin the power follows (2π|f|)⁴, which averages over the low band to far
        // below white noise's 1 at the same variance… per unit variance of the pattern.
        let variance: f64 =
            images.iter().flatten().map(|e| e * e).sum::<f64>() / (images.len() * w * h) as f64;
        assert!(
            low / variance < 0.05,
            "low band {low} of variance {variance}"
        );
        // And a white-noise image of the same variance is flat: the ratio the study reports.
        let white_images: Vec<Vec<f64>> = (0..8)
            .map(|s| {
                white(w, h, 200 + s)
                    .iter()
                    .map(|e| e * variance.sqrt())
                    .collect()
            })
            .collect();
        let flat = mean_spectrum(&white_images, w, h);
        assert!(
            low / flat.low_band < 0.05,
            "{low} vs white {}",
            flat.low_band
        );
    }

    #[test]
    fn a_cosine_puts_its_power_in_its_own_ring() {
        // cos(2π · 0.25 · x): all its power at |f| = 0.25, ring 16 of 32; variance ½.
        let (w, h) = (64, 64);
        let e: Vec<f64> = (0..w * h)
            .map(|i| (std::f64::consts::TAU * 0.25 * (i % w) as f64).cos())
            .collect();
        let all = vec![true; w * h];
        let s = radial_power(&e, w, h, &all).expect("pixels");
        let ring = (0.25 / 0.5 * RINGS as f64) as usize;
        for (i, p) in s.power.iter().enumerate() {
            if p.is_nan() {
                // At 64 pixels the lowest frequency is 1/64: the first ring is empty.
                assert_eq!(i, 0);
            } else if i == ring {
                assert!(*p > 1.0, "ring {i}: {p}");
            } else {
                assert!(*p < 1e-20, "ring {i}: {p}");
            }
        }
        assert!(s.low_band < 1e-20);
        assert!(radial_power(&e, w, h, &vec![false; w * h]).is_none());
    }

    #[test]
    fn the_low_pass_keeps_a_constant_and_shrinks_white_noise_by_the_kernel() {
        let (w, h) = (96, 80);
        let all = vec![true; w * h];
        let constant = vec![0.3; w * h];
        for sigma in LOWPASS_SIGMAS {
            let m = lowpass_mse(&constant, w, h, sigma, &all).expect("pixels");
            assert!((m - 0.09).abs() < 1e-12, "σ {sigma}: {m}");
        }
        // Blurred white noise of variance 1 keeps Σ g² of it: 1/(4πσ²) in the continuum.
        let e = white(w, h, 3);
        for sigma in LOWPASS_SIGMAS {
            let m = lowpass_mse(&e, w, h, sigma, &all).expect("pixels");
            let expected = 1.0 / (4.0 * std::f64::consts::PI * sigma * sigma);
            assert!(
                (m / expected - 1.0).abs() < 0.2,
                "σ {sigma}: {m} vs {expected}"
            );
        }
        assert!(lowpass_mse(&e, w, h, 1.0, &vec![false; w * h]).is_none());
    }
}
