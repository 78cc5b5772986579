//! `raywave bench --shard I/N --out DIR` and `raywave bench merge`: a tiny sweep run as 3
//! shards (and as 2) and merged equals the sweep run whole in everything that does not depend
//! on timing (points, settings, ray counts, figure names); the split is by cost; a shard
//! without points still writes its file; merge refuses missing, duplicated, truncated,
//! damaged and mismatched parts (other sweep, other SIMD path, other build, other shard count,
//! other machine unless --across-machines), and outputs that are inputs; bad --shard values are usage errors.
//! Tiny images: no timing is asserted.

use crate::common;

use common::bin::{files_in, raywave, stderr, stdout, words};
use raywave::bench::shard::SweepPoints;
use raywave::shard::{Part, read_part, write_part};
use serde_json::{Value, json};
use std::path::Path;
use std::process::Output;

/// The sweep every test shards: 2 sizes × 2 thread counts, 4 points.
pub(crate) const SWEEP: &str = "bench --size 16 16 --size 24 16 --threads 1,2 --runs 6 --shadow-samples 2 --engine wavefront -q";

/// `raywave` with `line` (split at spaces) in `dir`.
pub(crate) fn run(dir: &Path, line: &str) -> Output {
    raywave(dir, &words(line))
}

pub(crate) fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "exit {:?}\n{}\n{}",
        out.status.code(),
        stdout(out),
        stderr(out)
    );
}

/// Exit 1 with every needle in the error; returns the error.
fn refused(out: &Output, needles: &[&str]) -> String {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "{}\n{err}", stdout(out));
    for n in needles {
        assert!(err.contains(n), "missing `{n}` in:\n{err}");
    }
    err
}

/// Runs every shard of `SWEEP` split in `n` into `dir/parts`; returns the part paths, relative.
fn shards(dir: &Path, n: usize) -> Vec<String> {
    (0..n)
        .map(|i| {
            ok(&run(dir, &format!("{SWEEP} --shard {i}/{n} --out parts")));
            format!("parts/bench-shard-{i}-of-{n}.part")
        })
        .collect()
}

pub(crate) fn read(dir: &Path, name: &str) -> Value {
    let text = std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The first column of a CSV export, one per row.
fn csv_points(dir: &Path, name: &str) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect()
}

/// What of a record does not depend on timing: setup (scene hash, settings, threads), run
/// counts, and per engine its ray counts and the names of its headline figures.
fn deterministic(record: &Value) -> Value {
    // A measurement's ray counts, without its times and rates.
    let counts =
        |rays: &Value| json!(["camera", "shadow", "reflection", "total"].map(|k| &rays[k]["rays"]));
    let mut setup = record["setup"].clone();
    setup["scene"]["source"] = Value::Null;
    let engines: Vec<Value> = record["engines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            let figures: Vec<&Value> = e["summary"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| &f["figure"])
                .collect();
            let runs: Vec<Value> = e["runs"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| counts(&r["rays"]))
                .collect();
            json!({"engine": e["engine"], "rays": counts(&e["median"]["rays"]), "run_rays": runs, "figures": figures})
        })
        .collect();
    json!({"setup": setup, "runs": record["runs"], "warmup": record["warmup"], "engines": engines})
}

/// Every export that does not depend on timing's presentation, into `dir`.
fn exports(dir: &str) -> String {
    format!(
        "--export-json {dir}/points.json --export-csv {dir}/rows.csv --export-bmf {dir}/bmf.json \
         --export-github-action-benchmark {dir}/gab.json"
    )
}

#[test]
fn three_shards_merged_equal_the_sweep_run_whole() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("whole")).unwrap();
    std::fs::create_dir(d.join("merged")).unwrap();
    ok(&run(d, &format!("{SWEEP} {}", exports("whole"))));
    let parts = shards(d, 3);
    let merged = run(
        d,
        &format!("bench merge {} {}", parts.join(" "), exports("merged")),
    );
    ok(&merged);
    let text = stdout(&merged);
    for needle in [
        "point   16x16+t1",
        "wavefront  total",
        "merged  3 shard(s), 4 point(s) of one sweep, measured on 1 host(s)",
        "0/3 parts/bench-shard-0-of-3.part: 24x16+t1",
        "summed over the shards",
        "elapsed from the first start to the last end",
    ] {
        assert!(text.contains(needle), "missing `{needle}` in:\n{text}");
    }
    // Points in sweep order, as the sweep run whole lists them.
    let points = csv_points(d, "whole/rows.csv");
    assert_eq!(csv_points(d, "merged/rows.csv"), points);
    let mut distinct = points.clone();
    distinct.dedup();
    assert_eq!(distinct, ["16x16+t1", "16x16+t2", "24x16+t1", "24x16+t2"]);
    let whole = read(d, "whole/points.json");
    let merged = read(d, "merged/points.json");
    let (whole, merged) = (whole.as_array().unwrap(), merged.as_array().unwrap());
    assert_eq!(whole.len(), 4);
    assert_eq!(merged.len(), 4);
    for (w, m) in whole.iter().zip(merged) {
        assert_eq!(deterministic(w), deterministic(m));
    }
    // The trackers' names are the same, whichever way the sweep ran.
    let names = |v: &Value| -> Vec<String> { v.as_object().unwrap().keys().cloned().collect() };
    assert_eq!(
        names(&read(d, "whole/bmf.json")),
        names(&read(d, "merged/bmf.json"))
    );
    let gab_names = |v: &Value| -> Vec<Value> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|e| e["name"].clone())
            .collect()
    };
    assert_eq!(
        gab_names(&read(d, "whole/gab.json")),
        gab_names(&read(d, "merged/gab.json"))
    );
}

#[test]
fn two_shards_split_by_cost_and_merge_in_sweep_order() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 2);
    // Costs, width · height · (1 + 1 light · 2 points) · 7 runs / threads: 16x16+t1 5376,
    // 16x16+t2 2688, 24x16+t1 8064, 24x16+t2 4032. Longest first to the least loaded:
    // 24x16+t1 → 0; 16x16+t1 → 1; 24x16+t2 → 1 (5376 < 8064); 16x16+t2 → 0 (8064 < 9408).
    // By count it would be two and two in sweep order; by cost shard 0 gets the dearest.
    assert_eq!(labels(d, &parts[0]), ["16x16+t2", "24x16+t1"]);
    assert_eq!(labels(d, &parts[1]), ["16x16+t1", "24x16+t2"]);
    let zero = part(d, &parts[0]);
    assert_eq!((zero.shard.index, zero.shard.count), (0, 2));
    assert_eq!(zero.items, [1, 2]);
    assert_eq!(zero.identity.work.points.len(), 4);
    assert!(!zero.host.cpu.is_empty() && !zero.host.hostname.is_empty());
    assert_eq!(zero.results.len(), 2);
    let setups: Vec<_> = zero.results.iter().map(|r| r.setup.clone()).collect();
    let theirs: Vec<_> = [1, 2]
        .iter()
        .map(|&i| zero.identity.work.points[i].setup.clone())
        .collect();
    assert_eq!(setups, theirs);
    // Given in any order, merged in sweep order.
    let out = run(
        d,
        &format!(
            "bench merge {} {} --export-csv rows.csv -q",
            parts[1], parts[0]
        ),
    );
    ok(&out);
    let mut points = csv_points(d, "rows.csv");
    points.dedup();
    assert_eq!(points, ["16x16+t1", "16x16+t2", "24x16+t1", "24x16+t2"]);
    // Quiet: only what was merged.
    assert!(!stdout(&out).contains("point   "), "{}", stdout(&out));
    assert!(
        stdout(&out).starts_with("merged  2 shard(s)"),
        "{}",
        stdout(&out)
    );
    // No temporary file left beside the parts.
    assert_eq!(
        files_in(&d.join("parts")),
        ["bench-shard-0-of-2.part", "bench-shard-1-of-2.part"]
    );
}

#[test]
fn a_shard_without_points_still_writes_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 5);
    let empty = part(d, &parts[4]);
    assert!(empty.items.is_empty() && empty.results.is_empty());
    let out = run(
        d,
        &format!("bench merge {} --export-csv rows.csv -q", parts.join(" ")),
    );
    ok(&out);
    assert!(stdout(&out).contains("4/5 parts/bench-shard-4-of-5.part: no points"));
    let mut points = csv_points(d, "rows.csv");
    points.dedup();
    assert_eq!(points.len(), 4);
}

/// The part `name` in `dir`, as the library reads it.
fn part(dir: &Path, name: &str) -> Part<SweepPoints> {
    read_part(&dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e:#}"))
}

/// Writes the part `from` with `doctor` applied as `to`, whole and with its checksum right (a
/// part made by another build, sweep or machine, not a damaged one).
fn doctor(dir: &Path, from: &str, to: &str, doctor: impl FnOnce(&mut Part<SweepPoints>)) {
    let mut p = part(dir, from);
    doctor(&mut p);
    let scratch = tempfile::tempdir().unwrap();
    let written = write_part(scratch.path(), &p).unwrap();
    std::fs::copy(written, dir.join(to)).unwrap();
}

/// The labels of the points the part `name` ran.
fn labels(dir: &Path, name: &str) -> Vec<String> {
    let p = part(dir, name);
    p.items
        .iter()
        .map(|&i| p.identity.work.points[i].label.clone())
        .collect()
}

#[test]
fn a_doctored_part_with_its_checksum_redone_is_read() {
    // A part rewritten unchanged merges: the refusals below are for what was changed, not for
    // how it was rewritten.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 2);
    doctor(d, &parts[1], &parts[1], |_| {});
    ok(&run(d, &format!("bench merge {} -q", parts.join(" "))));
}

#[test]
fn merge_refuses_missing_duplicated_and_damaged_parts() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 3);
    let merge = |args: &str| run(d, &format!("bench merge {args} -q --export-csv rows.csv"));
    refused(
        &merge(&format!("{} {}", parts[0], parts[2])),
        &["shard 1/3 is missing", &parts[0], &parts[2], "--shard 1/3"],
    );
    refused(
        &merge(&format!(
            "{} {} {} {}",
            parts[0], parts[1], parts[1], parts[2]
        )),
        &[&parts[1], "is given twice"],
    );
    std::fs::copy(d.join(&parts[1]), d.join("copy.part")).unwrap();
    refused(
        &merge(&format!("{} {} copy.part {}", parts[0], parts[1], parts[2])),
        &["shard 1/3 is given twice", &parts[1], "copy.part"],
    );
    // Truncated, as a copy interrupted mid-way leaves it.
    let whole = std::fs::read(d.join(&parts[1])).unwrap();
    std::fs::write(d.join("cut.part"), &whole[..whole.len() / 2]).unwrap();
    refused(
        &merge(&format!("{} cut.part {}", parts[0], parts[2])),
        &["cut.part: truncated"],
    );
    // Damaged: one bit flipped in the payload, so not the bytes that were hashed.
    let mut damaged = whole.clone();
    let mid = damaged.len() / 2;
    damaged[mid] ^= 0x10;
    std::fs::write(d.join("damaged.part"), damaged).unwrap();
    refused(
        &merge(&format!("{} damaged.part {}", parts[0], parts[2])),
        &["damaged.part: corrupt"],
    );
    // Not a part at all, and a part of the JSON format of an earlier raywave.
    std::fs::write(d.join("other.json"), r#"{"format": 2, "engines": []}"#).unwrap();
    refused(&merge("other.json"), &["other.json: not a raywave part"]);
    std::fs::write(
        d.join("old.json"),
        "{\n  \"format\": \"raywave-bench-shard\",\n  \"version\": 1,\n  \"payload\": {}\n}\n",
    )
    .unwrap();
    refused(
        &merge("old.json"),
        &[
            "old.json: written by an earlier raywave",
            "run its shard again",
        ],
    );
    refused(&merge("nothing.json"), &["nothing.json"]);
    assert!(
        !d.join("rows.csv").exists(),
        "a refused merge wrote its export"
    );
}

#[test]
fn a_copy_of_a_shard_under_another_name_is_refused_naming_both() {
    // Shard 0, its copy under another name, shard 1 of 2: no shard is missing, no part is
    // damaged or foreign, so only the check that each shard comes once can refuse it. Only
    // the refusal is asserted, not its exit code.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 2);
    std::fs::copy(d.join(&parts[0]), d.join("copy-of-0.part")).unwrap();
    for order in [
        [parts[0].as_str(), "copy-of-0.part", parts[1].as_str()],
        ["copy-of-0.part", parts[1].as_str(), parts[0].as_str()],
    ] {
        let out = run(
            d,
            &format!("bench merge {} -q --export-csv rows.csv", order.join(" ")),
        );
        let err = stderr(&out);
        assert!(!out.status.success(), "{order:?} merged:\n{}", stdout(&out));
        for n in [parts[0].as_str(), "copy-of-0.part", "shard 0/2"] {
            assert!(err.contains(n), "{order:?}: missing `{n}` in:\n{err}");
        }
        assert!(!d.join("rows.csv").exists(), "{order:?} wrote its export");
    }
    ok(&run(d, &format!("bench merge {} -q", parts.join(" "))));
}

#[test]
fn merge_refuses_parts_of_other_sweeps_builds_and_splits() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 2);
    // Another sweep: the same split of a sweep with other run counts.
    ok(&run(
        d,
        &format!(
            "{} --shard 1/2 --out other",
            SWEEP.replace("--runs 6", "--runs 7")
        ),
    ));
    refused(
        &run(
            d,
            &format!("bench merge {} other/bench-shard-1-of-2.part", parts[0]),
        ),
        &[
            "are not shards of the same sweep",
            &parts[0],
            "other/bench-shard-1-of-2.part",
            "runs: 6 in",
        ],
    );
    // Another scene: the same flags on a scene whose text differs.
    std::fs::copy(
        common::bin::scenes().join("cornell_box.obj"),
        d.join("a.obj"),
    )
    .unwrap();
    ok(&run(d, &format!("{SWEEP} a.obj --shard 0/2 --out scene")));
    ok(&run(d, &format!("{SWEEP} a.obj --shard 1/2 --out scene")));
    refused(
        &run(
            d,
            &format!("bench merge {} scene/bench-shard-1-of-2.part", parts[0]),
        ),
        &["are not shards of the same sweep", "scene.text_hash"],
    );
    // Another build.
    doctor(d, &parts[1], "build.part", |p| {
        let commit = "0123456789abcdef0123456789abcdef01234567";
        p.identity.build.commit = commit.into();
        for r in &mut p.results {
            r.build.commit = commit.into();
        }
    });
    refused(
        &run(d, &format!("bench merge {} build.part", parts[0])),
        &[
            "come from different raywave builds",
            "build.part",
            "commit: ",
        ],
    );
    // Another split of the same sweep: the counts disagree.
    ok(&run(d, &format!("{SWEEP} --shard 1/3 --out three")));
    refused(
        &run(
            d,
            &format!("bench merge {} three/bench-shard-1-of-3.part", parts[0]),
        ),
        &["disagree on the number of shards", "0/2", "1/3"],
    );
    // A part whose points are not its shard's share contradicts itself.
    doctor(d, &parts[1], "points.part", |p| p.items = vec![0, 1]);
    refused(
        &run(d, &format!("bench merge {} points.part", parts[0])),
        &["points.part: inconsistent part", "it ran items [0, 1]"],
    );
}

#[test]
fn merge_refuses_a_part_run_with_another_simd_path_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 2);
    // Shard 1 as a binary of the same commit built for the other kind of node would have left
    // it: another SIMD path, target features and RUSTFLAGS, in the sweep and in every record.
    let ours = part(d, &parts[1]).identity.simd;
    let theirs = if ours.contains("avx512") {
        "avx2+fma (f32x8 in one 256-bit register)"
    } else {
        "avx512 (f32x16 in one 512-bit register)"
    };
    doctor(d, &parts[1], "other-cpu.part", |p| {
        let build = &mut p.identity.build;
        build.rustflags = "-C target-cpu=x86-64-v3".into();
        build.target_features = "avx,avx2,bmi1,bmi2,f16c,fma,lzcnt,movbe,xsave".into();
        let build = build.clone();
        p.identity.simd = theirs.into();
        for r in &mut p.results {
            r.build = build.clone();
            r.simd = theirs.into();
        }
    });
    let err = refused(
        &run(d, &format!("bench merge {} other-cpu.part", parts[0])),
        &[
            "were run by binaries with different SIMD paths",
            &format!("{ours} and {theirs}"),
            &parts[0],
            "other-cpu.part",
            "RUSTFLAGS: ",
        ],
    );
    assert!(!err.contains("are not shards of the same sweep"), "{err}");
    assert!(!d.join("merged").exists());
    // The SIMD path alone, every other field the same: still refused.
    doctor(d, &parts[1], "simd-only.part", |p| {
        p.identity.simd = theirs.into();
        for r in &mut p.results {
            r.simd = theirs.into();
        }
    });
    refused(
        &run(d, &format!("bench merge {} simd-only.part", parts[0])),
        &[
            "were run by binaries with different SIMD paths",
            &format!("simd: {ours} in {}, {theirs} in simd-only.part", parts[0]),
        ],
    );
}

#[test]
fn parts_of_two_machines_merge_only_across_machines_grouped_by_host() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = shards(d, 2);
    doctor(d, &parts[1], &parts[1], |p| {
        p.host.hostname = "elsewhere".into();
        p.host.cpu = "Other CPU".into();
        for r in &mut p.results {
            r.machine.hostname = "elsewhere".into();
            r.machine.cpu = "Other CPU".into();
        }
    });
    let both = parts.join(" ");
    refused(
        &run(d, &format!("bench merge {both} --export-csv rows.csv")),
        &[
            "measured on 2 machines",
            "elsewhere (Other CPU)",
            "--across-machines",
        ],
    );
    assert!(!d.join("rows.csv").exists());
    let out = run(
        d,
        &format!(
            "bench merge {both} --across-machines --export-csv rows.csv --export-bmf bmf.json --export-markdown table.md"
        ),
    );
    ok(&out);
    let text = stdout(&out);
    assert!(text.contains("host    elsewhere · Other CPU"), "{text}");
    assert!(text.contains("measured on 2 host(s)"), "{text}");
    // Grouped by host, hosts in the order of their first point: the other machine's (shard 1
    // ran 16x16+t1, the sweep's first point), then this one's, each in sweep order.
    let csv = std::fs::read_to_string(d.join("rows.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.ends_with(",host"), "{header}");
    let rows: Vec<(String, String)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            (cells[0].to_string(), cells[cells.len() - 1].to_string())
        })
        .collect();
    let mut order: Vec<(String, String)> = rows.clone();
    order.dedup();
    let here = order[2].1.clone();
    assert_ne!(here, "elsewhere");
    assert_eq!(
        order,
        [
            ("16x16+t1".to_string(), "elsewhere".to_string()),
            ("24x16+t2".to_string(), "elsewhere".to_string()),
            ("16x16+t2".to_string(), here.clone()),
            ("24x16+t1".to_string(), here),
        ]
    );
    let bmf = read(d, "bmf.json");
    assert!(
        bmf.as_object()
            .unwrap()
            .keys()
            .any(|k| k.ends_with(" @ elsewhere")),
        "{bmf}"
    );
    let table = std::fs::read_to_string(d.join("table.md")).unwrap();
    assert!(table.starts_with("| host | point |"), "{table}");
    assert!(table.contains("elsewhere: Other CPU"), "{table}");
}

#[test]
fn merge_refuses_an_output_that_is_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let one = "bench --size 16 16 --runs 6 --shadow-samples 2 --engine wavefront -q";
    ok(&run(d, &format!("{one} --shard 0/2 --out parts")));
    ok(&run(d, &format!("{one} --shard 1/2 --out parts")));
    let before = std::fs::read(d.join("parts/bench-shard-0-of-2.part")).unwrap();
    let parts = "parts/bench-shard-0-of-2.part parts/bench-shard-1-of-2.part";
    for outputs in [
        "--export-json parts/bench-shard-0-of-2.part",
        "--export-bmf parts/bench-shard-1-of-2.part",
        "--export-csv parts/../parts/bench-shard-1-of-2.part",
    ] {
        let out = run(d, &format!("bench merge {parts} {outputs}"));
        assert_eq!(out.status.code(), Some(2), "{outputs}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("is the same file as the input PARTS"),
            "{}",
            stderr(&out)
        );
    }
    assert_eq!(
        std::fs::read(d.join("parts/bench-shard-0-of-2.part")).unwrap(),
        before
    );
    // Saved elsewhere, the single point keeps its plain name.
    let out = run(d, &format!("bench merge {parts} --dir records --save one"));
    ok(&out);
    assert_eq!(files_in(&d.join("records")), ["one.json"]);
}

#[test]
fn bad_shard_flags_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (flags, needle) in [
        ("--shard 0/0 --out p", "N is 0"),
        ("--shard 4/4 --out p", "shard 4 does not exist"),
        ("--shard x/4 --out p", "expected I/N"),
        ("--shard=-1/4 --out p", "expected I/N"),
        ("--shard 0/2", "--out <DIR>"),
        ("--out p", "--shard <I/N>"),
        ("--shard 0/2 --out p --save s", "cannot be used with"),
        (
            "--shard 0/2 --out p --export-csv a.csv",
            "cannot be used with",
        ),
        ("--shard 0/2 --out p --compare base", "cannot be used with"),
    ] {
        let out = run(d, &format!("bench --size 16 16 --runs 6 {flags}"));
        assert_eq!(out.status.code(), Some(2), "{flags}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{flags}: {}", stderr(&out));
    }
    let out = run(d, "bench merge");
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(files_in(d).is_empty(), "{:?}", files_in(d));
}
