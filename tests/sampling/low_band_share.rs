//! The low band's share of the error spectrum, seed by seed and over the seeds
//! (`variance::perceived::measure`): its mean power over 0 < |f| ≤ 1/8 over the whole disc's,
//! 0 < |f| ≤ 1/2. The study reports the mean of the seeds' shares and its 95% interval; here
//! each seed's share is measured alone (one image) and held to a value known from its
//! spectrum, and the pooled figure and interval to those seeds' shares:
//!
//! ```text
//! white noise               the low band holds its fraction of the frequencies' power: share 1
//! a cosine at |f| = 1/16    all its power in the low band: share = disc count / low-band count
//! 2×2 checkerboard + noise  power at (±1/4, ±1/4), outside the low band: share σ² / (σ² + P/D)
//! pooled                    = mean of the seeds' shares; interval within [min, max] of them
//! ```
//!
//! The counts (frequencies in the low band and in the disc) are made here from the band's
//! definition. A share turned upside down (the disc over the low band) reads 1 for white noise
//! too; the cosine and the checkerboard tell it.

use crate::common;

use glam::Vec3;
use rand::RngExt;
use raywave::variance::figures::perceived::{Perceived, measure};

/// Seeds per pattern.
const K: usize = 8;

/// The frequencies (kx, ky) of a `w` × `h` DFT with 0 < |f| ≤ `band` cycles per pixel.
fn frequencies(w: usize, h: usize, band: f64) -> usize {
    let f = |k: usize, n: usize| {
        let k = if k <= n / 2 {
            k as f64
        } else {
            k as f64 - n as f64
        };
        k / n as f64
    };
    (0..h)
        .flat_map(|ky| (0..w).map(move |kx| (f(kx, w), f(ky, h))))
        .filter(|(fx, fy)| {
            let r = (fx * fx + fy * fy).sqrt();
            r > 0.0 && r <= band
        })
        .count()
}

/// `measure` of error images `errors` against a black reference, over the whole image.
fn measured(errors: &[Vec<f64>], w: usize, h: usize) -> Perceived {
    let images: Vec<Vec<Vec3>> = errors
        .iter()
        .map(|e| e.iter().map(|&v| Vec3::splat(v as f32)).collect())
        .collect();
    let refs: Vec<&[Vec3]> = images.iter().map(|i| i.as_slice()).collect();
    measure(&refs, &vec![Vec3::ZERO; w * h], w, h, &vec![true; w * h])
}

/// Uniform noise of standard deviation `sigma`.
fn noise(w: usize, h: usize, sigma: f64, seed: u64) -> Vec<f64> {
    let mut rng = common::seeded(seed);
    (0..w * h)
        .map(|_| (rng.random::<f64>() * 2.0 - 1.0) * 3f64.sqrt() * sigma)
        .collect()
}

/// Each seed's share is within `tolerance` of `expected(seed)`; the pooled share is their
/// mean, and its interval lies within their range, around the mean and within the tolerance.
/// Returns the seeds' shares.
fn check(
    what: &str,
    errors: &[Vec<f64>],
    w: usize,
    h: usize,
    expected: impl Fn(usize) -> f64,
    tolerance: f64,
) -> Vec<f64> {
    let shares: Vec<f64> = errors
        .iter()
        .enumerate()
        .map(|(seed, e)| {
            let p = measured(std::slice::from_ref(e), w, h);
            let (share, want) = (p.low_band_share, expected(seed));
            assert!(
                (share - want).abs() <= tolerance,
                "{what}, seed {seed}: low-band share {share}, expected {want} ± {tolerance}"
            );
            assert_eq!(p.low_band_share_interval, None, "one seed has no interval");
            share
        })
        .collect();
    let pooled = measured(errors, w, h);
    let mean = shares.iter().sum::<f64>() / shares.len() as f64;
    let (lo, hi) = shares
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &s| {
            (a.min(s), b.max(s))
        });
    assert!(
        (pooled.low_band_share - mean).abs() <= 1e-12 * mean.abs().max(1.0),
        "{what}: pooled share {}, the seeds' mean {mean} (seeds {shares:?})",
        pooled.low_band_share
    );
    let [a, b] = pooled
        .low_band_share_interval
        .unwrap_or_else(|| panic!("{what}: no interval over {K} seeds"));
    let slack = 1e-12 * hi.abs().max(1.0);
    assert!(
        lo - slack <= a && a <= mean + slack && mean - slack <= b && b <= hi + slack,
        "{what}: interval [{a}, {b}] against the seeds' shares {lo}..{hi}, mean {mean}"
    );
    println!("{what}: the seeds' shares {shares:?}, pooled {mean} in [{a}, {b}]");
    let band = (0..K).map(&expected);
    let (want_lo, want_hi) = band.fold((f64::INFINITY, f64::NEG_INFINITY), |(x, y), v| {
        (x.min(v), y.max(v))
    });
    assert!(
        a >= want_lo - tolerance && b <= want_hi + tolerance,
        "{what}: interval [{a}, {b}], expected within {want_lo}..{want_hi} ± {tolerance}"
    );
    shares
}

#[test]
fn white_noise_shares_one_seed_by_seed_and_over_the_seeds() {
    // 96 × 80: 372 frequencies in the low band, 186 of them independent (the others their
    // conjugates), each an exponential power: a seed's share has a standard deviation of
    // about 1/√186 = 7%; the tolerance is four of them.
    let (w, h) = (96, 80);
    let (low, disc) = (frequencies(w, h, 0.125), frequencies(w, h, 0.5));
    assert_eq!((low, disc), (372, 6018));
    let errors: Vec<Vec<f64>> = (0..K).map(|s| noise(w, h, 0.2, 10 + s as u64)).collect();
    let shares = check("white noise", &errors, w, h, |_| 1.0, 0.3);
    // Put as fractions: the low band holds its fraction of the frequencies' power.
    for share in shares {
        let fraction_of_power = share * low as f64 / disc as f64;
        assert!(
            (fraction_of_power / (low as f64 / disc as f64) - 1.0).abs() <= 0.3,
            "{fraction_of_power}"
        );
    }
}

#[test]
fn a_low_cosine_shares_the_disc_over_the_low_band_exactly() {
    // cos(2π · 4x/64 + φ): all its power at f = (±1/16, 0), in the low band; the phase, one
    // per seed, moves none of it. Share = (P / low) / (P / disc) = disc / low.
    let (w, h) = (64, 64);
    let (low, disc) = (frequencies(w, h, 0.125), frequencies(w, h, 0.5));
    let exact = disc as f64 / low as f64;
    assert!(exact > 10.0, "{disc} / {low}");
    let errors: Vec<Vec<f64>> = (0..K)
        .map(|s| {
            let phase = s as f64 * 0.7;
            (0..w * h)
                .map(|i| (std::f64::consts::TAU * 4.0 * (i % w) as f64 / w as f64 + phase).cos())
                .collect()
        })
        .collect();
    check("a cosine at 1/16", &errors, w, h, |_| exact, 1e-9 * exact);
}

#[test]
fn a_checkerboard_shares_almost_nothing_seed_by_seed_and_over_the_seeds() {
    // Blocks of 2 × 2 pixels, ±1: all the pattern's power at (±1/4, ±1/4), |f| = 0.354, in
    // the disc and outside the low band; by Parseval it is Σ e² = the pixel count P over the
    // disc's D frequencies. White noise of σ² on top, another per seed, puts σ² everywhere:
    // share = σ² / (σ² + P / D), 0.008 here. (A checkerboard of single pixels would sit at
    // |f| = 0.707, outside the disc the spectrum measures.)
    let (w, h) = (64, 64);
    let disc = frequencies(w, h, 0.5) as f64;
    let sigma: f64 = 0.1;
    let expected = sigma * sigma / (sigma * sigma + (w * h) as f64 / disc);
    assert!(expected < 0.01, "{expected}");
    let errors: Vec<Vec<f64>> = (0..K)
        .map(|s| {
            let n = noise(w, h, sigma, 100 + s as u64);
            (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    let board = if (x / 2 + y / 2) % 2 == 0 { 1.0 } else { -1.0 };
                    board + n[i]
                })
                .collect()
        })
        .collect();
    // A seed's low band holds 196 frequencies of noise alone: its share is within 40% of the
    // expected value, and every share is far below white noise's 1.
    let shares = check(
        "a 2×2 checkerboard",
        &errors,
        w,
        h,
        |_| expected,
        0.4 * expected,
    );
    assert!(shares.iter().all(|&s| s > 0.0 && s < 0.02), "{shares:?}");
}
