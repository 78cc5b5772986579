//! What a study fits across budgets and samplers, each with a 95% interval by bootstrap over
//! the seeds (`stats::bootstrap_interval`; every statistic sees the same resamples): the
//! slope of log MSE against log N, the budget matching the lab's 150 random points, and each
//! sampler's error and efficiency relative to random.
//!
//! ```text
//! fitted(sampler, region) = its rows minus those excluded_from_fit (seed-independent: bias)
//! slope    = least squares of log10 MSE on log10 N over fitted
//! matching = N where sampler's line reaches random's line at N = 150, both fitted on the
//!            budgets both have (so lab, random above N = 1, matches at exactly 150)
//! resample = K seeds drawn with replacement; MSE(N) = mean of the drawn seeds' MSE
//! ```

use crate::render::sampling::LightSampler;
use crate::stats::{BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, bootstrap_interval, median};
use crate::stats::{LogLogFit, loglog_fit};
use crate::variance::{Region, Row};
use serde::Serialize;

/// The lab's budget of random points that [`Matching`] is about.
pub(crate) const LAB_RANDOM_POINTS: f64 = 150.0;

/// The fitted slope for a (sampler, region).
#[derive(Clone, Debug, Serialize)]
pub struct Slope {
    /// Sampler name.
    pub sampler: &'static str,
    /// Region.
    pub region: Region,
    /// The fit (None with fewer than two fitted budgets with non-zero MSE).
    pub fit: Option<LogLogFit>,
    /// 95% interval of the slope (bootstrap over seeds).
    pub slope_interval: Option<[f64; 2]>,
    /// The budgets fitted.
    pub fitted: Vec<u32>,
    /// The budgets left out (see [`Row::excluded_from_fit`]).
    pub excluded: Vec<u32>,
}

/// The budget at which a sampler's fitted MSE equals random's fitted MSE at
/// `LAB_RANDOM_POINTS`, for a (sampler, region).
#[derive(Clone, Debug, Serialize)]
pub struct Matching {
    /// Sampler name.
    pub sampler: &'static str,
    /// Region.
    pub region: Region,
    /// The random budget matched.
    pub random_n: f64,
    /// The matching budget (None without both fits, or when the sampler's error does not fall).
    pub budget: Option<f64>,
    /// 95% interval (bootstrap over seeds); an end of `null` in JSON is unbounded.
    pub interval: Option<[f64; 2]>,
}

/// The mean of `xs` over the indices `idx` (all of `xs` when `idx` is None).
pub(crate) fn mean_at(xs: &[f64], idx: Option<&[usize]>) -> f64 {
    match idx {
        Some(idx) => idx.iter().map(|&i| xs[i]).sum::<f64>() / idx.len().max(1) as f64,
        None => xs.iter().sum::<f64>() / xs.len().max(1) as f64,
    }
}

/// The log-log fit of `rows` (one sampler and region, the fitted budgets), on the seeds `idx`
/// (a bootstrap resample) or on the rows' own MSE.
pub(crate) fn fit_rows(rows: &[&Row], idx: Option<&[usize]>) -> Option<LogLogFit> {
    let mse = |r: &Row| idx.map_or(r.stats.mse, |_| mean_at(&r.seed_mse, idx));
    let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.n as f64, mse(r))).collect();
    loglog_fit(&pts)
}

/// The N at which `other`'s line reaches `random`'s MSE at `random_n`; +∞ when `other`'s
/// error does not fall with N.
pub fn match_budget(random: LogLogFit, other: LogLogFit, random_n: f64) -> f64 {
    let target = random.intercept + random.slope * random_n.log10();
    if other.slope < 0.0 {
        10f64.powf((target - other.intercept) / other.slope)
    } else {
        f64::INFINITY
    }
}

/// A bootstrap interval over `k` seeds with the study's resamples and seed.
pub(crate) fn interval(k: usize, stat: impl FnMut(&[usize]) -> f64) -> Option<[f64; 2]> {
    bootstrap_interval(k, BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, stat).map(|(a, b)| [a, b])
}

/// The rows of `a` whose budget `b` also has.
fn common<'r>(a: &[&'r Row], b: &[&Row]) -> Vec<&'r Row> {
    a.iter()
        .filter(|r| b.iter().any(|o| o.n == r.n))
        .copied()
        .collect()
}

/// The rows fitted for `sampler` in `region`.
pub(crate) fn fitted(rows: &[Row], sampler: LightSampler, region: Region) -> Vec<&Row> {
    rows.iter()
        .filter(|r| r.sampler == sampler.name() && r.region == region && !r.excluded_from_fit)
        .collect()
}

/// One slope per (sampler, region), with its interval over `k` seeds.
pub(crate) fn slopes(rows: &[Row], samplers: &[LightSampler], k: usize) -> Vec<Slope> {
    let mut out = Vec::new();
    for &sampler in samplers {
        for region in Region::ALL {
            let (pts, excluded): (Vec<&Row>, Vec<&Row>) = rows
                .iter()
                .filter(|r| r.sampler == sampler.name() && r.region == region)
                .partition(|r| !r.excluded_from_fit);
            let fit = fit_rows(&pts, None);
            let slope_interval = fit.and_then(|_| {
                interval(k, |idx| {
                    fit_rows(&pts, Some(idx)).map_or(f64::NAN, |f| f.slope)
                })
            });
            out.push(Slope {
                sampler: sampler.name(),
                region,
                fit,
                slope_interval,
                fitted: pts.iter().map(|r| r.n).collect(),
                excluded: excluded.iter().map(|r| r.n).collect(),
            });
        }
    }
    out
}

/// The samplers compared with random: every other one, when random is studied; none otherwise.
pub(crate) fn against_random(samplers: &[LightSampler]) -> impl Iterator<Item = LightSampler> {
    let random = samplers.contains(&LightSampler::Random);
    samplers
        .iter()
        .copied()
        .filter(move |&s| random && s != LightSampler::Random)
}

/// One matching budget per (sampler other than random, region), when random was studied.
pub(crate) fn matching(rows: &[Row], samplers: &[LightSampler], k: usize) -> Vec<Matching> {
    let mut out = Vec::new();
    for sampler in against_random(samplers) {
        for region in Region::ALL {
            let (random, other) = (
                fitted(rows, LightSampler::Random, region),
                fitted(rows, sampler, region),
            );
            let (random, other) = (common(&random, &other), common(&other, &random));
            let budget = fit_rows(&random, None)
                .zip(fit_rows(&other, None))
                .map(|(r, o)| match_budget(r, o, LAB_RANDOM_POINTS));
            let interval = budget.and_then(|_| {
                interval(k, |idx| {
                    fit_rows(&random, Some(idx))
                        .zip(fit_rows(&other, Some(idx)))
                        .map_or(f64::NAN, |(r, o)| match_budget(r, o, LAB_RANDOM_POINTS))
                })
            });
            out.push(Matching {
                sampler: sampler.name(),
                region,
                random_n: LAB_RANDOM_POINTS,
                budget: budget.filter(|b| b.is_finite()),
                interval,
            });
        }
    }
    out
}

/// Efficiency 1/(mean MSE × median time) of `row` on the seeds `idx`.
pub(crate) fn efficiency_at(row: &Row, idx: &[usize]) -> f64 {
    let t: Vec<f64> = idx.iter().map(|&i| row.seed_seconds[i]).collect();
    1.0 / (mean_at(&row.seed_mse, Some(idx)) * median(&t).max(1e-12))
}

/// Calls `f` with every row that random has a row beside (at the same N and region), and a
/// copy of that row of random's taken before any row changed.
pub(crate) fn with_random(rows: &mut [Row], mut f: impl FnMut(&mut Row, &Row)) {
    let random: Vec<Row> = rows
        .iter()
        .filter(|r| r.sampler == LightSampler::Random.name())
        .cloned()
        .collect();
    for row in rows.iter_mut() {
        if let Some(base) = random
            .iter()
            .find(|r| r.n == row.n && r.region == row.region)
        {
            f(row, base);
        }
    }
}

/// Fills every row's error reduction (random's MSE over its own) and efficiency relative to
/// random's, at the same N and region, with their intervals (the same seeds resampled for
/// both: seed k of every sampler ran in round k, so a slow round slows both).
pub(crate) fn ratios_to_random(rows: &mut [Row], k: usize) {
    with_random(rows, |row, base| {
        row.efficiency_vs_random = Some(row.efficiency / base.efficiency);
        row.error_reduction = Some(base.stats.mse / row.stats.mse);
        let this: &Row = row;
        let efficiency = interval(k, |idx| efficiency_at(this, idx) / efficiency_at(base, idx));
        let error = interval(k, |idx| {
            mean_at(&base.seed_mse, Some(idx)) / mean_at(&this.seed_mse, Some(idx))
        });
        row.efficiency_vs_random_interval = efficiency;
        row.error_reduction_interval = error;
    });
}
