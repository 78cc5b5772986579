//! Comparing two bench records: refuse different setups, then a before/after table of the
//! headline figures and the verdict. Pure functions of the two records and the threshold.
//!
//! The rule is in `verdict.rs` (docs/BENCHMARKING.md, "The verdict").

use super::verdict::{Verdict, change_pct, of_records};
use crate::output::bench_record::{BenchRecord, FigureSummary, Setup};
use crate::output::terminal::table_line;
use serde_json::Value;
use std::fmt::Write;

/// The fields in which two setups differ, as `path: X A, Y B` lines with the sides named `a`
/// and `b` (`in the record` and `now`, `in A` and `in B`); empty if none.
pub fn setup_differences(before: &Setup, after: &Setup, a: &str, b: &str) -> Vec<String> {
    let mut out = Vec::new();
    let value = |s: &Setup| serde_json::to_value(s).unwrap_or_default();
    diff("", &value(before), &value(after), &mut |path, x, y| {
        out.push(format!("{path}: {x} {a}, {y} {b}"));
    });
    out
}

/// Calls `found` with the path and both values of each leaf where `x` and `y` differ.
fn diff(path: &str, x: &Value, y: &Value, found: &mut dyn FnMut(&str, &Value, &Value)) {
    // The scene's source is its name only: the text hash and counts decide.
    if path == "scene.source" {
        return;
    }
    match (x, y) {
        (Value::Object(mx), Value::Object(my)) => {
            let keys: std::collections::BTreeSet<&String> = mx.keys().chain(my.keys()).collect();
            for k in keys {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                let [x, y] = [mx, my].map(|m| m.get(k).unwrap_or(&Value::Null));
                diff(&p, x, y, found);
            }
        }
        _ if x != y => found(path, x, y),
        _ => {}
    }
}

/// One headline figure of one engine, before and after.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Engine name.
    pub engine: String,
    /// Before (the saved record, or A).
    pub before: FigureSummary,
    /// After (this run, or B).
    pub after: FigureSummary,
    /// (after − before) / before of the medians, in percent.
    pub change_pct: f64,
    /// What the rule says.
    pub verdict: Verdict,
}

/// The comparison of two records with equal setups.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Every headline figure, engine by engine: total, then stages.
    pub rows: Vec<Row>,
    /// The threshold used, in percent.
    pub threshold_pct: f64,
    /// Notes that do not change the verdict (other machine, other ray counts, ...).
    pub notes: Vec<String>,
}

impl Comparison {
    /// Whether any headline figure regressed.
    pub fn regressed(&self) -> bool {
        self.rows.iter().any(|r| r.verdict == Verdict::Slower)
    }

    /// The before/after table, the rule, the notes and the verdict, with the two columns named
    /// `a` and `b` ("before" and "after" for `raywave bench --compare`, "A" and "B" for
    /// `raywave bench compare A B`).
    pub fn table(&self, a: &str, b: &str) -> String {
        let (mut s, t) = (String::new(), self.threshold_pct);
        // In the unit the tables print: Mrays/s or Mrays/thread-s.
        let cell =
            |f: &FigureSummary| format!("{:.2} {}", f.median / 1e6, f.interval_text(1e-6, 2));
        let line = |cells: [&str; 5]| table_line(&[-10, -17, 26, 26, 8], cells);
        let (ha, hb) = (format!("{a} [95% interval]"), format!("{b} [95% interval]"));
        let header = line(["engine", "figure", &ha, &hb, "change"]);
        let _ = writeln!(s, "{header}  verdict");
        for r in &self.rows {
            let change = format!("{:+.1}%", r.change_pct);
            let [before, after] = [&r.before, &r.after].map(cell);
            let row = line([&r.engine, &r.after.figure, &before, &after, &change]);
            let _ = writeln!(s, "{row}  {}", r.verdict.label());
        }
        let _ = writeln!(
            s,
            "totals in Mrays/s (wall clock), kinds and stages in Mrays/thread-s; medians of {} and {} run(s)",
            self.rows.first().map_or(0, |r| r.before.runs),
            self.rows.first().map_or(0, |r| r.after.runs),
        );
        let _ = writeln!(
            s,
            "rule: SLOWER when the median fell by more than {t:.1}% and the 95% intervals do \
             not overlap ({b}'s high < {a}'s low); faster in the mirror case; undecided when \
             the change passes {t:.1}% but the intervals overlap"
        );
        for n in &self.notes {
            let _ = writeln!(s, "note: {n}");
        }
        let regressed: Vec<String> = self
            .rows
            .iter()
            .filter(|r| r.verdict == Verdict::Slower)
            .map(|r| {
                format!(
                    "{} {} {:+.1}% ({} < {})",
                    r.engine,
                    r.after.figure,
                    r.change_pct,
                    r.after.interval_text(1e-6, 2),
                    r.before.interval_text(1e-6, 2)
                )
            })
            .collect();
        let verdict = if regressed.is_empty() {
            format!("no headline figure regressed (threshold {t:.1}%)")
        } else {
            format!("REGRESSION past {t:.1}%: {}", regressed.join(", "))
        };
        let _ = writeln!(s, "verdict: {verdict}");
        s
    }
}

/// Why two records cannot be compared: each line names what is missing or wrong.
#[derive(Clone, Debug, PartialEq)]
pub enum Refusal {
    /// The setups differ (`path: before -> after` lines): the figures describe other work.
    Setup(Vec<String>),
    /// A record lacks figures the other has, holds figures that are not positive finite
    /// rates, or has no intervals (fewer than 6 runs): a verdict on them could not fail.
    Incomparable(Vec<String>),
}

/// A headline rate that a verdict can rest on: finite and above zero.
fn usable(rate: f64) -> bool {
    rate.is_finite() && rate > 0.0
}

/// That figure `f` of `engine` (`whose`: which record's, or "") has no 95% interval.
fn no_interval(engine: &str, f: &FigureSummary, whose: &str) -> String {
    let (figure, runs, min) = (&f.figure, f.runs, crate::stats::MIN_FOR_INTERVAL);
    format!(
        "engine {engine} {figure}{whose}: no 95% interval ({runs} run(s); at least {min} needed)"
    )
}

/// What in `record` keeps it from being compared with a run of `engines`: an engine it lacks
/// or without a total, a headline figure whose median is not a positive finite rate or that has
/// no 95% interval (fewer than 6 runs). Empty when it can be compared; checked before timing.
pub fn record_problems(record: &BenchRecord, engines: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    if record.engines.is_empty() {
        out.push("it holds no engines".to_string());
    }
    let names: Vec<&str> = record.engines.iter().map(|e| e.engine.as_str()).collect();
    let held = if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    };
    for engine in engines.iter().filter(|e| !names.contains(e)) {
        out.push(format!(
            "it has no figures for engine {engine} (it holds {held})"
        ));
    }
    for e in record
        .engines
        .iter()
        .filter(|e| engines.contains(&e.engine.as_str()))
    {
        if !e.summary.iter().any(|f| f.figure == "total") {
            out.push(format!("engine {}: no total figure", e.engine));
        }
        for f in &e.summary {
            if !usable(f.median) {
                let what = if f.figure == "total" {
                    "rays per second"
                } else {
                    "rays per thread-second"
                };
                out.push(format!(
                    "engine {} {}: rate {}, expected a positive number of {what}",
                    e.engine, f.figure, f.median
                ));
            }
            match (f.low, f.high) {
                (Some(l), Some(h)) if l <= f.median && f.median <= h => {}
                (Some(l), Some(h)) => out.push(format!(
                    "engine {} {}: interval [{l}, {h}] does not hold its median {}",
                    e.engine, f.figure, f.median
                )),
                _ => out.push(no_interval(&e.engine, f, "")),
            }
        }
    }
    out
}

/// Compares `after` against `before` by the rule of [`verdict`]. Refused when the setups
/// differ, and when any headline figure of `after` has nothing valid to compare with in
/// `before` (a verdict that cannot fail is not given).
pub fn compare(
    before: &BenchRecord,
    after: &BenchRecord,
    threshold_pct: f64,
) -> Result<Comparison, Refusal> {
    let differences = setup_differences(&before.setup, &after.setup, "in the record", "now");
    if !differences.is_empty() {
        return Err(Refusal::Setup(differences));
    }
    let engines: Vec<&str> = after.engines.iter().map(|e| e.engine.as_str()).collect();
    let mut problems = record_problems(before, &engines);
    if after.engines.is_empty() {
        problems.push("the newer record measured no engine".to_string());
    }
    let (mut rows, mut notes) = (Vec::new(), Vec::new());
    for a in &after.engines {
        let Some(b) = before.engines.iter().find(|b| b.engine == a.engine) else {
            continue;
        };
        if b.median.rays.kinds.map(|k| k.rays) != a.median.rays.kinds.map(|k| k.rays) {
            notes.push(format!(
                "{}: ray counts differ ({} rays before, {} after): the engines no longer do \
                 the same work",
                a.engine, b.median.rays.total.rays, a.median.rays.total.rays
            ));
        }
        for fa in &a.summary {
            let Some(fb) = b.summary.iter().find(|fb| fb.figure == fa.figure) else {
                problems.push(format!(
                    "engine {} has no figure for {}",
                    a.engine, fa.figure
                ));
                continue;
            };
            if fa.low.is_none() || fa.high.is_none() {
                problems.push(no_interval(&a.engine, fa, " of the newer run"));
                continue;
            }
            // A figure of the newer run that is not a positive finite rate (with a positive one
            // before) fails: it is no evidence of speed.
            let verdict = if usable(fa.median) {
                of_records(fb, fa, threshold_pct)
            } else {
                Verdict::Slower
            };
            rows.push(Row {
                engine: a.engine.clone(),
                before: fb.clone(),
                after: fa.clone(),
                change_pct: change_pct(fb.median, fa.median),
                verdict,
            });
        }
    }
    if !problems.is_empty() {
        return Err(Refusal::Incomparable(problems));
    }
    let (mb, ma) = (&before.machine, &after.machine);
    if (&mb.hostname, &mb.cpu, &before.simd) != (&ma.hostname, &ma.cpu, &after.simd) {
        notes.push(format!(
            "the records were made on {} ({}, simd {}) and {} ({}, simd {})",
            mb.hostname, mb.cpu, before.simd, ma.hostname, ma.cpu, after.simd
        ));
    }
    Ok(Comparison {
        rows,
        threshold_pct,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig(median: f64, low: f64, high: f64) -> FigureSummary {
        FigureSummary {
            figure: "total".into(),
            unit: "rays/s".into(),
            runs: 10,
            min: low,
            median,
            low: Some(low),
            high: Some(high),
            max: high,
            outliers: vec![],
        }
    }

    #[test]
    fn the_rule_needs_both_effect_and_separation() {
        let before = fig(100.0, 95.0, 105.0);
        // -50%, apart: regressed.
        assert_eq!(
            of_records(&before, &fig(50.0, 45.0, 55.0), 10.0),
            Verdict::Slower
        );
        // -50% but a wide interval reaching the old one: noise.
        assert_eq!(
            of_records(&before, &fig(50.0, 40.0, 96.0), 10.0),
            Verdict::Undecided
        );
        // -8%, apart: real but within the threshold.
        assert_eq!(
            of_records(&before, &fig(92.0, 91.0, 94.0), 10.0),
            Verdict::Within
        );
        // Touching ends overlap.
        assert_eq!(
            of_records(&before, &fig(50.0, 45.0, 95.0), 10.0),
            Verdict::Undecided
        );
        assert_eq!(
            of_records(&before, &fig(101.0, 97.0, 104.0), 10.0),
            Verdict::Within
        );
        assert_eq!(
            of_records(&before, &fig(200.0, 190.0, 210.0), 10.0),
            Verdict::Faster
        );
        // Exactly the threshold is not past it.
        assert_eq!(
            of_records(&before, &fig(90.0, 85.0, 91.0), 10.0),
            Verdict::Within
        );
    }
}
