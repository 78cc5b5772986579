//! The verdicts of `raywave bench`: one set of words for both ways it compares two builds.
//!
//! ```text
//!               bench --compare (two records)       bench --against (paired rounds)
//! evidence      each median's 95% interval           the 95% interval of the median ratio
//!               (or a planned look's, --until-decided)
//! slower        change < −t and after.high < before.low       interval above 1 + t
//! faster        change > +t and after.low > before.high       interval below 1 / (1 + t) ¹
//! within        |change| ≤ t                                  interval in [1/(1 + t), 1 + t] ¹
//! not slower    —                                             interval at or below 1 + t ²
//! undecided     |change| > t, intervals overlap               interval across a boundary
//!               ¹ --verdict three-way   ² --verdict regression, the default
//! ```
//!
//! Either half of the record rule alone is not enough: a large change with overlapping
//! intervals is noise a few runs could produce, a small change with separate intervals is real
//! but below what the threshold says matters. Rates are higher-is-better for records; ratios
//! are this build's time over the other's (lower is better). Slower is a regression (exit 3)
//! in both.

use crate::output::bench_record::FigureSummary;
use crate::stats::median_with_interval_at;

/// What a rule says of one figure: the same five words for `bench --compare` and `--against`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The whole interval lies above 1 + t: a regression.
    Slower,
    /// The whole interval lies at or below 1 + t: not a regression (the one-sided form).
    NotSlower,
    /// The whole interval lies below 1 / (1 + t) (the three-way form).
    Faster,
    /// The whole interval lies within [1 / (1 + t), 1 + t] (the three-way form).
    Within,
    /// The interval straddles a boundary: more rounds are needed to decide.
    Undecided,
}

impl Verdict {
    /// The verdict in one or two words, as tables and each look of `--until-decided` print it.
    pub fn word(self) -> &'static str {
        match self {
            Verdict::Slower => "slower",
            Verdict::NotSlower => "not slower",
            Verdict::Faster => "faster",
            Verdict::Within => "within",
            Verdict::Undecided => "undecided",
        }
    }

    /// The word as a table's verdict column shows it: a regression in capitals, to stand out.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Slower => "SLOWER",
            other => other.word(),
        }
    }
}

/// Which verdicts `--against` can reach (`--verdict`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VerdictForm {
    /// One-sided, a pull request's gate: slower by more than the threshold, or not.
    #[default]
    Regression,
    /// Slower, faster, or no change beyond the threshold.
    ThreeWay,
}

/// The verdict rule of `--against`: a threshold and the form of the verdict.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    /// Regression threshold in percent.
    pub threshold_pct: f64,
    /// Which verdicts the rule can reach.
    pub form: VerdictForm,
}

#[cfg(test)]
impl Rule {
    // For the tests: the command line builds its `Rule` whole.

    /// The pull-request gate's rule at `threshold_pct`: one-sided, a regression or not.
    pub fn regression(threshold_pct: f64) -> Rule {
        Rule {
            threshold_pct,
            form: VerdictForm::Regression,
        }
    }

    /// `--verdict three-way` at `threshold_pct`: slower, faster or no change beyond it.
    pub fn three_way(threshold_pct: f64) -> Rule {
        Rule {
            threshold_pct,
            form: VerdictForm::ThreeWay,
        }
    }
}

impl Rule {
    /// The verdict of an interval [`low`, `high`] of the ratio this / other.
    ///
    /// "Slower by more than t" needs the whole interval above 1 + t (strictly: a low end at
    /// 1 + t is no evidence of more than t); "not slower by more than t" needs it at or below
    /// 1 + t, since a median of exactly 1 + t is not more than t. So the two one-sided calls
    /// split the line at 1 + t between them, and an interval that holds the median sits on
    /// the true side of it. An unbounded interval (too few rounds) reaches neither.
    pub fn judge(self, low: f64, high: f64) -> Verdict {
        let slow = 1.0 + self.threshold_pct / 100.0;
        if low > slow {
            return Verdict::Slower;
        }
        match self.form {
            VerdictForm::Regression if high <= slow => Verdict::NotSlower,
            VerdictForm::ThreeWay if high < 1.0 / slow => Verdict::Faster,
            VerdictForm::ThreeWay if low >= 1.0 / slow && high <= slow => Verdict::Within,
            _ => Verdict::Undecided,
        }
    }
}

/// The rule, on the summaries of one figure before and after (rates: higher is better).
/// A figure without an interval on either side, or whose `after` median is not a positive
/// finite rate, is decided by `compare::compare` before this is called.
pub fn of_records(before: &FigureSummary, after: &FigureSummary, threshold_pct: f64) -> Verdict {
    let change = change_pct(before.median, after.median);
    let (Some(bl), Some(bh), Some(al), Some(ah)) = (before.low, before.high, after.low, after.high)
    else {
        return Verdict::Undecided;
    };
    // Past the threshold the intervals must be apart too; within it, apart or not, the change
    // is within what the threshold says matters.
    match (change < -threshold_pct, change > threshold_pct) {
        (true, _) if ah < bl => Verdict::Slower,
        (_, true) if al > bh => Verdict::Faster,
        (false, false) => Verdict::Within,
        _ => Verdict::Undecided,
    }
}

/// A ratio's summary: median, interval, verdict.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RatioSummary {
    /// Median of the per-round ratios this / other.
    pub median: f64,
    /// The low end of that median's interval (95%; with `--until-decided`, the look's level).
    pub low: f64,
    /// The high end of that median's interval.
    pub high: f64,
    /// Against the threshold.
    pub verdict: Verdict,
}

/// Median, 95% interval and verdict of per-round ratios.
#[cfg(test)]
pub fn summarize(ratios: &[f64], rule: Rule) -> RatioSummary {
    summarize_at(ratios, rule, crate::stats::looks::ALPHA)
}

/// Median, (1 − `alpha`) interval and verdict of per-round ratios.
pub fn summarize_at(ratios: &[f64], rule: Rule, alpha: f64) -> RatioSummary {
    let (median, low, high) = median_with_interval_at(ratios, alpha);
    RatioSummary {
        median,
        low,
        high,
        verdict: rule.judge(low, high),
    }
}

/// Percent change from `before` to `after`; 0 when `before` is 0 (nothing to compare).
pub fn change_pct(before: f64, after: f64) -> f64 {
    if before > 0.0 {
        (after - before) / before * 100.0
    } else {
        0.0
    }
}
