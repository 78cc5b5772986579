//! The bench verdict on records written here by hand (JSON, not made by the code under test):
//! a clear slowdown is a regression, a larger change that the intervals cannot tell from
//! noise is not, nor is a real change inside the threshold; a record with nothing to compare
//! is refused. Then `raywave bench compare A B` and `raywave bench list` on such files, good
//! and bad.

use crate::common;

use common::bin::{raywave, stderr, stdout};
use raywave::bench::compare::{Refusal, compare};
use raywave::bench::verdict::Verdict;
use raywave::output::bench_record::BenchRecord;
use serde_json::{Value, json};
use std::path::Path;

/// A summary entry: `figure` at `median` with its interval [low, high], in rays/s.
fn figure(name: &str, median: f64, low: f64, high: f64) -> Value {
    json!({
        "figure": name,
        "unit": if name == "total" { "rays/s" } else { "rays/thread-s" },
        "runs": 10, "min": low * 0.9, "median": median, "low": low, "high": high,
        "max": high * 1.1, "outliers": []
    })
}

/// A record of the wavefront engine on the built-in scene at 32×32, whose headline figures
/// are `summary` (in Mrays/s: multiplied by 1e6 here).
fn record(total: (f64, f64, f64), shadow_stage: (f64, f64, f64)) -> Value {
    let m = |(a, b, c): (f64, f64, f64)| (a * 1e6, b * 1e6, c * 1e6);
    let (t, s) = (m(total), m(shadow_stage));
    let kind = |rays: u64| json!({"rays": rays, "thread_seconds": rays as f64, "rays_per_thread_second": 1.0});
    let rays = json!({"camera": kind(1024), "shadow": kind(16384), "reflection": kind(100),
                      "total": {"rays": 17508, "seconds": 17508.0 / t.0, "rays_per_second": t.0}});
    json!({
        "format": 3,
        "raywave": "0.1.0",
        "git_commit": "0123456789abcdef0123456789abcdef01234567",
        "git_dirty": false,
        "build": {
            "commit": "0123456789abcdef0123456789abcdef01234567", "dirty": false,
            "profile": "release", "target": "x86_64-unknown-linux-gnu",
            "target_features": "avx2,fma", "rustflags": "-C target-cpu=native"
        },
        "timestamp": "2026-11-30T12:00:00Z",
        "machine": {"hostname": "lab", "cpu": "Test CPU", "logical_cpus": 2, "os": "linux",
                    "arch": "x86_64"},
        "simd": "avx2+fma",
        "setup": {
            "scene": {"source": "<built-in cornell_box_reflective_spheres>",
                      "text_hash": "f682a4f8692ee6ad", "triangles": 12, "spheres": 3,
                      "lights": 1},
            "settings": {"width": 32, "height": 32, "bounces": 5, "shadows": "soft",
                         "shadow_samples": 16, "sampler": "stratified", "aa_samples": 1,
                         "background": [0.2, 0.1, 0.6], "seed": 0, "two_sided": false,
                         "light_model": "lab", "ambient": [0.2, 0.2, 0.2]},
            "threads": 2,
            "batch_size": 4096
        },
        "runs": 10,
        "warmup": 1,
        "engines": [{
            "engine": "wavefront",
            "median": {
                "rays": rays,
                "stages": [{"stage": "shadow", "rays": 16384, "thread_seconds": 16384.0 / s.0,
                            "rays_per_thread_second": s.0}]
            },
            "runs": [],
            "summary": [figure("total", t.0, t.1, t.2), figure("stage shadow", s.0, s.1, s.2)]
        }]
    })
}

fn parse(v: &Value) -> BenchRecord {
    serde_json::from_value(v.clone()).expect("the fixture is a record")
}

const STEADY: (f64, f64, f64) = (100.0, 97.0, 103.0);

#[test]
fn a_clear_slowdown_is_a_regression_and_the_table_shows_the_rule_inputs() {
    let before = parse(&record(STEADY, STEADY));
    // Total 100 -> 50 Mrays/s, intervals [97, 103] and [48, 52]: -50%, apart.
    let after = parse(&record((50.0, 48.0, 52.0), STEADY));
    let c = compare(&before, &after, 40.0).unwrap();
    assert!(c.regressed());
    let total = c.rows.iter().find(|r| r.after.figure == "total").unwrap();
    assert_eq!(total.verdict, Verdict::Slower);
    assert_eq!(total.change_pct, -50.0);
    let shadow = c
        .rows
        .iter()
        .find(|r| r.after.figure == "stage shadow")
        .unwrap();
    assert_eq!(shadow.verdict, Verdict::Within);
    let table = c.table("before", "after");
    for needle in [
        "100.00 [97.00, 103.00]",
        "50.00 [48.00, 52.00]",
        "-50.0%  SLOWER",
        "verdict: REGRESSION past 40.0%: wavefront total -50.0% ([48.00, 52.00] < [97.00, 103.00])",
        "rule: SLOWER when the median fell by more than 40.0% and the 95% intervals do not overlap",
    ] {
        assert!(table.contains(needle), "missing `{needle}` in:\n{table}");
    }
}

#[test]
fn a_change_inside_the_noise_or_inside_the_threshold_is_not_a_regression() {
    // -45% on the medians, but the intervals [60, 140] and [40, 90] overlap: noise.
    let before = parse(&record((100.0, 60.0, 140.0), STEADY));
    let after = parse(&record((55.0, 40.0, 90.0), STEADY));
    let c = compare(&before, &after, 40.0).unwrap();
    assert!(!c.regressed(), "{}", c.table("before", "after"));
    assert_eq!(c.rows[0].verdict, Verdict::Undecided);
    // -10%, intervals apart: real, but inside the 40% threshold.
    let after = parse(&record((90.0, 89.0, 91.0), STEADY));
    let c = compare(&parse(&record(STEADY, STEADY)), &after, 40.0).unwrap();
    assert!(!c.regressed());
    assert_eq!(c.rows[0].verdict, Verdict::Within);
    // The same -10% with a 5% threshold is a regression.
    assert!(
        compare(&parse(&record(STEADY, STEADY)), &after, 5.0)
            .unwrap()
            .regressed()
    );
    // Twice as fast, apart: faster, never a regression.
    let after = parse(&record((200.0, 190.0, 210.0), STEADY));
    let c = compare(&parse(&record(STEADY, STEADY)), &after, 40.0).unwrap();
    assert_eq!(c.rows[0].verdict, Verdict::Faster);
    assert!(!c.regressed());
}

#[test]
fn a_stage_alone_regresses() {
    let before = parse(&record(STEADY, STEADY));
    let after = parse(&record(STEADY, (30.0, 29.0, 31.0)));
    let c = compare(&before, &after, 40.0).unwrap();
    let bad: Vec<&str> = c
        .rows
        .iter()
        .filter(|r| r.verdict == Verdict::Slower)
        .map(|r| r.after.figure.as_str())
        .collect();
    assert_eq!(bad, ["stage shadow"]);
}

#[test]
fn records_with_nothing_comparable_are_refused() {
    let good = record(STEADY, STEADY);
    let refused = |before: Value| match compare(&parse(&before), &parse(&good), 40.0) {
        Err(Refusal::Incomparable(lines)) => lines.join("; "),
        other => panic!("expected a refusal, got {other:?}"),
    };
    let mut no_interval = good.clone();
    no_interval["engines"][0]["summary"][0]["low"] = Value::Null;
    assert!(refused(no_interval).contains("total: no 95% interval"));
    let mut no_stage = good.clone();
    no_stage["engines"][0]["summary"]
        .as_array_mut()
        .unwrap()
        .pop();
    assert!(refused(no_stage).contains("no figure for stage shadow"));
    let mut zero = good.clone();
    zero["engines"][0]["summary"][0]["median"] = json!(0.0);
    assert!(refused(zero).contains("total: rate 0, expected a positive number"));
    let mut other_engine = good.clone();
    other_engine["engines"][0]["engine"] = json!("reference");
    assert!(refused(other_engine).contains("no figures for engine wavefront"));
    let mut other_size = good.clone();
    other_size["setup"]["settings"]["width"] = json!(64);
    match compare(&parse(&other_size), &parse(&good), 40.0) {
        Err(Refusal::Setup(lines)) => {
            assert_eq!(lines, ["settings.width: 64 in the record, 32 now"])
        }
        other => panic!("{other:?}"),
    }
}

/// Writes the records into DIR/.raywave-bench.
fn saved(dir: &Path, records: &[(&str, &Value)]) {
    let d = dir.join(".raywave-bench");
    std::fs::create_dir_all(&d).unwrap();
    for (name, r) in records {
        std::fs::write(d.join(format!("{name}.json")), r.to_string()).unwrap();
    }
}

#[test]
fn bench_compare_a_b_gives_the_table_and_exit_3_on_a_regression() {
    let dir = tempfile::tempdir().unwrap();
    let slow = record((50.0, 48.0, 52.0), STEADY);
    let noisy = record((55.0, 40.0, 98.0), STEADY);
    saved(
        dir.path(),
        &[
            ("old", &record(STEADY, STEADY)),
            ("slow", &slow),
            ("noisy", &noisy),
        ],
    );
    let out = raywave(dir.path(), &["bench", "compare", "old", "slow"]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(3), "{text}\n{}", stderr(&out));
    assert!(
        text.contains("A [95% interval]") && text.contains("B [95% interval]"),
        "{text}"
    );
    assert!(text.contains("-50.0%  SLOWER"), "{text}");
    let out = raywave(dir.path(), &["bench", "compare", "old", "noisy"]);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
    assert!(stdout(&out).contains("undecided"));
    // A threshold of its own, and a path instead of a name.
    let path = dir.path().join(".raywave-bench/slow.json");
    let out = raywave(
        dir.path(),
        &[
            "bench",
            "compare",
            "old",
            path.to_str().unwrap(),
            "--threshold",
            "60",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
}

#[test]
fn bench_compare_fails_cleanly_on_bad_records() {
    let dir = tempfile::tempdir().unwrap();
    let mut wide = record(STEADY, STEADY);
    wide["setup"]["threads"] = json!(1);
    saved(
        dir.path(),
        &[("old", &record(STEADY, STEADY)), ("wide", &wide)],
    );
    std::fs::write(
        dir.path().join(".raywave-bench/cut.json"),
        "{\"format\": 2, \"raywave\"",
    )
    .unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["old", "cut"], "cut.json: not a JSON bench record"),
        (
            &["old", "missing"],
            "no bench record .raywave-bench/missing.json",
        ),
        (&["old", "wide"], "threads: 2 in A, 1 in B"),
        (&["old", "../x"], "not usable"),
    ];
    for (args, message) in cases {
        let out = raywave(dir.path(), &[&["bench", "compare"][..], args].concat());
        let err = stderr(&out);
        assert!(matches!(out.status.code(), Some(1 | 2)), "{args:?}: {err}");
        assert!(
            err.contains(message),
            "{args:?}: expected `{message}` in:\n{err}"
        );
        assert!(stdout(&out).is_empty(), "{args:?}");
    }
}

#[test]
fn bench_list_lists_records_and_skips_bad_ones_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(dir.path(), &["bench", "list"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("no bench records"),
        "{}",
        stderr(&out)
    );
    let mut later = record((80.0, 79.0, 81.0), STEADY);
    later["timestamp"] = json!("2026-12-01T08:00:00Z");
    saved(
        dir.path(),
        &[("zeta", &record(STEADY, STEADY)), ("alpha", &later)],
    );
    std::fs::write(dir.path().join(".raywave-bench/broken.json"), "[]").unwrap();
    let out = raywave(dir.path(), &["bench", "list"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "{text}");
    // Oldest first: zeta (Nov 30), then alpha (Dec 1).
    assert!(
        lines[1].starts_with("zeta") && lines[2].starts_with("alpha"),
        "{text}"
    );
    assert!(lines[1].contains("2026-11-30T12:00:00Z") && lines[1].contains("0123456789ab"));
    assert!(
        lines[1].contains("32x32") && lines[1].contains("100.00"),
        "{text}"
    );
    assert!(lines[2].contains("80.00"), "{text}");
    assert!(
        stderr(&out).contains("warning: skipped") && stderr(&out).contains("broken.json"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn another_simd_path_is_noted() {
    let mut after = record(STEADY, STEADY);
    after["simd"] = json!("sse2");
    let c = compare(&parse(&record(STEADY, STEADY)), &parse(&after), 40.0).unwrap();
    assert_eq!(c.notes.len(), 1, "{:?}", c.notes);
    assert!(
        c.notes[0].contains("simd avx2+fma") && c.notes[0].contains("simd sse2"),
        "{:?}",
        c.notes
    );
    assert!(!c.regressed());
}
