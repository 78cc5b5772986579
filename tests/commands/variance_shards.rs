//! `raywave variance --shard I/N`, `variance merge` and `variance prepare`: a study of two
//! scenes run in four shards and merged gives the single process's report, figure for figure
//! (every figure that does not come from a clock); merges of parts that are missing, repeated,
//! cut short, corrupt, of another study or of a binary with another SIMD path are refused naming
//! the files; concurrent shards render a shared reference once.

use crate::common;

use common::bin::{raywave, scenes, stderr, stdout, words};
use serde_json::Value;
use std::path::Path;

/// A study of two scenes, small enough to run in a second.
pub(crate) const STUDY: &str = r#"
scenes = ["cornell_box.obj", "two_lights.obj"]
samplers = ["random", "stratified", "sobol"]
budgets = [1, 4, 16]
seeds = 3
sizes = [[16, 16]]
reference_samples = 64
mask_samples = 16
"#;

/// A scratch directory with the study file and its two scenes.
pub(crate) fn study_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in ["cornell_box.obj", "two_lights.obj"] {
        std::fs::copy(scenes().join(name), dir.path().join(name)).unwrap();
    }
    std::fs::write(dir.path().join("study.toml"), STUDY).unwrap();
    dir
}

pub(crate) fn ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "exit {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status.code(),
        stdout(out),
        stderr(out)
    );
}

/// Fields of a row that come from a clock or name the machine.
const TIMED: [&str; 8] = [
    "seconds",
    "seconds_interval",
    "rays_per_second",
    "efficiency",
    "efficiency_interval",
    "efficiency_vs_random",
    "efficiency_vs_random_interval",
    "host",
];

/// The figures of a case's results.json that no clock touches: rows (without their timings),
/// slopes, matching budgets, regions, reference error, and each seed's MSE and bias.
fn figures(dir: &Path) -> Value {
    let text = std::fs::read_to_string(dir.join("results.json")).unwrap();
    let mut doc: Value = serde_json::from_str(&text).unwrap();
    for row in doc["rows"].as_array_mut().unwrap() {
        for key in TIMED {
            row.as_object_mut().unwrap().remove(key);
        }
    }
    for seed in doc["seeds"].as_array_mut().unwrap() {
        seed.as_object_mut().unwrap().remove("seconds");
    }
    let mut kept = serde_json::Map::new();
    for key in [
        "rows",
        "slopes",
        "matching",
        "seeds",
        "region_pixels",
        "reference_mse",
    ] {
        kept.insert(key.into(), doc[key].take());
    }
    kept.insert("study".into(), doc["settings"]["study"].take());
    Value::Object(kept)
}

fn bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Runs the four shards, one after another, into `parts/`.
fn shards(dir: &Path, extra: &[&str]) {
    for i in 0..4 {
        let shard = format!("{i}/4");
        let mut args = vec!["variance", "--study", "study.toml", "--shard", &shard];
        args.extend(["--out", "parts", "-q"]);
        args.extend(extra);
        let out = raywave(dir, &args);
        ok(&out);
        assert!(
            stdout(&out).contains(&format!("shard {i}/4: ran ")),
            "{}",
            stdout(&out)
        );
    }
}

/// Asserts that the reports of [`STUDY`] in `single` and `merged` hold the same figures: each
/// case's results.json but for its timings, its perceived-error and spectrum tables, its
/// contact sheet and a heat map, and the whole summary across the cases.
pub(crate) fn assert_same_figures(single: &Path, merged: &Path) {
    for case in ["cornell_box", "two_lights"] {
        let (a, b) = (single.join(case), merged.join(case));
        assert_eq!(figures(&a), figures(&b), "{case}: results.json");
        for file in [
            "perceived.csv",
            "spectra.csv",
            "contact_sheet.png",
            "heat_sobol_N16.png",
        ] {
            assert!(
                bytes(&a.join(file)) == bytes(&b.join(file)),
                "{case}/{file} differs"
            );
        }
    }
    // The summary across the scenes holds no timing: the whole file is the same.
    for file in ["summary.json", "summary.csv"] {
        assert_eq!(
            String::from_utf8(bytes(&single.join(file))).unwrap(),
            String::from_utf8(bytes(&merged.join(file))).unwrap(),
            "{file}"
        );
    }
}

/// Runs the study of [`STUDY`] in `d` in one process into `single/`, and renders its
/// references into `cache/` (`variance prepare`), as a batch run would before its shards.
pub(crate) fn single_and_prepared(d: &Path) {
    ok(&raywave(
        d,
        &words("variance --study study.toml --out single -q --no-cache"),
    ));
    ok(&raywave(
        d,
        &words("variance prepare --study study.toml --cache cache -q"),
    ));
}

/// Merges `d/parts` into `d/merged`, checks that the merge says each of `said`, and that its
/// figures are those of `d/single`.
pub(crate) fn merge_matches_single(d: &Path, said: &[&str]) {
    let merged = raywave(d, &words("variance merge parts --out merged"));
    ok(&merged);
    let out = stdout(&merged);
    for s in said {
        assert!(out.contains(s), "expected {s:?} in:\n{out}");
    }
    assert_same_figures(&d.join("single"), &d.join("merged"));
}

#[test]
fn a_four_way_sharded_study_merges_into_the_single_process_report() {
    let dir = study_dir();
    let d = dir.path();
    ok(&raywave(
        d,
        &words("variance --study study.toml --out single -q --no-cache"),
    ));
    shards(d, &["--no-cache"]);
    merge_matches_single(
        d,
        &["merged  4 shards, 18 jobs, 1 host", "across the cases"],
    );
    let summary: Value = serde_json::from_slice(&bytes(&d.join("merged/summary.json"))).unwrap();
    let slope = summary["slopes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["sampler"] == "random" && s["region"] == "whole")
        .unwrap();
    assert_eq!(slope["per_case"].as_array().unwrap().len(), 2);
    assert!(slope["interval"].is_array(), "{slope}");
}

/// A single-scene study from flags, in shards; returns the scratch dir.
fn flag_shards(cache: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for i in 0..3 {
        let shard = format!("{i}/3");
        let mut args = vec![
            "variance",
            "--size",
            "12",
            "12",
            "--seeds",
            "2",
            "--budgets",
            "1,4",
        ];
        args.extend(["--samplers", "random,sobol", "--reference-samples", "16"]);
        args.extend([
            "--mask-samples",
            "4",
            "--shard",
            &shard,
            "--out",
            "parts",
            "-q",
        ]);
        args.extend(cache);
        ok(&raywave(dir.path(), &args));
    }
    dir
}

#[test]
fn merge_refuses_parts_that_are_missing_repeated_cut_short_corrupt_or_foreign() {
    let dir = flag_shards(&["--no-cache"]);
    let d = dir.path();
    let refused = |args: &[&str], says: &[&str]| {
        let out = raywave(d, args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        for s in says {
            assert!(err.contains(s), "{args:?}: expected {s:?} in:\n{err}");
        }
        assert!(!d.join("report").exists(), "{args:?} wrote a report");
    };
    let p = |i: usize| format!("parts/variance-shard-{i}-of-3.part");
    refused(
        &["variance", "merge", &p(0), &p(2), "--out", "report"],
        &["shard 1/3 is missing", &p(0)],
    );
    refused(
        &[
            "variance",
            "merge",
            &p(0),
            &p(1),
            &p(2),
            &p(1),
            "--out",
            "report",
        ],
        &[&p(1), "given twice"],
    );
    // A part of another study (more seeds) among them.
    std::fs::create_dir(d.join("other")).unwrap();
    let args = [
        "variance",
        "--size",
        "12",
        "12",
        "--seeds",
        "3",
        "--budgets",
        "1,4",
    ];
    let mut args = args.to_vec();
    args.extend([
        "--samplers",
        "random,sobol",
        "--reference-samples",
        "16",
        "--mask-samples",
    ]);
    args.extend(["4", "--shard", "1/3", "--out", "other", "-q", "--no-cache"]);
    ok(&raywave(d, &args));
    refused(
        &[
            "variance",
            "merge",
            &p(0),
            "other/variance-shard-1-of-3.part",
            &p(2),
            "--out",
            "report",
        ],
        &[
            "are not shards of the same study",
            "seeds: 2 in",
            "3 in other/variance-shard-1-of-3.part",
        ],
    );
    // Cut short, as a copy interrupted mid-way leaves it.
    let whole = bytes(&d.join(p(1)));
    std::fs::write(d.join("cut.part"), &whole[..whole.len() / 2]).unwrap();
    refused(
        &[
            "variance",
            "merge",
            &p(0),
            "cut.part",
            &p(2),
            "--out",
            "report",
        ],
        &["cut.part", "truncated"],
    );
    // One bit flipped in the middle.
    let mut flipped = whole.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 0x10;
    std::fs::write(d.join("flipped.part"), &flipped).unwrap();
    refused(
        &[
            "variance",
            "merge",
            &p(0),
            "flipped.part",
            &p(2),
            "--out",
            "report",
        ],
        &["flipped.part", "corrupt"],
    );
    std::fs::write(d.join("text.part"), "not a part\n").unwrap();
    refused(
        &[
            "variance",
            "merge",
            &p(0),
            "text.part",
            &p(2),
            "--out",
            "report",
        ],
        &["text.part", "not a raywave part"],
    );
    // The output directory is the parts' own.
    let out = raywave(d, &["variance", "merge", "parts", "--out", "parts"]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "an output that is an input is a usage error"
    );
    assert!(
        stderr(&out).contains("--out parts is one of the merge's inputs"),
        "{}",
        stderr(&out)
    );
    // The parts named one by one, the report sent beside them.
    let out = raywave(
        d,
        &["variance", "merge", &p(0), &p(1), &p(2), "--out", "parts"],
    );
    assert_eq!(
        out.status.code(),
        Some(2),
        "an output that is an input is a usage error"
    );
    assert!(
        stderr(&out).contains("--out parts holds the part parts/variance-shard-0-of-3.part"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read_dir(d.join("parts")).unwrap().count(), 3);
    // And the parts as they are merge.
    ok(&raywave(
        d,
        &["variance", "merge", "parts", "--out", "report"],
    ));
}

/// Refused, without a report: a non-zero exit and every needle in the error. (The exit code
/// itself is left to the merge's other tests.)
fn refused_naming(d: &Path, args: &[&str], needles: &[&str]) {
    let out = raywave(d, args);
    let err = stderr(&out);
    assert!(
        !out.status.success(),
        "{args:?} merged:\n{}\n{err}",
        stdout(&out)
    );
    for n in needles {
        assert!(err.contains(n), "{args:?}: expected {n:?} in:\n{err}");
    }
    assert!(!d.join("report").exists(), "{args:?} wrote a report");
}

#[test]
fn a_copy_of_a_shard_under_another_name_is_refused_naming_both() {
    // Shard 0, the same file copied under another name, and shard 1 of 2: every shard is
    // there, every part is whole and of this study, and the copy is another file, so only
    // the check that each shard comes once can refuse it.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for i in 0..2 {
        let shard = format!("{i}/2");
        let mut args = vec!["variance", "--size", "8", "8", "--seeds", "2"];
        args.extend(["--budgets", "1,4", "--samplers", "random"]);
        args.extend(["--reference-samples", "4", "--mask-samples", "4"]);
        args.extend(["--heatmap-n", "1", "--no-cache", "--shard", &shard]);
        args.extend(["--out", "parts", "-q"]);
        ok(&raywave(d, &args));
    }
    let (zero, one) = (
        "parts/variance-shard-0-of-2.part",
        "parts/variance-shard-1-of-2.part",
    );
    std::fs::copy(d.join(zero), d.join("copy-of-0.part")).unwrap();
    for order in [[zero, "copy-of-0.part", one], ["copy-of-0.part", one, zero]] {
        let mut args = vec!["variance", "merge"];
        args.extend(order);
        args.extend(["--out", "report"]);
        refused_naming(d, &args, &[zero, "copy-of-0.part", "shard 0/2"]);
    }
    // The two shards alone merge.
    ok(&raywave(
        d,
        &["variance", "merge", zero, one, "--out", "report"],
    ));
}

#[test]
fn merge_refuses_a_part_run_with_another_simd_path_naming_both() {
    use raywave::shard::{Part, read_part, write_part};
    use raywave::variance::study::plan::Study;
    let dir = flag_shards(&["--no-cache"]);
    let d = dir.path();
    // Shard 1 as a binary of the same commit built for the other kind of node would have
    // written it: the identity differs in its SIMD path alone.
    let mut other: Part<Study> = read_part(&d.join("parts/variance-shard-1-of-3.part")).unwrap();
    let ours = raywave::simd_path();
    let theirs = if ours.contains("avx512") {
        "avx2+fma (f32x8 in one 256-bit register)"
    } else {
        "avx512 (f32x16 in one 512-bit register)"
    };
    assert_eq!(other.identity.simd, ours);
    other.identity.simd = theirs.into();
    let written = write_part(&d.join("other-cpu"), &other).unwrap();
    std::fs::rename(written, d.join("other-cpu.part")).unwrap();
    let out = raywave(
        d,
        &words(
            "variance merge parts/variance-shard-0-of-3.part other-cpu.part parts/variance-shard-2-of-3.part --out report",
        ),
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    for needle in [
        "parts/variance-shard-0-of-3.part and other-cpu.part were run by binaries with different SIMD paths",
        &format!("simd: {ours} in parts/variance-shard-0-of-3.part, {theirs} in other-cpu.part"),
    ] {
        assert!(err.contains(needle), "expected {needle:?} in:\n{err}");
    }
    assert!(!d.join("report").exists());
}

#[test]
fn a_shard_out_of_range_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    for (shard, says) in [
        ("0/0", "N is 0, expected at least 1 shard"),
        ("4/4", "shard 4 does not exist"),
        ("x/4", "expected I/N"),
        ("3", "expected I/N"),
    ] {
        let out = raywave(
            dir.path(),
            &["variance", "--shard", shard, "--out", "parts"],
        );
        assert_eq!(out.status.code(), Some(2), "{shard}");
        assert!(stderr(&out).contains(says), "{shard}: {}", stderr(&out));
    }
    assert!(!dir.path().join("parts").exists());
}

#[test]
fn concurrent_shards_render_a_shared_reference_once_and_prepare_renders_it_ahead() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A reference of about a second: long enough that the four processes, started together,
    // all ask for it before the first has written it (without the lock, each renders it).
    let args = |shard: &str| {
        let line = "variance --size 64 64 --seeds 2 --budgets 1,4 --samplers random,sobol \
                    --reference-samples 65536";
        let mut a: Vec<String> = line.split_whitespace().map(String::from).collect();
        a.extend(["--mask-samples", "4", "--cache", "cache", "-q"].map(String::from));
        if !shard.is_empty() {
            a.extend(["--shard", shard, "--out", "parts"].map(String::from));
        }
        a
    };
    let children: Vec<_> = (0..4)
        .map(|i| {
            std::process::Command::new(crate::common::bin::exe())
                .args(args(&format!("{i}/4")))
                .current_dir(d)
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for child in children {
        ok(&child.wait_with_output().unwrap());
    }
    let entries = |d: &Path| {
        std::fs::read_dir(d.join("cache"))
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .ends_with(".rwref")
            })
            .count()
    };
    assert_eq!(entries(d), 1);
    let merged = raywave(d, &["variance", "merge", "parts", "--out", "report"]);
    ok(&merged);
    assert!(
        stdout(&merged).contains("references 1 rendered by a shard, 3 read from the cache"),
        "{}",
        stdout(&merged)
    );
    // `prepare` with other settings renders that reference; the shards then find it.
    std::fs::remove_dir_all(d.join("parts")).unwrap();
    let mut prepare: Vec<String> = args("");
    prepare.insert(1, "prepare".into());
    prepare.extend(["--bounces", "2"].map(String::from));
    let out = raywave(d, &prepare.iter().map(String::as_str).collect::<Vec<_>>());
    ok(&out);
    assert!(
        stdout(&out).contains("builtin: converged reference rendered and cached"),
        "{}",
        stdout(&out)
    );
    assert_eq!(entries(d), 2);
    for i in 0..4 {
        let mut a = args(&format!("{i}/4"));
        a.extend(["--bounces", "2"].map(String::from));
        ok(&raywave(
            d,
            &a.iter().map(String::as_str).collect::<Vec<_>>(),
        ));
    }
    let merged = raywave(d, &["variance", "merge", "parts", "--out", "report2"]);
    ok(&merged);
    assert!(
        stdout(&merged).contains("references 0 rendered by a shard, 4 read from the cache"),
        "{}",
        stdout(&merged)
    );
}
