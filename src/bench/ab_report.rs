//! The text of `raywave bench --against`: the verdict table, and with `--until-decided` the
//! plan of looks and each engine's rounds and looks.

use super::ab::{AbOptions, EngineAb};
use super::running::sequential::{self, Budget, Stop};
use super::verdict::{Verdict, VerdictForm};
use crate::output::terminal::table_line;
use crate::stats::looks::{self, LookPlan};
use crate::stats::median;
use std::time::Duration;

/// `--max-time`'s value as typed back (`10m`, `1h 30m`).
fn duration_text(d: Duration) -> String {
    humantime::format_duration(Duration::from_secs(d.as_secs().max(1))).to_string()
}

/// The verdict table.
pub fn report(options: &AbOptions, results: &[EngineAb]) -> String {
    let t = options.rule.threshold_pct;
    let form = match options.rule.form {
        VerdictForm::Regression => "one-sided: a regression or not",
        VerdictForm::ThreeWay => "three-way: slower, faster or no change",
    };
    let (rounds, plan, level) = match options.until_decided {
        None => (
            format!("{} rounds", options.rounds),
            String::new(),
            "95% interval",
        ),
        Some(budget) => {
            let plan = LookPlan::new(budget.max_rounds);
            let looks: Vec<String> = plan.looks.iter().map(u32::to_string).collect();
            (
                format!(
                    "until decided (at most {} rounds{})",
                    budget.max_rounds,
                    budget
                        .max_time
                        .map(|d| format!(", {}", duration_text(d)))
                        .unwrap_or_default()
                ),
                format!(
                    " · looks at {} rounds, each a {}% interval ({}% split over {} looks)",
                    looks.join(", "),
                    round_pct(plan.confidence_pct()),
                    looks::ALPHA * 100.0,
                    plan.split,
                ),
                "interval",
            )
        }
    };
    let columns = [-10, 25, 25, 8, 18];
    let header = format!("engine|this: median (min–max)|other: median (min–max)|ratio|{level}");
    let mut out = format!(
        "this build / {} · {rounds} after {} warm-up, alternating · threshold {t}%, \
         {form}{plan}\n{}  verdict\n",
        options.other.display(),
        options.warmup,
        table_line(&columns, header.split('|')),
    );
    for r in results {
        let s = r.summary(options.rule);
        let spread = |xs: &[f64]| {
            if xs.is_empty() {
                return "no rounds".to_string();
            }
            let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            format!("{:.4} s ({:.3}–{:.3})", median(xs), lo, hi)
        };
        let verdict = match (s.verdict, &r.sequential) {
            (Verdict::Slower, _) => format!("slower by more than {t}%: a regression"),
            (Verdict::NotSlower, _) => format!("not slower by more than {t}%: not a regression"),
            (Verdict::Faster, _) => format!("faster by more than {t}%"),
            (Verdict::Within, _) => format!("no change beyond {t}%"),
            (Verdict::Undecided, None) => {
                "undecided: the interval crosses the threshold; run more rounds".to_string()
            }
            (Verdict::Undecided, Some(_)) => "undecided at the budget".to_string(),
        };
        let [this, other] = [&r.this, &r.other].map(|xs| spread(xs));
        let (median, interval) = (
            format!("{:.4}", s.median),
            format!("[{:.4}, {:.4}]", s.low, s.high),
        );
        let cells = [r.engine.name(), &this, &other, &median, &interval];
        out += &format!("{}  {verdict}\n", table_line(&columns, cells));
        if let (Some(outcome), Some(budget)) = (&r.sequential, options.until_decided) {
            out += &format!("  {}\n", looks_line(outcome, budget));
        }
        if let Some((mine, theirs)) = &r.different_work {
            out += &format!(
                "  warning: the builds traced different rays with {} (camera, shadow, \
                 reflection, total: this {mine}, other {theirs}): the ratio compares \
                 different work\n",
                r.engine.name()
            );
        }
    }
    out
}

/// A level in percent without trailing zeros: 95, 99.44.
fn round_pct(pct: f64) -> String {
    let text = format!("{pct:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// One engine's rounds and looks: `14 rounds used; looks at 9 (undecided), 14 (slower)`.
fn looks_line(outcome: &sequential::Outcome, budget: Budget) -> String {
    let looks: Vec<String> = outcome
        .looks
        .iter()
        .map(|l| format!("{} ({})", l.rounds, l.summary.verdict.word()))
        .collect();
    let looks = if looks.is_empty() {
        "no look taken".to_string()
    } else {
        format!("looks at {}", looks.join(", "))
    };
    let why = match outcome.stop {
        Stop::Decided => "decided".to_string(),
        Stop::MaxRounds => format!("--max-rounds {} reached", budget.max_rounds),
        Stop::Budget => format!(
            "--max-time {} left too little time for the next look",
            budget.max_time.map(duration_text).unwrap_or_default()
        ),
    };
    format!("{} rounds used; {looks}; {why}", outcome.rounds)
}
