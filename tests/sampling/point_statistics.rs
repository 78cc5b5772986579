//! Every sampler's points tested as points: what `PointSet::stream(key).point(j)` (or
//! `PointSet::point`, for the lab's four samplers, which have no stream) hands the renderers,
//! held to what any correct sampler of its kind must give, never to the implementation's
//! constants. For all eight samplers at N = 16, 64 and 256:
//!
//! - **uniform**: each point index j of a stream on its own, over many streams, and all the
//!   points pooled on a 32 × 32 grid (fine enough to see a band along the diagonal);
//! - **independent**: u against v within a stream (correlation, ranks); a stream against the
//!   stream of the next pixel (blue noise and ZSobol: anti-correlated, the sign stated), of the
//!   next seed, bounce and light;
//! - **the diagonal band**: a stream whose two axes share their randomisation integrates the
//!   band u ≈ v worse than the same band shifted along v, which a correct stream cannot tell
//!   apart; the scrambled nets stay within Owen's variance bound on it;
//! - **each set's own construction**: `promises.rs`.
//!
//! False alarms: each test compares its statistics with critical values from their exact
//! distributions under a correct sampler (χ² for counts, the normal for means of bounded
//! per-stream values over thousands of streams), with a Bonferroni split so that each `#[test]`
//! fails a correct sampler with probability at most [`FAMILY_ALPHA`] = 1e-4: the module's seven
//! statistical tests together at most 7e-4. The streams are fixed (the seeds below), so every run
//! passes or fails the same way; a planted correlation gives statistics far past the limits.
//!
//! Every stream below has its own render seed, and the streams of a pair differ in one field:
//! ZSobol and the blue-noise tables share their randomisation across a seed's pixels on
//! purpose, and with a seed per stream their streams are independent, which the χ² needs.
//! The neighbour tests pair pixels of one seed on purpose.

mod promises;

use raywave::render::sampling::{LightSampler, PointSet, SampleKey, strata_grid};
use raywave::render::settings::{RenderSettings, ShadowMode};
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

/// The chance that a `#[test]` of this module fails a correct sampler.
const FAMILY_ALPHA: f64 = 1e-4;

/// Points per light.
const COUNTS: [u32; 3] = [16, 64, 256];

/// The image the screen-space samplers (zsobol, bluenoise) lay their streams on.
const IMAGE: (u32, u32) = (64, 64);

/// The point set of `sampler` with N = `n` on [`IMAGE`], after `RenderSettings::check_sampler` accepts it.
fn point_set(sampler: LightSampler, n: u32) -> PointSet {
    let settings = RenderSettings {
        width: IMAGE.0,
        height: IMAGE.1,
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        aa_samples: 1,
        ..RenderSettings::default()
    };
    settings
        .check_sampler()
        .expect("N = 16, 64 and 256 on a 64 × 64 image are within every limit");
    settings.point_set()
}

/// The N points of `key`'s stream, as the reference draws them: through the stream for the
/// samplers that have one, `PointSet::point` for the others.
fn points(set: &PointSet, key: &SampleKey) -> Vec<(f64, f64)> {
    let n = set.count;
    let f = |(u, v): (f32, f32)| (f64::from(u), f64::from(v));
    match set.stream(key) {
        Some(stream) => (0..n).map(|j| f(stream.point(j))).collect(),
        None => (0..n).map(|j| f(set.point(key, j))).collect(),
    }
}

/// Point `j` of `key`'s stream alone, as [`points`] draws it.
fn point(set: &PointSet, key: &SampleKey, j: u32) -> (f64, f64) {
    let (u, v) = match set.stream(key) {
        Some(stream) => stream.point(j),
        None => set.point(key, j),
    };
    (f64::from(u), f64::from(v))
}

/// The coordinates in which a point is uniform on [0, 1)²: the point itself, or for
/// `stratified`, whose point j is confined to a stratum, its offset inside that stratum.
fn uniform_frame(sampler: LightSampler, n: u32, (u, v): (f64, f64)) -> (f64, f64) {
    if sampler == LightSampler::Stratified {
        let (nx, ny) = strata_grid(n);
        ((u * nx as f64).fract(), (v * ny as f64).fract())
    } else {
        (u, v)
    }
}

/// A small integer mix for spreading the streams over the image (the test's own, so that no
/// stream layout follows the sampler's hashing).
fn spread(t: u32) -> u32 {
    let mut z = u64::from(t).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 31)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    (z >> 32) as u32
}

/// Stream `t` of the module's independent streams: its own seed, a pixel spread over the
/// image, bounces 0–2 and lights 0–1 in turn.
fn stream_key(t: u32) -> SampleKey {
    SampleKey {
        pixel: spread(t) % (IMAGE.0 * IMAGE.1),
        sample: 0,
        bounce: t % 3,
        light: (t / 3) % 2,
        seed: 1000 + t,
    }
}

/// The bin of x ∈ [0, 1) among `k`.
fn bin(x: f64, k: usize) -> usize {
    ((x * k as f64) as usize).min(k - 1)
}

/// Pearson's χ² of `counts` against equal expectations.
fn chi2(counts: &[u32]) -> f64 {
    let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
    let e = total as f64 / counts.len() as f64;
    assert!(e >= 5.0, "{e:.1} expected per cell: too few for χ²");
    counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum()
}

/// The upper `alpha` point of χ² with `dof` degrees of freedom.
fn chi2_limit(dof: usize, alpha: f64) -> f64 {
    let d = ChiSquared::new(dof as f64).expect("positive degrees of freedom");
    upper_point(|x| d.sf(x), alpha)
}

/// The upper `alpha` point of the standard normal.
fn z_limit(alpha: f64) -> f64 {
    let d = Normal::standard();
    upper_point(|x| d.sf(x), alpha)
}

/// The x where a decreasing survival function `sf` falls to `alpha`, by bisection (the
/// quantile functions lose their precision so far out in the tail).
fn upper_point(sf: impl Fn(f64) -> f64, alpha: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    while sf(hi) > alpha {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if sf(mid) > alpha { lo = mid } else { hi = mid }
    }
    hi
}

/// Mean and standard error of `values`.
fn mean_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Pairs whose two sides are independent and each uniform on [0, 1): χ² of their 8 × 8 joint
/// histogram (63 degrees of freedom).
fn independence_chi2(pairs: &[(f64, f64)]) -> f64 {
    let mut counts = [0u32; 64];
    for &(a, b) in pairs {
        counts[bin(b, 8) * 8 + bin(a, 8)] += 1;
    }
    chi2(&counts)
}

/// The statistics of one test past their limits, reported together: a failure names every
/// sampler and N it touches.
#[derive(Default)]
struct Failures(Vec<String>);

impl Failures {
    fn check(&mut self, ok: bool, what: impl FnOnce() -> String) {
        if !ok {
            self.0.push(what());
        }
    }

    fn assert_none(self) {
        assert!(
            self.0.is_empty(),
            "{} statistics past their limits:\n{}",
            self.0.len(),
            self.0.join("\n")
        );
    }
}

/// Streams per point index in the uniformity test: 10 per cell of its 16 × 16 grid.
const UNIFORM_STREAMS: u32 = 2560;

#[test]
fn every_point_index_is_uniform_on_the_square_over_streams() {
    // Point j of a stream, over 2560 independent streams, on a 16 × 16 grid: one χ² per
    // (sampler, N, j), 255 degrees of freedom; 8 × (16 + 64 + 256) statistics share the
    // family's α. A sampler whose axes share a digit's randomisation fails at the indices
    // whose digits line up (Halton's j ≡ 1 mod 3), one digital shift for both axes at every j.
    let mut failures = Failures::default();
    let statistics = LightSampler::ALL.len() * COUNTS.iter().sum::<u32>() as usize;
    let limit = chi2_limit(255, FAMILY_ALPHA / statistics as f64);
    for sampler in LightSampler::ALL {
        for n in COUNTS {
            let set = point_set(sampler, n);
            let mut counts = vec![[0u32; 256]; n as usize];
            for t in 0..UNIFORM_STREAMS {
                for (j, p) in points(&set, &stream_key(t)).into_iter().enumerate() {
                    let (u, v) = uniform_frame(sampler, n, p);
                    counts[j][bin(v, 16) * 16 + bin(u, 16)] += 1;
                }
            }
            let (j, x) = counts
                .iter()
                .map(|c| chi2(c))
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .expect("N > 0");
            failures.check(x < limit, || {
                format!(
                    "{} N = {n}: point {j} over {UNIFORM_STREAMS} streams has χ² = {x:.0} ≥ {limit:.0} \
                     (255 dof, 16 × 16 cells): not uniform on the square",
                    sampler.name()
                )
            });
        }
    }
    failures.assert_none();
}

#[test]
fn pooled_points_are_uniform_on_a_32_by_32_grid() {
    // All the points of 2560 streams, pooled: χ² on 32 × 32 cells (1023 dof, at least 40
    // expected per cell), 24 statistics. The rate is exact for independent points (random,
    // lab); the other sets spread a stream's points more evenly than independent ones, so their
    // counts vary less and their χ² is smaller still. A diagonal band of excess or deficit
    // shows here.
    let mut failures = Failures::default();
    let limit = chi2_limit(1023, FAMILY_ALPHA / 24.0);
    for sampler in LightSampler::ALL {
        for n in COUNTS {
            let set = point_set(sampler, n);
            let mut counts = vec![0u32; 1024];
            for t in 0..UNIFORM_STREAMS {
                for (u, v) in points(&set, &stream_key(t)) {
                    counts[bin(v, 32) * 32 + bin(u, 32)] += 1;
                }
            }
            let x = chi2(&counts);
            failures.check(x < limit, || {
                format!(
                    "{} N = {n}: χ² = {x:.0} ≥ {limit:.0} (1023 dof) over {} pooled points",
                    sampler.name(),
                    UNIFORM_STREAMS * n
                )
            });
        }
    }
    failures.assert_none();
}

/// Independent streams in the tests of the diagonal band.
const STREAM_STREAMS: u32 = 4096;

/// Independent streams in the test of a stream's own u against v.
const RANK_STREAMS: u32 = 2048;

/// The ranks of `values` among themselves (0 for the smallest).
fn ranks(values: impl Iterator<Item = f64>) -> Vec<usize> {
    let mut order: Vec<(f64, usize)> = values.enumerate().map(|(i, x)| (x, i)).collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut rank = vec![0; order.len()];
    for (r, &(_, i)) in order.iter().enumerate() {
        rank[i] = r;
    }
    rank
}

#[test]
fn u_and_v_of_a_stream_are_independent() {
    // Per stream, the sample correlation 12 · mean (u − ½)(v − ½) (mean 0 whenever each point
    // is uniform), its mean over 2048 streams against the normal (two-sided); and the ranks of
    // u and of v within the stream on an 8 × 8 histogram pooled over the streams, χ² with
    // 49 dof (its margins are fixed). 2 × 24 statistics.
    let mut failures = Failures::default();
    let alpha = FAMILY_ALPHA / 48.0;
    let (z_max, rank_limit) = (z_limit(alpha / 2.0), chi2_limit(49, alpha));
    for sampler in LightSampler::ALL {
        for n in COUNTS {
            let set = point_set(sampler, n);
            let mut corr = Vec::new();
            let mut counts = [0u32; 64];
            for t in 0..RANK_STREAMS {
                let p = points(&set, &stream_key(t));
                corr.push(
                    12.0 * p.iter().map(|(u, v)| (u - 0.5) * (v - 0.5)).sum::<f64>() / n as f64,
                );
                let (ru, rv) = (ranks(p.iter().map(|q| q.0)), ranks(p.iter().map(|q| q.1)));
                for (a, b) in ru.into_iter().zip(rv) {
                    counts[b * 8 / n as usize * 8 + a * 8 / n as usize] += 1;
                }
            }
            let (mean, se) = mean_se(&corr);
            failures.check((mean / se).abs() < z_max, || {
                format!(
                    "{} N = {n}: u and v correlated: mean r = {mean:.4} ± {se:.4}, |z| ≥ {z_max:.2}",
                    sampler.name()
                )
            });
            // Every row and column holds N/8 ranks of each stream: the expectation of each
            // cell is the product of its margins, the same for all.
            let x = chi2(&counts);
            failures.check(x < rank_limit, || {
                format!(
                    "{} N = {n}: ranks of u and v: χ² = {x:.0} ≥ {rank_limit:.0} (49 dof)",
                    sampler.name()
                )
            });
        }
    }
    failures.assert_none();
}

/// The shift along v under which a sampler's streams are symmetric: ½ for the base-2
/// constructions, the rotations and the random ones (a flip of v's top bit, a half turn);
/// ⅓ for Halton, whose v is a scrambled base-3 radical inverse (its top digit moved by one).
fn symmetry_shift(sampler: LightSampler) -> f64 {
    if sampler == LightSampler::Halton {
        1.0 / 3.0
    } else {
        0.5
    }
}

/// The fraction of `points` in the band where u and v + `shift` (mod 1) fall in the same
/// column and row of the 2^k × 2^k grid: area 2^-k.
fn band(points: &[(f64, f64)], k: u32, shift: f64) -> f64 {
    let cells = f64::from(1u32 << k);
    let inside = points
        .iter()
        .filter(|(u, v)| (u * cells) as u64 == (((v + shift) % 1.0) * cells) as u64)
        .count();
    inside as f64 / points.len() as f64
}

/// The levels k of the diagonal band tested at N = 2^m: 2^-1 to 2^-(m+2).
fn band_levels(n: u32) -> std::ops::RangeInclusive<u32> {
    1..=n.trailing_zeros() + 2
}

/// One band level's (z, mean, standard error) of [`band_asymmetry`], or `None`.
type Asymmetry = Option<(f64, f64, f64)>;

/// For each band level, z of the per-stream difference (band − 2^-k)² − (shifted band −
/// 2^-k)² over `STREAM_STREAMS` streams, its mean, and its standard error; `None` where
/// both squared errors are the same in every stream (a net fixes both bands' counts).
fn band_asymmetry(sampler: LightSampler, n: u32) -> Vec<(u32, Asymmetry)> {
    let set = point_set(sampler, n);
    let shift = symmetry_shift(sampler);
    let levels: Vec<u32> = band_levels(n).collect();
    let mut w = vec![Vec::with_capacity(STREAM_STREAMS as usize); levels.len()];
    for t in 0..STREAM_STREAMS {
        let p = points(&set, &stream_key(t));
        for (i, &k) in levels.iter().enumerate() {
            let mu = 1.0 / f64::from(1u32 << k);
            w[i].push((band(&p, k, 0.0) - mu).powi(2) - (band(&p, k, shift) - mu).powi(2));
        }
    }
    levels
        .into_iter()
        .zip(w)
        .map(|(k, w)| {
            let (mean, se) = mean_se(&w);
            (k, (se > 0.0 || mean != 0.0).then(|| (mean / se, mean, se)))
        })
        .collect()
}

/// The diagonal-band statistics of every sampler but ZSobol (see
/// `zsobol_integrates_the_diagonal_band_as_well_as_its_shifted_copy`).
fn band_statistics() -> usize {
    COUNTS
        .iter()
        .map(|&n| band_levels(n).count())
        .sum::<usize>()
        * (LightSampler::ALL.len() - 1)
}

#[test]
fn the_diagonal_band_is_integrated_as_well_as_its_shifted_copy() {
    // A stream's two axes randomised independently (Owen scrambles, digital shifts, rotations,
    // independent jitter) make its law unchanged when v alone is shifted by `symmetry_shift`:
    // its estimate of the diagonal band's area is then exactly as good as of the shifted band's.
    // Axes that share their randomisation keep the unscrambled set's relation between u and v,
    // and the diagonal band, where u and v share their leading digits, is integrated worse.
    // One-sided z over 4096 streams at each level 2^-1 to 2^-(m+2); ZSobol is in its own test.
    let mut failures = Failures::default();
    let z_max = z_limit(FAMILY_ALPHA / band_statistics() as f64);
    for sampler in LightSampler::ALL {
        if sampler == LightSampler::Zsobol {
            continue;
        }
        for n in COUNTS {
            for (k, stat) in band_asymmetry(sampler, n) {
                let Some((z, mean, se)) = stat else { continue };
                failures.check(z < z_max, || {
                    format!(
                        "{} N = {n}: the diagonal band of width 2^-{k} is integrated worse than its \
                         shifted copy: mean excess squared error {mean:.3e} ± {se:.1e}, z = {z:.1} \
                         ≥ {z_max:.2}: u and v share their randomisation",
                        sampler.name()
                    )
                });
            }
        }
    }
    failures.assert_none();
}

/// ZSobol on the same test. It failed while `zsobol::owen_scramble` was Burley's (2020)
/// original Laine–Karras hash, which left part of the Sobol sequence's own relation between
/// dimensions 0 and 1 in the scrambled points: z = 22, 32 and 27 at N = 16, 64 and 256 on the
/// first band the net leaves free (4096 streams), 7 to 10 on the finest.
#[test]
fn zsobol_integrates_the_diagonal_band_as_well_as_its_shifted_copy() {
    let mut failures = Failures::default();
    let z_max = z_limit(FAMILY_ALPHA / band_statistics() as f64);
    for n in COUNTS {
        for (k, stat) in band_asymmetry(LightSampler::Zsobol, n) {
            let Some((z, mean, se)) = stat else { continue };
            failures.check(z < z_max, || {
                format!(
                    "zsobol N = {n}: band 2^-{k}: mean excess squared error {mean:.3e} ± {se:.1e}, \
                     z = {z:.1} ≥ {z_max:.2}"
                )
            });
        }
    }
    failures.assert_none();
}

#[test]
fn scrambled_nets_stay_within_owens_variance_bound() {
    // A (0, m, 2)-net in base 2 whose two axes are Owen-scrambled independently integrates
    // any f with variance at most 2σ²/N (Owen 1997: (b / (b − 1))^(s−1) times Monte Carlo's).
    // Sobol's and ZSobol's streams are such nets. The integrand: the diagonal band one level
    // finer than the net's square cells (2^-(m/2+1)), the first the net leaves free. One-sided
    // z of the mean squared error over 4096 streams against the bound, 6 statistics. Axes
    // scrambled alike keep the count in that band fixed by the unscrambled set: 2.3 to 8 times
    // Monte Carlo's variance.
    let mut failures = Failures::default();
    let z_max = z_limit(FAMILY_ALPHA / 6.0);
    for sampler in [LightSampler::Sobol, LightSampler::Zsobol] {
        for n in COUNTS {
            let set = point_set(sampler, n);
            let k = n.trailing_zeros() / 2 + 1;
            let mu = 1.0 / f64::from(1u32 << k);
            let bound = 2.0 * mu * (1.0 - mu) / f64::from(n);
            let errors: Vec<f64> = (0..STREAM_STREAMS)
                .map(|t| (band(&points(&set, &stream_key(t)), k, 0.0) - mu).powi(2))
                .collect();
            let (mse, se) = mean_se(&errors);
            failures.check(mse <= bound + z_max * se, || {
                format!(
                    "{} N = {n}: the diagonal band 2^-{k} has MSE {mse:.3e} ± {se:.1e}, {:.2}× Monte \
                     Carlo's, above Owen's bound of 2× for scrambled nets (z ≥ {z_max:.2}): u and v \
                     not scrambled independently",
                    sampler.name(),
                    mse / (bound / 2.0)
                )
            });
        }
    }
    failures.assert_none();
}

/// One coordinate of two streams' points, (a, b), per stream pair.
type Pairs = Vec<(f64, f64)>;

/// Stream pairs in the tests across pixels, seeds, bounces and lights.
const PAIRS: u32 = 4096;

/// Independent pairs (a, b) of uniform coordinates from `PAIRS` stream pairs, one point
/// index each (j = t mod N, so all N indices take part): u of both, and v of both.
fn paired_points(
    sampler: LightSampler,
    n: u32,
    pair: impl Fn(u32) -> (SampleKey, SampleKey),
) -> (Pairs, Pairs) {
    let set = point_set(sampler, n);
    let (mut us, mut vs) = (Vec::new(), Vec::new());
    for t in 0..PAIRS {
        let (a, b) = pair(t);
        let j = t % n;
        let p = uniform_frame(sampler, n, point(&set, &a, j));
        let q = uniform_frame(sampler, n, point(&set, &b, j));
        us.push((p.0, q.0));
        vs.push((p.1, q.1));
    }
    (us, vs)
}

#[test]
fn streams_of_the_next_seed_bounce_and_light_are_independent() {
    // Point j of a stream against point j of the stream with the next seed, bounce or light
    // (all else equal), one j per pair of 4096: χ² of the 8 × 8 joint histogram of u against
    // u and of v against v, 8 × 3 × 3 × 2 = 144 statistics. A stream shared by two lights puts
    // every pair on the diagonal.
    let mut failures = Failures::default();
    let limit = chi2_limit(63, FAMILY_ALPHA / 144.0);
    type Next = fn(SampleKey) -> SampleKey;
    let fields: [(&str, Next); 3] = [
        ("seed", |k| SampleKey {
            seed: k.seed + 1,
            ..k
        }),
        ("bounce", |k| SampleKey {
            bounce: k.bounce + 1,
            ..k
        }),
        ("light", |k| SampleKey { light: 1, ..k }),
    ];
    for sampler in LightSampler::ALL {
        for n in COUNTS {
            for (field, next) in fields {
                let (us, vs) = paired_points(sampler, n, |t| {
                    let a = SampleKey {
                        light: 0,
                        ..stream_key(t)
                    };
                    (a, next(a))
                });
                for (axis, pairs) in [("u", us), ("v", vs)] {
                    let x = independence_chi2(&pairs);
                    failures.check(x < limit, || {
                        format!(
                            "{} N = {n}: {axis} of the next {field}'s stream depends on this one's: \
                             χ² = {x:.0} ≥ {limit:.0} (63 dof, {PAIRS} pairs)",
                            sampler.name()
                        )
                    });
                }
            }
        }
    }
    failures.assert_none();
}

/// Stream t's pixel and the one to its right, on one seed (the pixels' relation is what is
/// tested), `even` for a left pixel in an even column: the two share a ZSobol Morton quad.
fn neighbours(t: u32, even: bool) -> (SampleKey, SampleKey) {
    let (w, h) = IMAGE;
    let x = if even {
        2 * (spread(t) % (w / 2))
    } else {
        2 * (spread(t) % (w / 2 - 1)) + 1
    };
    let y = spread(t ^ 0x5555) % h;
    let a = SampleKey {
        pixel: y * w + x,
        ..stream_key(t)
    };
    (
        a,
        SampleKey {
            pixel: a.pixel + 1,
            ..a
        },
    )
}

#[test]
fn neighbouring_pixels_are_independent_or_anti_correlated_as_designed() {
    // Pixel p against pixel p + 1 of the same seed, bounce and light.
    // - The samplers that randomise every pixel on its own: point j against point j, χ² of the
    //   8 × 8 joint histogram (u and v), one j per pair of 4096.
    // - Blue noise: its tables are optimised so that neighbours' points avoid each other;
    //   expected sign negative: z of the per-pair correlation below −z_α.
    // - ZSobol: the two pixels of a Morton quad take complementary halves of one net, so
    //   their estimates (here of the triangle u + v < 0.8, area 0.32) are anti-correlated;
    //   expected sign negative, likewise.
    let mut failures = Failures::default();
    let independent = [
        LightSampler::Random,
        LightSampler::Stratified,
        LightSampler::Sobol,
        LightSampler::Lab,
        LightSampler::Halton,
        LightSampler::Pmj02,
    ];
    let statistics = independent.len() * 3 * 2 + 2 * 3;
    let alpha = FAMILY_ALPHA / statistics as f64;
    let (limit, z_min) = (chi2_limit(63, alpha), -z_limit(alpha));
    for n in COUNTS {
        for sampler in independent {
            let (us, vs) = paired_points(sampler, n, |t| neighbours(t, t % 2 == 0));
            for (axis, pairs) in [("u", us), ("v", vs)] {
                let x = independence_chi2(&pairs);
                failures.check(x < limit, || {
                    format!(
                        "{} N = {n}: {axis} of pixel p + 1 depends on pixel p's: χ² = {x:.0} ≥ \
                         {limit:.0} (63 dof, {PAIRS} pairs)",
                        sampler.name()
                    )
                });
            }
        }
        let set = point_set(LightSampler::Bluenoise, n);
        let corr: Vec<f64> = (0..PAIRS)
            .map(|t| {
                let (a, b) = neighbours(t, t % 2 == 0);
                let (p, q) = (points(&set, &a), points(&set, &b));
                let c: f64 = p
                    .iter()
                    .zip(&q)
                    .map(|(p, q)| (p.0 - 0.5) * (q.0 - 0.5) + (p.1 - 0.5) * (q.1 - 0.5))
                    .sum();
                6.0 * c / f64::from(n)
            })
            .collect();
        let (mean, se) = mean_se(&corr);
        failures.check(mean / se < z_min, || {
            format!(
                "bluenoise N = {n}: neighbours' points are not anti-correlated: mean r = {mean:.4} ± \
                 {se:.4}, z = {:.1}, expected below {z_min:.2}",
                mean / se
            )
        });
        let set = point_set(LightSampler::Zsobol, n);
        let triangle = |p: &[(f64, f64)]| {
            p.iter().filter(|(u, v)| u + v < 0.8).count() as f64 / p.len() as f64 - 0.32
        };
        let products: Vec<f64> = (0..PAIRS)
            .map(|t| {
                let (a, b) = neighbours(t, true);
                triangle(&points(&set, &a)) * triangle(&points(&set, &b))
            })
            .collect();
        let (mean, se) = mean_se(&products);
        failures.check(mean / se < z_min, || {
            format!(
                "zsobol N = {n}: the errors of a Morton quad's neighbours are not anti-correlated: \
                 mean product {mean:.3e} ± {se:.1e}, z = {:.1}, expected below {z_min:.2}",
                mean / se
            )
        });
    }
    failures.assert_none();
}
