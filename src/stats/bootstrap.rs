//! Intervals by bootstrap: a statistic's 95% interval from resamples of its data, drawn from a
//! fixed seed so that a report is the same on every run; grouped, for data that come in
//! blocks (seeds of one image).

/// Resamples drawn by [`bootstrap_interval`]'s callers unless they say otherwise: enough that
/// the 2.5% and 97.5% percentiles move by well under their own width between generator seeds.
pub const BOOTSTRAP_RESAMPLES: usize = 2000;

/// The generator seed callers pass to [`bootstrap_interval`], so that a report is reproducible
/// and every statistic of one report is computed on the same resamples.
pub const BOOTSTRAP_SEED: u64 = 0x5eed_b007;

/// A 95% percentile-bootstrap interval of a statistic of `n` independent units (seeds, runs):
/// `resamples` times, draw `n` unit indices with replacement (xoshiro256++ seeded with `seed`,
/// so the same call gives the same interval, and calls with the same `n` and `seed` see the
/// same resamples), evaluate `stat` on them, and return the 2.5th and 97.5th percentiles of
/// the values. NaN values are dropped; ±∞ are kept (an unbounded statistic gives an unbounded
/// end). `None` with fewer than two units, no resamples, or no value left.
///
/// ```text
/// for b in 0..resamples: idx = [uniform(0..n); n]; v[b] = stat(idx)
/// sort v; (v[⌊0.025·B⌋], v[⌈0.975·B⌉ − 1])
/// ```
///
/// The percentile interval assumes the statistic's distribution over resamples mirrors its
/// distribution over experiments; with few units (under about 10) it is too narrow.
pub fn bootstrap_interval(
    n: usize,
    resamples: usize,
    seed: u64,
    mut stat: impl FnMut(&[usize]) -> f64,
) -> Option<(f64, f64)> {
    // One group of `n`: the same draws, in the same order.
    grouped_bootstrap_interval(&[n], resamples, seed, |idx| stat(&idx[0]))
}

/// [`bootstrap_interval`] over independent groups: each resample draws, within every group
/// of `sizes[g]` units, that many units with replacement (a study's seeds, case by case), and
/// `stat` sees one index list per group. None when a group has fewer than two units.
pub fn grouped_bootstrap_interval(
    sizes: &[usize],
    resamples: usize,
    seed: u64,
    mut stat: impl FnMut(&[Vec<usize>]) -> f64,
) -> Option<(f64, f64)> {
    use rand::{RngExt, SeedableRng};
    if sizes.is_empty() || sizes.iter().any(|&n| n < 2) || resamples == 0 {
        return None;
    }
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut idx: Vec<Vec<usize>> = sizes.iter().map(|&n| vec![0; n]).collect();
    let mut values = Vec::with_capacity(resamples);
    for _ in 0..resamples {
        for (group, &n) in idx.iter_mut().zip(sizes) {
            for i in group.iter_mut() {
                *i = rng.random_range(0..n);
            }
        }
        let v = stat(&idx);
        if !v.is_nan() {
            values.push(v);
        }
    }
    percentile_interval(values)
}

/// The 2.5% and 97.5% points of `values` (NaN left out before), None when empty.
fn percentile_interval(mut values: Vec<f64>) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let b = values.len();
    let low = (b as f64 * 0.025).floor() as usize;
    let high = ((b as f64 * 0.975).ceil() as usize).clamp(1, b) - 1;
    Some((values[low.min(b - 1)], values[high]))
}

#[cfg(test)]
mod bootstrap_tests {
    use super::*;

    #[test]
    fn the_bootstrap_is_reproducible_and_brackets_the_statistic() {
        let xs: Vec<f64> = (0..20).map(|i| ((i * 37) % 20) as f64).collect();
        let mean = |idx: &[usize]| idx.iter().map(|&i| xs[i]).sum::<f64>() / idx.len() as f64;
        let a = bootstrap_interval(xs.len(), 1000, 7, mean).unwrap();
        let b = bootstrap_interval(xs.len(), 1000, 7, mean).unwrap();
        assert_eq!(a, b);
        // The sample mean is 9.5 and its standard error √(33.25/20) = 1.29: the interval is
        // about 9.5 ± 2.5.
        assert!(a.0 < 9.5 && 9.5 < a.1, "{a:?}");
        assert!(a.0 > 5.0 && a.1 < 14.0, "{a:?}");
    }

    #[test]
    fn the_bootstrap_refuses_what_it_cannot_resample() {
        assert_eq!(bootstrap_interval(1, 100, 0, |_| 1.0), None);
        assert_eq!(bootstrap_interval(5, 0, 0, |_| 1.0), None);
        assert_eq!(bootstrap_interval(5, 100, 0, |_| f64::NAN), None);
        let inf = bootstrap_interval(5, 100, 0, |_| f64::INFINITY).unwrap();
        assert_eq!(inf, (f64::INFINITY, f64::INFINITY));
    }
}
