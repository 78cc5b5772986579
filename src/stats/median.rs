//! Summaries of repeated measurements: the median, and a distribution-free interval for it.
//! One place for them, so that `raywave bench`, its A/B mode and the variance study's timings
//! summarise alike.

/// The median of `xs` (the mean of the middle two for an even count), NaN values ignored;
/// 0 when nothing is left.
pub fn median(xs: &[f64]) -> f64 {
    let mut v: Vec<f64> = xs.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        (v[m - 1] + v[m]) / 2.0
    }
}

/// The fewest values that give a 95% interval of the median (see [`median_interval_rank_at`]).
pub const MIN_FOR_INTERVAL: usize = 6;

/// The 1-based rank k of the lower end of a (1 − `alpha`) interval of the median of n values:
/// for n values sorted, the median lies between the k-th and the (n − k + 1)-th with
/// probability at least 1 − `alpha`, k the largest with P(Binomial(n, ½) < k) ≤ `alpha`/2 (the
/// sign test's interval; it assumes nothing of the distribution but independent values).
/// `None` when even the extremes do not reach that level (n below [`min_for_interval_at`]).
pub fn median_interval_rank_at(n: usize, alpha: f64) -> Option<usize> {
    debug_assert!(alpha > 0.0 && alpha < 1.0, "alpha {alpha}");
    let tail = alpha / 2.0;
    // P(X = j) for X ~ Binomial(n, ½), from j = 0, carried as a logarithm: 2^-n itself is 0
    // in f64 past n = 1074, and the terms that matter (near the tail) are not.
    let mut ln_term = -(n as f64) * std::f64::consts::LN_2;
    let mut below = 0.0; // P(X < j)
    let mut k = 0;
    for j in 0..n {
        let term = ln_term.exp();
        if below + term > tail {
            break;
        }
        below += term;
        k = j + 1;
        ln_term += ((n - j) as f64 / (j + 1) as f64).ln();
    }
    (k >= 1).then_some(k)
}

/// The fewest values that give a (1 − `alpha`) interval of the median: the smallest n whose
/// extremes already hold it (2^-n ≤ `alpha`/2).
pub fn min_for_interval_at(alpha: f64) -> usize {
    (1..)
        .find(|&n| median_interval_rank_at(n, alpha).is_some())
        .unwrap_or(usize::MAX)
}

/// The median of `xs` and its 95% interval ([`median_interval_rank_at`] at 0.05); the interval is
/// (−∞, ∞) with fewer than [`MIN_FOR_INTERVAL`] values. NaN values are ignored.
pub fn median_with_interval(xs: &[f64]) -> (f64, f64, f64) {
    median_with_interval_at(xs, 0.05)
}

/// The median of `xs` and its (1 − `alpha`) interval ([`median_interval_rank_at`]); the
/// interval is (−∞, ∞) with too few values for that level. NaN values are ignored.
pub fn median_with_interval_at(xs: &[f64], alpha: f64) -> (f64, f64, f64) {
    let mut v: Vec<f64> = xs.iter().copied().filter(|x| !x.is_nan()).collect();
    v.sort_by(f64::total_cmp);
    let (low, high) = match median_interval_rank_at(v.len(), alpha) {
        Some(k) => (v[k - 1], v[v.len() - k]),
        None => (f64::NEG_INFINITY, f64::INFINITY),
    };
    (median(&v), low, high)
}

/// The modified Z-score above which a value counts as an outlier ([`modified_z_scores`]):
/// hyperfine's rule, far beyond Iglewicz and Hoaglin's 3.5, so that only a run something else
/// clearly disturbed is flagged, not the ordinary spread of a shared machine.
pub const OUTLIER_Z: f64 = 14.0;

/// Each value's modified Z-score, 0.6745 · (x − median) / MAD (Iglewicz and Hoaglin), MAD the
/// median absolute deviation: robust, since neither the median nor the MAD moves much with one
/// wild value. When the MAD is 0 (most values equal), a value equal to the median scores 0 and
/// any other ±∞. NaN values score NaN.
fn modified_z_scores(xs: &[f64]) -> Vec<f64> {
    let m = median(xs);
    let deviations: Vec<f64> = xs.iter().map(|x| (x - m).abs()).collect();
    let mad = median(&deviations);
    xs.iter()
        .map(|&x| {
            if x.is_nan() {
                f64::NAN
            } else if mad > 0.0 {
                0.6745 * (x - m) / mad
            } else if x == m {
                0.0
            } else {
                (x - m).signum() * f64::INFINITY
            }
        })
        .collect()
}

/// The indices of the values whose modified Z-score exceeds [`OUTLIER_Z`] in magnitude.
pub fn outliers(xs: &[f64]) -> Vec<usize> {
    modified_z_scores(xs)
        .iter()
        .enumerate()
        .filter(|(_, z)| z.abs() > OUTLIER_Z)
        .map(|(i, _)| i)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rank of the 95% interval, the one the tools use.
    fn median_interval_rank(n: usize) -> Option<usize> {
        median_interval_rank_at(n, 0.05)
    }

    #[test]
    fn medians() {
        assert_eq!(median(&[]), 0.0);
        assert_eq!(median(&[3.0]), 3.0);
        assert_eq!(median(&[5.0, 1.0, 3.0]), 3.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&[f64::NAN, 4.0, 1.0, 3.0]), 3.0);
    }

    /// Exact P(Binomial(n, ½) < k), by summing coefficients in integers.
    fn below(n: usize, k: usize) -> f64 {
        let mut c = 1u128;
        let mut sum = 0u128;
        for j in 0..k {
            sum += c;
            c = c * (n - j) as u128 / (j + 1) as u128;
        }
        sum as f64 / 2f64.powi(n as i32)
    }

    #[test]
    fn the_interval_rank_is_the_largest_with_at_most_2_5_percent_below() {
        assert_eq!(median_interval_rank(5), None);
        // Tables of the sign test: n = 6 → 1, 10 → 2, 20 → 6, 30 → 10.
        assert_eq!(median_interval_rank(6), Some(1));
        assert_eq!(median_interval_rank(10), Some(2));
        assert_eq!(median_interval_rank(20), Some(6));
        assert_eq!(median_interval_rank(30), Some(10));
        for n in MIN_FOR_INTERVAL..100 {
            let k = median_interval_rank(n).unwrap();
            assert!(below(n, k) <= 0.025, "n = {n}, k = {k}");
            assert!(below(n, k + 1) > 0.025, "n = {n}, k + 1 = {}", k + 1);
        }
    }

    /// Other levels by the same rule, against the exact sums: the Bonferroni levels of
    /// `bench --until-decided` (5% over up to 12 looks) among them.
    #[test]
    fn the_interval_rank_at_other_levels() {
        assert_eq!(min_for_interval_at(0.05), MIN_FOR_INTERVAL);
        for alpha in [0.2, 0.1, 0.01, 0.05 / 9.0, 0.05 / 12.0, 0.001] {
            let first = min_for_interval_at(alpha);
            // The extremes of n values hold the median with probability 1 − 2·2^-n.
            assert!(2f64.powi(-(first as i32)) <= alpha / 2.0, "alpha {alpha}");
            assert!(
                2f64.powi(-(first as i32 - 1)) > alpha / 2.0,
                "alpha {alpha}"
            );
            assert_eq!(median_interval_rank_at(first - 1, alpha), None);
            for n in first..100 {
                let k = median_interval_rank_at(n, alpha).unwrap();
                assert!(
                    below(n, k) <= alpha / 2.0,
                    "alpha {alpha}, n = {n}, k = {k}"
                );
                assert!(
                    below(n, k + 1) > alpha / 2.0,
                    "alpha {alpha}, n = {n}, k + 1"
                );
            }
        }
        // A narrower level gives a wider interval from the same values.
        let xs: Vec<f64> = (0..40).map(|i| (i * 13 % 40) as f64).collect();
        let (_, lo95, hi95) = median_with_interval(&xs);
        let (_, lo99, hi99) = median_with_interval_at(&xs, 0.01);
        assert!(lo99 < lo95 && hi95 < hi99, "{lo99} {lo95} {hi95} {hi99}");
    }

    /// Past n = 1074, 2^-n is 0 in f64: the rank must still come from the tail's terms. The
    /// normal approximation n/2 − 1.96·√n/2 is within a rank or two there.
    #[test]
    fn the_interval_rank_of_many_values() {
        for n in [1_000usize, 2_000, 5_000, 10_000] {
            let k = median_interval_rank(n).unwrap() as f64;
            let normal = n as f64 / 2.0 - 1.959964 * (n as f64).sqrt() / 2.0;
            assert!(
                (k - normal).abs() < 2.0,
                "n = {n}: rank {k}, normal {normal}"
            );
        }
    }

    #[test]
    fn the_interval_holds_the_median() {
        let xs: Vec<f64> = (0..20).map(|i| (i * 7 % 20) as f64).collect();
        let (m, lo, hi) = median_with_interval(&xs);
        assert_eq!((m, lo, hi), (9.5, 5.0, 14.0));
        let (_, lo, hi) = median_with_interval(&[1.0; 5]);
        assert!(lo.is_infinite() && hi.is_infinite());
    }

    #[test]
    fn outliers_by_modified_z_score() {
        // Median 10.5, deviations 0.5, 0.5, 1.5, 0.5, 0.5, 89.5 -> MAD 0.5.
        let xs = [10.0, 11.0, 9.0, 10.0, 11.0, 100.0];
        let z = modified_z_scores(&xs);
        assert!((z[5] - 0.6745 * 89.5 / 0.5).abs() < 1e-9, "{z:?}");
        assert!((z[2] + 0.6745 * 1.5 / 0.5).abs() < 1e-9, "{z:?}");
        assert_eq!(outliers(&xs), [5]);
        // The ordinary spread of a shared machine: nothing flagged.
        assert!(outliers(&[10.0, 12.0, 9.0, 11.0, 13.0, 8.0]).is_empty());
        // MAD 0: only values off the median are outliers.
        assert_eq!(outliers(&[5.0, 5.0, 5.0, 7.0]), [3]);
        assert!(outliers(&[]).is_empty());
    }
}
