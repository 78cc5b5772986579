//! `raywave bench`: save then compare passes; a doctored record with inflated figures makes
//! --compare exit 3 with its table; different settings are refused (exit 1); a missing record
//! names its file and how to create it. Tiny images and one run: no timing is asserted.

mod common;

use common::bin::{stderr, stdout};
use std::path::Path;
use std::process::Output;

/// `raywave bench` on a tiny image, one run, with `args` after.
fn raywave(dir: &Path, args: &[&str]) -> Output {
    let bench = [
        "bench",
        "--size",
        "32",
        "32",
        "--runs",
        "1",
        "--bounces",
        "2",
    ];
    common::bin::raywave(dir, &[&bench[..], args].concat())
}

fn text(out: &Output) -> (String, String) {
    (stdout(out), stderr(out))
}

#[test]
fn save_then_compare_passes_and_the_record_is_complete() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(dir.path(), &["--save", "before"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    for needle in [
        "reference  total",
        "wavefront  shadow",
        "Mrays/thread-s",
        "saved",
    ] {
        assert!(stdout.contains(needle), "missing `{needle}` in:\n{stdout}");
    }
    // Kinds per thread-second of their own work: measured for the wavefront engine, `-` for
    // the reference (timed without timers); totals per wall-clock second.
    let line = |start: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no `{start}` line in:\n{stdout}"))
            .to_string()
    };
    assert!(line("reference  camera").ends_with(" -"), "{stdout}");
    assert!(!line("wavefront  camera").ends_with(" -"), "{stdout}");
    assert!(
        line("engine     kind").ends_with("Mrays/thread-s"),
        "{stdout}"
    );
    assert!(
        line("wavefront  total").ends_with("(Mrays/s, wall clock)"),
        "{stdout}"
    );
    let path = dir.path().join(".raywave-bench/before.json");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for key in [
        "machine",
        "simd",
        "git_commit",
        "raywave",
        "timestamp",
        "setup",
        "engines",
    ] {
        assert!(record.get(key).is_some(), "record lacks {key}");
    }
    assert_eq!(record["setup"]["settings"]["width"], 32);
    assert_eq!(record["engines"][1]["engine"], "wavefront");
    assert_eq!(
        record["engines"][1]["median"]["stages"]
            .as_array()
            .unwrap()
            .len(),
        5
    );
    assert_eq!(record["engines"][0]["runs"].as_array().unwrap().len(), 1);

    // A huge threshold: whatever the noise, the same build does not regress by 1000%.
    let out = raywave(dir.path(), &["--compare", "before", "--threshold", "999"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("verdict: no headline figure fell"),
        "{stdout}"
    );
}

#[test]
fn an_inflated_record_makes_compare_exit_3_with_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let records = dir.path().join("records");
    let r = records.to_str().unwrap();
    assert!(
        raywave(dir.path(), &["--save", "fast", "--dir", r, "-q"])
            .status
            .success()
    );
    let path = records.join("fast.json");
    let mut record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for engine in record["engines"].as_array_mut().unwrap() {
        let median = &mut engine["median"];
        let total = median["rates"]["total_per_second"].as_f64().unwrap();
        median["rates"]["total_per_second"] = (total * 100.0).into();
        for stage in median["stages"].as_array_mut().unwrap() {
            let v = stage["rays_per_thread_second"].as_f64().unwrap();
            stage["rays_per_thread_second"] = (v * 100.0).into();
        }
    }
    std::fs::write(&path, serde_json::to_string(&record).unwrap()).unwrap();

    let out = raywave(
        dir.path(),
        &["--compare", "fast", "--dir", r, "--threshold", "50"],
    );
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("before") && stdout.contains("after"),
        "{stdout}"
    );
    assert!(stdout.contains("REGRESSED"), "{stdout}");
    assert!(
        stdout.contains("verdict: REGRESSION past 50.0%"),
        "{stdout}"
    );
    assert!(stdout.contains("reference  total"), "{stdout}");
}

#[test]
fn different_settings_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    assert!(raywave(dir.path(), &["--save", "b", "-q"]).status.success());
    let out = raywave(dir.path(), &["--compare", "b", "--shadows", "hard"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("cannot compare with .raywave-bench/b.json"),
        "{stderr}"
    );
    assert!(
        stderr.contains("settings.shadows: \"soft\" in the record, \"hard\" now"),
        "{stderr}"
    );
    // Refused before the timed part: nothing measured, nothing printed.
    assert!(stdout.is_empty(), "{stdout}");
}

#[test]
fn a_missing_record_names_the_file_and_how_to_create_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(dir.path(), &["--compare", "nope"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("no bench record .raywave-bench/nope.json"),
        "{stderr}"
    );
    assert!(stderr.contains("raywave bench --save nope"), "{stderr}");
    // A name that is not plain is a usage error.
    let out = raywave(dir.path(), &["--save", "../x"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("not usable"));
}
