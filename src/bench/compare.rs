//! Comparing two bench records: refuse different setups, then a before/after table and the
//! verdict. Pure functions of the two records and the threshold.

use super::record::{BenchRecord, Measurement, Setup};
use std::fmt::Write;

/// The fields in which two setups differ, as `path: before -> after` lines (empty if none).
pub fn setup_differences(before: &Setup, after: &Setup) -> Vec<String> {
    let a = serde_json::to_value(before).unwrap_or_default();
    let b = serde_json::to_value(after).unwrap_or_default();
    let mut out = Vec::new();
    diff("", &a, &b, &mut out);
    out
}

fn diff(path: &str, a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<String>) {
    use serde_json::Value::Object;
    // The scene's source is its name only: the text hash and counts decide.
    if path == "scene.source" {
        return;
    }
    match (a, b) {
        (Object(ma), Object(mb)) => {
            let mut keys: Vec<&String> = ma.keys().chain(mb.keys()).collect();
            keys.sort();
            keys.dedup();
            for k in keys {
                let null = serde_json::Value::Null;
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                diff(
                    &p,
                    ma.get(k).unwrap_or(&null),
                    mb.get(k).unwrap_or(&null),
                    out,
                );
            }
        }
        _ if a != b => out.push(format!("{path}: {a} in the record, {b} now")),
        _ => {}
    }
}

/// One line of the before/after table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Engine name.
    pub engine: String,
    /// "kind" (rays per wall-clock second) or "stage" (rays per thread-second).
    pub section: &'static str,
    /// Kind or stage name.
    pub name: String,
    /// Rays/s in the saved record.
    pub before: f64,
    /// Rays/s now.
    pub after: f64,
    /// (after − before) / before, in percent (0 when before is 0).
    pub change_pct: f64,
    /// A headline figure: each engine's total and each stage; these decide the verdict.
    pub headline: bool,
    /// A headline figure that fell by more than the threshold.
    pub regressed: bool,
}

/// The comparison of two records with equal setups.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Every row, engine by engine: kinds, then stages.
    pub rows: Vec<Row>,
    /// The threshold used, in percent.
    pub threshold_pct: f64,
    /// Notes that do not change the verdict (other machine, other ray counts, ...).
    pub notes: Vec<String>,
}

impl Comparison {
    /// Whether any headline figure regressed.
    pub fn regressed(&self) -> bool {
        self.rows.iter().any(|r| r.regressed)
    }

    /// The before/after table, the notes and the verdict, as printed.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{:<10} {:<18} {:>12} {:>12} {:>9}",
            "engine", "figure", "before", "after", "change"
        );
        for r in &self.rows {
            let figure = format!(
                "{} {}",
                r.name,
                if r.section == "kind" { "" } else { "(stage)" }
            );
            let mark = match (r.headline, r.regressed) {
                (_, true) => "  REGRESSED",
                (true, false) => "  *",
                _ => "",
            };
            let _ = writeln!(
                s,
                "{:<10} {:<18} {:>12.2} {:>12.2} {:>+8.1}%{mark}",
                r.engine,
                figure.trim_end(),
                r.before / 1e6,
                r.after / 1e6,
                r.change_pct,
            );
        }
        let _ = writeln!(
            s,
            "totals in Mrays/s (wall clock), kinds and stages in Mrays/thread-s; \
             * = headline figure, checked against the threshold of -{:.1}%",
            self.threshold_pct
        );
        for n in &self.notes {
            let _ = writeln!(s, "note: {n}");
        }
        let regressed: Vec<String> = self
            .rows
            .iter()
            .filter(|r| r.regressed)
            .map(|r| format!("{} {} {:+.1}%", r.engine, r.name, r.change_pct))
            .collect();
        if regressed.is_empty() {
            let _ = writeln!(
                s,
                "verdict: no headline figure fell by more than {:.1}%",
                self.threshold_pct
            );
        } else {
            let _ = writeln!(
                s,
                "verdict: REGRESSION past {:.1}%: {}",
                self.threshold_pct,
                regressed.join(", ")
            );
        }
        s
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

/// Why two records cannot be compared: each line names what is missing or wrong.
#[derive(Clone, Debug, PartialEq)]
pub enum Refusal {
    /// The setups differ (`path: before -> after` lines): the figures describe other work.
    Setup(Vec<String>),
    /// The saved record lacks figures this run has, or holds figures that are not positive
    /// finite rates: a verdict on them could not fail.
    Incomparable(Vec<String>),
}

impl Refusal {
    /// The lines, whichever the kind.
    pub fn lines(&self) -> &[String] {
        match self {
            Refusal::Setup(l) | Refusal::Incomparable(l) => l,
        }
    }
}

/// A headline rate that a verdict can rest on: finite and above zero.
fn usable(rate: f64) -> bool {
    rate.is_finite() && rate > 0.0
}

/// What in `record` keeps it from being compared with a run of `engines`: an engine it lacks,
/// a headline figure (an engine's total, a stage that handled rays) that is not a positive
/// finite rate. Empty when it can be compared. Checked before anything is timed.
pub fn record_problems(record: &BenchRecord, engines: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    if record.engines.is_empty() {
        out.push("it holds no engines".to_string());
    }
    let names: Vec<&str> = record.engines.iter().map(|e| e.engine.as_str()).collect();
    for engine in engines {
        if !names.contains(engine) {
            out.push(format!(
                "it has no figures for engine {engine} (it holds {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ));
        }
    }
    for e in &record.engines {
        let total = e.median.rays_per_second.total;
        if !usable(total) {
            out.push(format!(
                "engine {}: total rate {total}, expected a positive number of rays per second",
                e.engine
            ));
        }
        for st in e.median.stages.iter().filter(|st| st.rays > 0) {
            if !usable(st.rays_per_thread_second) {
                out.push(format!(
                    "engine {} stage {}: rate {}, expected a positive number of rays per \
                     thread-second",
                    e.engine, st.stage, st.rays_per_thread_second
                ));
            }
        }
    }
    out
}

/// Compares `after` against `before`. Refused when the setups differ, and when any headline
/// figure of `after` has nothing valid to compare with in `before` (a verdict that cannot
/// fail is not given).
pub fn compare(
    before: &BenchRecord,
    after: &BenchRecord,
    threshold_pct: f64,
) -> Result<Comparison, Refusal> {
    let differences = setup_differences(&before.setup, &after.setup);
    if !differences.is_empty() {
        return Err(Refusal::Setup(differences));
    }
    let engines: Vec<&str> = after.engines.iter().map(|e| e.engine.as_str()).collect();
    let mut problems = record_problems(before, &engines);
    if after.engines.is_empty() {
        problems.push("this run measured no engine".to_string());
    }
    for a in &after.engines {
        let Some(b) = before.engines.iter().find(|b| b.engine == a.engine) else {
            continue;
        };
        for st in a.median.stages.iter().filter(|st| st.rays > 0) {
            match b.median.stages.iter().find(|sb| sb.stage == st.stage) {
                None => problems.push(format!(
                    "engine {} has no figure for stage {}",
                    a.engine, st.stage
                )),
                // A stage idle in the record but not now: its zero rate cannot be compared.
                Some(sb) if sb.rays == 0 && !usable(sb.rays_per_thread_second) => {
                    problems.push(format!(
                        "engine {} stage {}: no rays in the record, {} now",
                        a.engine, st.stage, st.rays
                    ))
                }
                Some(_) => {}
            }
        }
    }
    if !problems.is_empty() {
        return Err(Refusal::Incomparable(problems));
    }
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for a in &after.engines {
        let Some(b) = before.engines.iter().find(|b| b.engine == a.engine) else {
            continue;
        };
        engine_rows(&a.engine, &b.median, &a.median, threshold_pct, &mut rows);
        if b.median.rays != a.median.rays {
            notes.push(format!(
                "{}: ray counts differ ({} rays in the record, {} now): the engines no longer \
                 do the same work",
                a.engine,
                b.median.rays.total(),
                a.median.rays.total()
            ));
        }
    }
    let (mb, ma) = (&before.machine, &after.machine);
    if (&mb.hostname, &mb.cpu, &before.simd) != (&ma.hostname, &ma.cpu, &after.simd) {
        notes.push(format!(
            "the record was made on {} ({}, simd {}), this run on {} ({}, simd {})",
            mb.hostname, mb.cpu, before.simd, ma.hostname, ma.cpu, after.simd
        ));
    }
    Ok(Comparison {
        rows,
        threshold_pct,
        notes,
    })
}

fn engine_rows(
    engine: &str,
    b: &Measurement,
    a: &Measurement,
    threshold: f64,
    rows: &mut Vec<Row>,
) {
    let mut push = |section: &'static str, name: &str, before: f64, after: f64, headline: bool| {
        let change = change_pct(before, after);
        rows.push(Row {
            engine: engine.to_string(),
            section,
            name: name.to_string(),
            before,
            after,
            change_pct: change,
            headline,
            // A headline figure of this run that is not a positive finite rate (with a
            // positive one in the record) fails too: it is no evidence of speed.
            regressed: headline && usable(before) && (!usable(after) || change < -threshold),
        });
    };
    for ((name, before), (_, after)) in b
        .rays_per_second
        .rows()
        .iter()
        .zip(a.rays_per_second.rows())
    {
        push("kind", name, *before, after, *name == "total");
    }
    // A stage that handled no rays in either record (no shadow rays with shadows off) has no
    // rate to compare; it is shown and does not gate.
    for sa in &a.stages {
        let idle = sa.rays == 0;
        let before = b
            .stages
            .iter()
            .find(|sb| sb.stage == sa.stage)
            .map_or(0.0, |sb| sb.rays_per_thread_second);
        push("stage", &sa.stage, before, sa.rays_per_thread_second, !idle);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::record::*;
    use crate::settings::RenderSettings;
    use crate::stats::RayCounts;

    fn measurement(total_scale: f64, stage_scale: f64) -> Measurement {
        let rays = RayCounts {
            camera: 100,
            shadow: 1000,
            reflection: 10,
        };
        Measurement {
            seconds: 1.0 / total_scale,
            rays,
            rays_per_second: KindRates {
                // Each kind falls with the total: shown, never gating.
                camera: Some(100.0 * total_scale),
                shadow: Some(1000.0 * total_scale),
                reflection: Some(10.0 * total_scale),
                ..KindRates::new(&rays, 1.0 / total_scale)
            },
            stages: ["generate", "shadow"]
                .iter()
                .map(|s| StageFigure {
                    stage: s.to_string(),
                    rays: 100,
                    thread_seconds: 1.0 / stage_scale,
                    rays_per_thread_second: 100.0 * stage_scale,
                })
                .collect(),
        }
    }

    fn record(total_scale: f64, stage_scale: f64) -> BenchRecord {
        let m = measurement(total_scale, stage_scale);
        BenchRecord {
            format: FORMAT,
            raywave: "0".into(),
            git_commit: "unknown".into(),
            git_dirty: None,
            timestamp: rfc3339_utc(0),
            machine: Machine {
                hostname: "h".into(),
                cpu: "c".into(),
                logical_cpus: 2,
                os: "linux".into(),
                arch: "x86_64".into(),
            },
            simd: "s".into(),
            setup: Setup {
                scene: SceneId {
                    source: "a.obj".into(),
                    text_hash: "00".into(),
                    triangles: 12,
                    spheres: 3,
                    lights: 1,
                },
                settings: RenderSettings::preview(),
                threads: 2,
                batch_size: 4096,
            },
            runs: 1,
            engines: vec![EngineRecord {
                engine: "wavefront".into(),
                median: m.clone(),
                runs: vec![m],
            }],
        }
    }

    #[test]
    fn equal_records_pass() {
        let c = compare(&record(1.0, 1.0), &record(1.0, 1.0), 10.0).unwrap();
        assert!(!c.regressed());
        assert!(c.rows.iter().all(|r| r.change_pct == 0.0));
        assert!(c.table().contains("verdict: no headline figure fell"));
    }

    #[test]
    fn threshold_is_strict_and_one_sided() {
        // 9% slower total: within a 10% threshold; 11% slower: past it.
        assert!(
            !compare(&record(1.0, 1.0), &record(0.91, 1.0), 10.0)
                .unwrap()
                .regressed()
        );
        let c = compare(&record(1.0, 1.0), &record(0.89, 1.0), 10.0).unwrap();
        assert!(c.regressed());
        let bad: Vec<_> = c
            .rows
            .iter()
            .filter(|r| r.regressed)
            .map(|r| r.name.as_str())
            .collect();
        assert_eq!(bad, ["total"], "per-kind rates are shown but do not gate");
        // Faster is never a regression.
        assert!(
            !compare(&record(1.0, 1.0), &record(5.0, 5.0), 1.0)
                .unwrap()
                .regressed()
        );
    }

    #[test]
    fn a_stage_alone_regresses() {
        let c = compare(&record(1.0, 1.0), &record(1.0, 0.5), 10.0).unwrap();
        let bad: Vec<_> = c
            .rows
            .iter()
            .filter(|r| r.regressed)
            .map(|r| r.name.as_str())
            .collect();
        assert_eq!(bad, ["generate", "shadow"]);
        let table = c.table();
        assert!(table.contains("-50.0%  REGRESSED"), "{table}");
        assert!(
            table.contains("verdict: REGRESSION past 10.0%: wavefront generate -50.0%"),
            "{table}"
        );
    }

    #[test]
    fn records_with_nothing_valid_to_compare_are_refused() {
        let refused = |before: &BenchRecord| match compare(before, &record(1.0, 1.0), 10.0) {
            Err(Refusal::Incomparable(lines)) => lines.join("; "),
            other => panic!("{other:?}"),
        };
        for bad in [0.0, -5.0, f64::NAN, f64::INFINITY] {
            let mut before = record(1.0, 1.0);
            before.engines[0].median.stages[0].rays_per_thread_second = bad;
            assert!(refused(&before).contains("stage generate: rate"), "{bad}");
            let mut before = record(1.0, 1.0);
            before.engines[0].median.rays_per_second.total = bad;
            assert!(refused(&before).contains("total rate"), "{bad}");
        }
        let mut before = record(1.0, 1.0);
        before.engines.clear();
        assert!(refused(&before).contains("no engines"));
        before = record(1.0, 1.0);
        before.engines[0].engine = "other".into();
        assert!(refused(&before).contains("no figures for engine wavefront (it holds other)"));
        before = record(1.0, 1.0);
        before.engines[0].median.stages.pop();
        assert!(refused(&before).contains("no figure for stage shadow"));
        assert_eq!(change_pct(0.0, 5.0), 0.0);
    }

    #[test]
    fn a_rate_of_this_run_that_is_not_positive_regresses() {
        let mut after = record(1.0, 1.0);
        after.engines[0].median.rays_per_second.total = f64::NAN;
        assert!(
            compare(&record(1.0, 1.0), &after, 10.0)
                .unwrap()
                .regressed()
        );
    }

    #[test]
    fn idle_stages_do_not_gate() {
        let mut before = record(1.0, 1.0);
        let mut after = record(1.0, 1.0);
        for r in [&mut before, &mut after] {
            let st = &mut r.engines[0].median.stages[1];
            st.rays = 0;
            st.rays_per_thread_second = 0.0;
        }
        let c = compare(&before, &after, 10.0).unwrap();
        assert!(!c.regressed());
        assert!(!c.rows.iter().any(|r| r.name == "shadow" && r.headline));
    }

    #[test]
    fn different_setups_are_refused() {
        let mut after = record(1.0, 1.0);
        after.setup.settings.bounces += 1;
        after.setup.threads = 1;
        after.setup.scene.source = "renamed.obj".into();
        let e = compare(&record(1.0, 1.0), &after, 10.0).unwrap_err();
        assert_eq!(
            e.lines(),
            [
                "settings.bounces: 2 in the record, 3 now",
                "threads: 2 in the record, 1 now"
            ]
        );
        let mut edited = record(1.0, 1.0);
        edited.setup.scene.text_hash = "01".into();
        assert_eq!(
            compare(&record(1.0, 1.0), &edited, 10.0)
                .unwrap_err()
                .lines()
                .len(),
            1
        );
    }

    #[test]
    fn other_machine_and_counts_are_noted() {
        let mut after = record(1.0, 1.0);
        after.machine.hostname = "other".into();
        after.engines[0].median.rays.shadow += 1;
        let c = compare(&record(1.0, 1.0), &after, 10.0).unwrap();
        assert_eq!(c.notes.len(), 2, "{:?}", c.notes);
        assert!(!c.regressed());
    }
}
