//! `raywave bench`: save then compare passes; a doctored record with inflated figures makes
//! --compare exit 3 with its table, and `--compare X --save X` then keeps X; --compare adopts
//! the record's settings unless a flag is given, and refuses a given flag that differs (exit
//! 1); a missing record names its file and how to create it; sweeps write one record per
//! point; the exports parse back. Tiny images: no timing is asserted.

use crate::common;

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
        "6",
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
        "build",
        "warmup",
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
    assert_eq!(record["engines"][0]["runs"].as_array().unwrap().len(), 6);
    assert_eq!(record["warmup"], 1);
    assert_eq!(record["build"]["profile"], "release");
    // The headline figures: total and the five stages, each with an interval inside [min, max].
    let summary = record["engines"][1]["summary"].as_array().unwrap();
    assert_eq!(summary.len(), 6, "{summary:?}");
    for f in summary {
        let v = |k: &str| f[k].as_f64().unwrap();
        assert!(v("min") <= v("low") && v("low") <= v("median"), "{f}");
        assert!(v("median") <= v("high") && v("high") <= v("max"), "{f}");
        assert_eq!(f["runs"], 6);
    }

    // A huge threshold: whatever the noise, the same build does not regress by 1000%.
    let out = raywave(dir.path(), &["--compare", "before", "--threshold", "999"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("verdict: no headline figure regressed"),
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
    inflate(&mut record, 100.0);
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
    assert!(stdout.contains("SLOWER"), "{stdout}");
    assert!(
        stdout.contains("verdict: REGRESSION past 50.0%"),
        "{stdout}"
    );
    assert!(stdout.contains("reference  total"), "{stdout}");

    // The rolling baseline: a run that regressed does not replace it.
    let before = std::fs::read(&path).unwrap();
    let out = raywave(
        dir.path(),
        &["--compare", "fast", "--save", "fast", "--dir", r, "-q"],
    );
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(err.contains("not saved: this run regressed"), "{err}");
    assert_eq!(
        std::fs::read(&path).unwrap(),
        before,
        "the baseline changed"
    );
}

/// Multiplies every headline figure of a saved record (the summaries the verdict reads) by
/// `factor`.
fn inflate(record: &mut serde_json::Value, factor: f64) {
    for engine in record["engines"].as_array_mut().unwrap() {
        for f in engine["summary"].as_array_mut().unwrap() {
            for k in ["min", "low", "median", "high", "max"] {
                f[k] = (f[k].as_f64().unwrap() * factor).into();
            }
        }
    }
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
fn compare_adopts_the_records_settings_unless_a_flag_is_given() {
    let dir = tempfile::tempdir().unwrap();
    let bench = |args: &[&str]| common::bin::raywave(dir.path(), &[&["bench"][..], args].concat());
    let saved = bench(&[
        "--size",
        "24",
        "16",
        "--bounces",
        "1",
        "--shadow-samples",
        "4",
        "--threads",
        "1",
        "--engine",
        "wavefront",
        "--runs",
        "6",
        "--save",
        "small",
        "-q",
    ]);
    assert!(saved.status.success(), "{}", stderr(&saved));
    // No image flags: the record's 24×16, 1 bounce, 4 points, 1 thread, wavefront only.
    let out = bench(&["--compare", "small", "--runs", "6", "--threshold", "999"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("24×16, 1 bounces, shadows soft, 4 stratified points"),
        "{stdout}"
    );
    assert!(stdout.contains("· 1 thread(s) ·"), "{stdout}");
    assert!(!stdout.contains("reference  total"), "{stdout}");
    // A flag given explicitly is kept, and a difference refused.
    let out = bench(&["--compare", "small", "--runs", "6", "--bounces", "3"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out)
            .1
            .contains("settings.bounces: 1 in the record, 3 now"),
        "{}",
        text(&out).1
    );
    let out = bench(&[
        "--compare",
        "small",
        "--runs",
        "6",
        "--engine",
        "wavefront",
        "--engine",
        "reference",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out).1.contains("no figures for engine reference"),
        "{}",
        text(&out).1
    );
    // Too few runs for an interval: a usage error.
    let out = bench(&["--compare", "small", "--runs", "3"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out).1.contains("--compare needs --runs 6"),
        "{}",
        text(&out).1
    );
}

#[test]
fn a_sweep_writes_one_record_per_point_and_the_exports_parse_back() {
    let dir = tempfile::tempdir().unwrap();
    let out = common::bin::raywave(
        dir.path(),
        &[
            "bench",
            "--size",
            "16",
            "16",
            "--size",
            "24",
            "8",
            "--threads",
            "1,2",
            "--shadow-samples",
            "2",
            "--bounces",
            "1",
            "--runs",
            "6",
            "--save",
            "sw",
            "--export-json",
            "all.json",
            "--export-csv",
            "all.csv",
            "--export-markdown",
            "-",
            "-q",
        ],
    );
    let (md, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let records = dir.path().join(".raywave-bench");
    let mut names = common::bin::files_in(&records);
    names.sort();
    assert_eq!(
        names,
        [
            "sw+16x16+t1.json",
            "sw+16x16+t2.json",
            "sw+24x8+t1.json",
            "sw+24x8+t2.json"
        ]
    );
    let point: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(records.join("sw+24x8+t2.json")).unwrap())
            .unwrap();
    assert_eq!(point["setup"]["settings"]["width"], 24);
    assert_eq!(point["setup"]["settings"]["height"], 8);
    assert_eq!(point["setup"]["settings"]["shadow_samples"], 2);
    assert_eq!(point["setup"]["threads"], 2);

    // JSON: the four records, in sweep order.
    let all: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("all.json")).unwrap())
            .unwrap();
    let all = all.as_array().unwrap();
    assert_eq!(all.len(), 4);
    assert_eq!(all[1]["setup"]["threads"], 2);
    assert_eq!(all[2]["setup"]["settings"]["width"], 24);
    // CSV: the header, then one row per point, engine and headline figure (1 + 5 stages for
    // the wavefront engine, 1 for the reference): 4 × 7 rows of 17 fields.
    let csv = std::fs::read_to_string(dir.path().join("all.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 17);
    assert_eq!(&header[..3], ["point", "scene", "width"]);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 28, "{csv}");
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for row in &rows {
        assert_eq!(row.len(), 17, "{row:?}");
        let v = |name: &str| row[col(name)].parse::<f64>().unwrap();
        assert!(
            v("low") <= v("median") && v("median") <= v("high"),
            "{row:?}"
        );
    }
    assert_eq!(rows[0][col("point")], "16x16+t1");
    assert_eq!(rows[27][col("point")], "24x8+t2");
    assert_eq!(rows[27][col("figure")], "stage film");
    // Markdown on stdout: a header, a separator and 28 rows of 8 cells.
    let table: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
    assert_eq!(table.len(), 30, "{md}");
    assert!(
        table[0].contains("| median | 95% interval | min | max |"),
        "{md}"
    );
    assert!(
        table[2..].iter().all(|r| r.matches('|').count() == 9),
        "{md}"
    );
    assert!(
        table[2].starts_with("| 16x16+t1 | reference | total |"),
        "{md}"
    );
}

#[test]
fn one_engine_and_sweep_flags_that_take_one_point() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(
        dir.path(),
        &["--engine", "reference", "--json", "r.json", "-q"],
    );
    assert!(out.status.success(), "{}", text(&out).1);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(r["engines"].as_array().unwrap().len(), 1);
    assert_eq!(r["engines"][0]["engine"], "reference");
    // A list in any order, a name twice: each engine once, in record order.
    let out = raywave(
        dir.path(),
        &[
            "--engine",
            "wavefront,reference,wavefront",
            "--json",
            "b.json",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", text(&out).1);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b.json")).unwrap()).unwrap();
    let names: Vec<&str> = r["engines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["engine"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["reference", "wavefront"]);
    let out = raywave(dir.path(), &["--threads", "1,2", "--json", "x.json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out).1.contains("--json takes one point"),
        "{}",
        text(&out).1
    );
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

#[test]
fn a_record_of_an_earlier_raywave_is_refused_not_misread() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join(".raywave-bench")).unwrap();
    // A measurement as format 2 wrote it: seconds, counts and flat rates apart.
    let old = r#"{"format": 2, "engines": [{"engine": "wavefront", "median": {"seconds": 0.5,
        "rays": {"camera": 1024, "shadow": 16384, "reflection": 100},
        "rates": {"camera_per_thread_second": 1.0, "shadow_per_thread_second": 1.0,
                  "reflection_per_thread_second": 1.0, "total_per_second": 35016.0},
        "stages": []}}]}"#;
    std::fs::write(dir.path().join(".raywave-bench/old.json"), old).unwrap();
    let why = "old.json: bench record format 2, expected 3: written by an earlier raywave";
    let out = common::bin::raywave(dir.path(), &["bench", "compare", "old", "old"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(why), "{stderr}");
    assert!(
        stderr.contains("re-record it with this build, `raywave bench --save old`"),
        "{stderr}"
    );
    let out = common::bin::raywave(dir.path(), &["bench", "list"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains(why), "{stderr}");
    assert!(stdout.contains("no bench records"), "{stdout}");
}

#[test]
fn exports_may_not_overwrite_inputs_or_each_other_and_a_scene_named_list_is_dot_slash_list() {
    let dir = common::bin::dir_with(&["cornell_box.obj"]);
    let out = raywave(
        dir.path(),
        &["cornell_box.obj", "--export-csv", "cornell_box.obj"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out)
            .1
            .contains("--export-csv cornell_box.obj is the same file as the input SCENE"),
        "{}",
        text(&out).1
    );
    let out = raywave(
        dir.path(),
        &["--export-json", "-", "--export-markdown", "-"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out)
            .1
            .contains("--export-json - (standard output) and --export-markdown - (standard output) are the same file"),
        "{}",
        text(&out).1
    );
    // `-` alone: the export on stdout, the report on stderr.
    let out = raywave(dir.path(), &["--export-csv", "-"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.starts_with("point,scene,width"), "{stdout}");
    assert!(stderr.contains("reference  total"), "{stderr}");
    // A scene file named like a subcommand.
    std::fs::copy(dir.path().join("cornell_box.obj"), dir.path().join("list")).unwrap();
    let out = raywave(dir.path(), &["./list", "--json", "r.json", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(r["setup"]["scene"]["source"], "./list");
}
