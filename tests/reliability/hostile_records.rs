//! The hostile-input catalogue for the records of `raywave bench` and the verdicts it gives on
//! them: records that are empty, foreign, zero, negative, non-numeric, truncated, of another
//! format or not regular files; names that are paths; a regressing run that must not replace
//! its baseline; and the command's exit codes (2 usage, 1 failure, 3 regression). Each case
//! checks its exit code, a message, no panic, no hang and that nothing changed but the files it
//! names (`common::hostile`). The variance cache's cases are in
//! `tests/reliability/hostile_cache.rs`.

use crate::common;

use common::hostile::{Case, TIMEOUT, check_all, run, setup};
use std::path::Path;
/// The smallest bench that can be compared: 8×8, six runs (the fewest with a 95% interval).
const BENCH: &[&str] = &["bench", "--size", "8", "8", "--runs", "6", "-q"];

fn bench(extra: &[&'static str]) -> &'static [&'static str] {
    Box::leak([BENCH, extra].concat().into_boxed_slice())
}

/// A saved record `good` of the smallest bench, then changed by `edit`.
fn doctored_record(dir: &Path, edit: fn(&mut serde_json::Value)) {
    let r = run(dir, bench(&["--save", "good"]), None, TIMEOUT);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let path = dir.join(".raywave-bench/good.json");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    edit(&mut json);
    std::fs::write(path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
}

/// A case comparing with the record `good` that `setup` doctored: refused with exit 1 before
/// anything is timed, naming the record and what was wrong; the record untouched.
fn refused(name: &'static str, setup: fn(&Path), why: &'static str) -> Case {
    let fragments: &'static [&'static str] =
        Box::leak(vec!["cannot compare with .raywave-bench/good.json", why].into_boxed_slice());
    Case {
        name,
        setup,
        args: bench(&["--compare", "good"]),
        stdin: None,
        exit: 1,
        stderr: fragments,
        outputs: &[],
    }
}

/// The headline figure `figure` ("total", "stage generate") of `engine` in a record: its
/// summary, on which verdicts are decided.
fn figure<'a>(
    json: &'a mut serde_json::Value,
    engine: &str,
    figure: &str,
) -> &'a mut serde_json::Value {
    let engines = json["engines"].as_array_mut().unwrap();
    let e = engines.iter_mut().find(|e| e["engine"] == engine).unwrap();
    let summary = e["summary"].as_array_mut().unwrap();
    summary.iter_mut().find(|f| f["figure"] == figure).unwrap()
}

#[test]
fn records_with_nothing_valid_to_compare_are_refused() {
    check_all(&[
        refused(
            "a record with no engines",
            |d| doctored_record(d, |j| j["engines"] = serde_json::json!([])),
            "it holds no engines",
        ),
        refused(
            "a record with other engine names",
            |d| {
                doctored_record(d, |j| {
                    for e in j["engines"].as_array_mut().unwrap() {
                        e["engine"] = format!("old-{}", e["engine"].as_str().unwrap()).into();
                    }
                })
            },
            "no figures for engine reference (it holds old-reference, old-wavefront)",
        ),
        refused(
            "a record whose total rate is zero",
            |d| doctored_record(d, |j| figure(j, "reference", "total")["median"] = 0.into()),
            "engine reference total: rate 0, expected a positive number",
        ),
        refused(
            "a record whose total rate is negative",
            |d| {
                doctored_record(d, |j| {
                    figure(j, "wavefront", "total")["median"] = (-5.0).into()
                })
            },
            "engine wavefront total: rate -5, expected a positive number",
        ),
        refused(
            "a record whose stage rate is zero",
            |d| {
                doctored_record(d, |j| {
                    figure(j, "wavefront", "stage generate")["median"] = 0.into()
                })
            },
            "stage generate: rate 0",
        ),
        refused(
            "a record without intervals (fewer than 6 runs)",
            |d| {
                doctored_record(d, |j| {
                    figure(j, "wavefront", "total")["low"] = serde_json::Value::Null
                })
            },
            "engine wavefront total: no 95% interval",
        ),
        refused(
            "a record without a stage this run has",
            |d| {
                doctored_record(d, |j| {
                    let engines = j["engines"].as_array_mut().unwrap();
                    let e = engines
                        .iter_mut()
                        .find(|e| e["engine"] == "wavefront")
                        .unwrap();
                    e["summary"].as_array_mut().unwrap().remove(1);
                })
            },
            "engine wavefront has no figure for stage generate",
        ),
    ]);
}

#[test]
fn records_that_do_not_parse_name_the_file_and_what_was_expected() {
    let unreadable = |name, setup, why| Case {
        stderr: Box::leak(vec![".raywave-bench/good.json", why].into_boxed_slice()),
        ..refused(name, setup, why)
    };
    check_all(&[
        // JSON has no NaN: serde_json writes it as null, which is no rate.
        unreadable(
            "a record with a NaN rate (null in JSON)",
            |d| {
                doctored_record(d, |j| {
                    figure(j, "wavefront", "total")["median"] = serde_json::Value::Null
                })
            },
            "not a valid bench record: invalid type: null, expected f64",
        ),
        unreadable(
            "a record with a word for a rate",
            |d| {
                doctored_record(d, |j| {
                    figure(j, "wavefront", "total")["median"] = "fast".into()
                })
            },
            "invalid type: string \"fast\", expected f64",
        ),
        unreadable(
            "a truncated record",
            |d| {
                doctored_record(d, |_| {});
                let p = d.join(".raywave-bench/good.json");
                let text = std::fs::read(&p).unwrap();
                std::fs::write(&p, &text[..text.len() / 2]).unwrap();
            },
            "not a JSON bench record",
        ),
        unreadable(
            "a record of another format version",
            |d| doctored_record(d, |j| j["format"] = 99.into()),
            "bench record format 99, expected 3: written by a later raywave",
        ),
        unreadable(
            "a record of format 2 (its kinds' figures were apart from the counts and seconds)",
            |d| doctored_record(d, |j| j["format"] = 2.into()),
            "bench record format 2, expected 3: written by an earlier raywave; its figures are \
             laid out or mean other things (docs/SCHEMA.md): re-record it with this build, \
             `raywave bench --save good`",
        ),
        Case {
            name: "a record that is a FIFO (must not hang)",
            setup: |d| {
                std::fs::create_dir(d.join(".raywave-bench")).unwrap();
                setup::fifo(d, ".raywave-bench/good.json");
            },
            args: bench(&["--compare", "good"]),
            stdin: None,
            exit: 1,
            stderr: &[".raywave-bench/good.json: expected a bench record (a regular JSON file)"],
            outputs: &[],
        },
        Case {
            name: "a record that is a link to /dev/zero (must not read forever)",
            setup: |d| {
                std::fs::create_dir(d.join(".raywave-bench")).unwrap();
                setup::symlink(d, ".raywave-bench/good.json", "/dev/zero");
            },
            args: bench(&["--compare", "good"]),
            stdin: None,
            exit: 1,
            stderr: &["expected a bench record (a regular JSON file)"],
            outputs: &[],
        },
        Case {
            name: "a record that is a directory",
            setup: |d| std::fs::create_dir_all(d.join(".raywave-bench/good.json")).unwrap(),
            args: bench(&["--compare", "good"]),
            stdin: None,
            exit: 1,
            stderr: &["found a directory or device"],
            outputs: &[],
        },
        Case {
            name: "--compare a record that does not exist",
            setup: setup::nothing,
            args: bench(&["--compare", "missing"]),
            stdin: None,
            exit: 1,
            stderr: &[
                "no bench record .raywave-bench/missing.json",
                "--save missing",
            ],
            outputs: &[],
        },
    ]);
}

/// `good`, doctored 1000× faster than any run can be, so that comparing with it regresses.
fn inflated(dir: &Path) {
    doctored_record(dir, |j| {
        for e in ["reference", "wavefront"] {
            let f = figure(j, e, "total");
            for k in ["min", "low", "median", "high", "max"] {
                f[k] = (f[k].as_f64().unwrap() * 1000.0).into();
            }
        }
    })
}

#[test]
fn record_names_and_regressions() {
    check_all(&[
        Case {
            name: "--save ../escape",
            setup: setup::nothing,
            args: bench(&["--save", "../escape"]),
            stdin: None,
            exit: 2,
            stderr: &["bench record name `../escape` is not usable"],
            outputs: &[],
        },
        Case {
            name: "--save with a slash",
            setup: setup::nothing,
            args: bench(&["--save", "a/b"]),
            stdin: None,
            exit: 2,
            stderr: &["`a/b` is not usable"],
            outputs: &[],
        },
        Case {
            name: "--compare with a name that is a path",
            setup: setup::nothing,
            args: bench(&["--compare", "/etc/passwd"]),
            stdin: None,
            exit: 2,
            stderr: &["is not usable"],
            outputs: &[],
        },
        Case {
            name: "--compare X --save X on a regression keeps X",
            setup: inflated,
            args: bench(&["--compare", "good", "--save", "good"]),
            stdin: None,
            exit: 3,
            stderr: &["not saved: this run regressed against .raywave-bench/good.json"],
            outputs: &[],
        },
        Case {
            name: "--compare X --save Y on a regression saves Y",
            setup: inflated,
            args: bench(&["--compare", "good", "--save", "new"]),
            stdin: None,
            exit: 3,
            stderr: &[],
            outputs: &[".raywave-bench/new.json"],
        },
        Case {
            name: "--compare X --save X without a regression replaces X",
            setup: |d| doctored_record(d, |_| {}),
            args: bench(&["--compare", "good", "--save", "good", "--threshold", "999"]),
            stdin: None,
            exit: 0,
            stderr: &[],
            outputs: &[".raywave-bench/good.json"],
        },
        Case {
            name: "--threshold that is not a percentage",
            setup: setup::nothing,
            args: bench(&["--threshold", "NaN"]),
            stdin: None,
            exit: 2,
            stderr: &["expected a percentage between 0 and 1000"],
            outputs: &[],
        },
        Case {
            name: "a scene and --input",
            setup: setup::cornell_box,
            args: bench(&["cornell_box.obj", "--input", "cornell_box.obj"]),
            stdin: None,
            exit: 2,
            stderr: &["cannot be used with"],
            outputs: &[],
        },
    ]);
}
