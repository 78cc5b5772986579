//! The JSON Schemas of `--stats-json` files and bench records (docs/schema/, described in
//! docs/SCHEMA.md): the checked-in files are the ones the types generate, so a change to the
//! types without a new schema fails here; and real output of `render --stats-json` (both
//! engines) and `bench --json` / `--save` validates against the checked-in files, while
//! doctored output does not.
//!
//! After changing the types: `RAYWAVE_UPDATE_SCHEMA=1 cargo test --release --test commands schema::`
//! rewrites docs/schema/, then review the diff (and bump `FORMAT` if the layout changed).

use crate::common;

use common::bin::{dir_with, raywave, stderr, words};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn schema_dir() -> PathBuf {
    Path::new(env!("RAYWAVE_REPO")).join("docs/schema")
}

/// The checked-in schema `name`, parsed.
fn checked_in(name: &str) -> Value {
    let path = schema_dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// The validator: python-jsonschema, the reference implementation of JSON Schema (kept by the
/// maintainers of the specification's test suite), which picks the draft from the schema's
/// `$schema`, checks the schema itself, then prints one line per violation of the instance
/// read from stdin. A Rust validator (the jsonschema crate and the regex engines under it) cost
/// every clean build over 30 CPU-seconds; this costs none.
const VALIDATE: &str = r#"
import json, sys
from jsonschema.validators import validator_for
schema = json.load(open(sys.argv[1]))
cls = validator_for(schema)
cls.check_schema(schema)
for e in cls(schema).iter_errors(json.load(sys.stdin)):
    print(e.message, "at /" + "/".join(map(str, e.absolute_path)))
"#;

/// A Python 3 that has the `jsonschema` module: the first of `python3` on the PATH and
/// Debian's `/usr/bin/python3` (where the `python3-jsonschema` package installs it, which
/// `.ci/run` does when neither has it). None outside CI: the caller skips, saying why; in CI a
/// missing validator fails, as a silent pass would be a false green.
fn python() -> Option<&'static str> {
    let found = ["python3", "/usr/bin/python3"].into_iter().find(|p| {
        std::process::Command::new(p)
            .args(["-c", "import jsonschema.validators"])
            .output()
            .is_ok_and(|o| o.status.success())
    });
    if found.is_none() {
        let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false" && v != "0");
        assert!(
            !ci,
            "CI is set but no python3 has the jsonschema module (.ci/run installs python3-jsonschema)"
        );
        println!("SKIPPED: no python3 with the jsonschema module (Debian: python3-jsonschema)");
    }
    found
}

/// Every way `instance` breaks the checked-in schema `name` (empty: it validates), by `python`.
fn violations(python: &str, name: &str, instance: &Value) -> Vec<String> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let mut child = Command::new(python)
        .args(["-c", VALIDATE])
        .arg(schema_dir().join(name))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {python}: {e}"));
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(instance.to_string().as_bytes()).unwrap();
    drop(stdin);
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "docs/schema/{name} is not a usable JSON Schema, or the validator failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

fn assert_valid(python: &str, name: &str, instance: &Value) {
    let v = violations(python, name, instance);
    assert!(v.is_empty(), "{name}:\n{}\n{instance:#}", v.join("\n"));
}

#[test]
fn the_checked_in_schemas_are_the_generated_ones() {
    let update = std::env::var_os("RAYWAVE_UPDATE_SCHEMA").is_some_and(|v| v == "1");
    for (name, generated) in raywave::output::render_record::schemas() {
        let path = schema_dir().join(name);
        if update {
            std::fs::create_dir_all(schema_dir()).unwrap();
            std::fs::write(&path, &generated).unwrap();
            continue;
        }
        let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            on_disk == generated,
            "docs/schema/{name} differs from the schema the types generate: after changing \
             the record types run `RAYWAVE_UPDATE_SCHEMA=1 cargo test --release --test commands schema::`, \
             review the diff, bump FORMAT if the layout changed, and update docs/SCHEMA.md"
        );
    }
}

#[test]
fn the_schemas_pin_the_format_and_name_every_top_level_field() {
    for (name, fields) in [
        (
            "render-record.schema.json",
            &[
                "format",
                "raywave",
                "machine",
                "engine",
                "seconds",
                "rays",
                "kinds_timed_by",
                "stages",
            ][..],
        ),
        (
            "bench-record.schema.json",
            &["format", "raywave", "machine", "setup", "engines"][..],
        ),
    ] {
        let schema = checked_in(name);
        assert_eq!(
            schema["properties"]["format"]["const"],
            json!(raywave::output::bench_record::FORMAT),
            "{name}"
        );
        for field in fields {
            assert!(
                schema["required"]
                    .as_array()
                    .is_some_and(|r| r.contains(&json!(field))),
                "{name} does not require `{field}`"
            );
        }
    }
}

/// `raywave render` with `--stats-json s.json` on a bundled scene, the file parsed.
fn stats_json(engine: &str) -> Value {
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let line = format!(
        "cornell_box_reflective_spheres.obj --size 16 12 --engine {engine} -q -o i.png \
         --stats-json s.json"
    );
    let out = raywave(dir.path(), &words(&line));
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap()
}

#[test]
fn render_stats_json_validates_for_both_engines() {
    let Some(python) = python() else { return };
    for engine in ["wavefront", "reference"] {
        let record = stats_json(engine);
        assert_valid(python, "render-record.schema.json", &record);
        // The meaning, not only the shape: each kind's rate is its rays over its own
        // thread-seconds, the total its rays over the wall clock.
        let rays = &record["rays"];
        for kind in ["camera", "shadow", "reflection"] {
            let k = &rays[kind];
            let (n, t) = (k["rays"].as_f64().unwrap(), k["thread_seconds"].as_f64());
            let t = t.unwrap_or_else(|| panic!("{engine} {kind}: thread_seconds missing"));
            assert!(n > 0.0 && t > 0.0, "{engine} {kind}: {k}");
            let rate = k["rays_per_thread_second"].as_f64().unwrap();
            assert!((rate - n / t).abs() <= 1e-9 * rate, "{engine} {kind}: {k}");
        }
        let total = &rays["total"];
        let expected = total["rays"].as_f64().unwrap() / record["seconds"].as_f64().unwrap();
        let got = total["rays_per_second"].as_f64().unwrap();
        assert!(
            (got - expected).abs() <= 1e-9 * expected,
            "{engine}: {total}"
        );
        let timed_by = if engine == "reference" {
            "instrumented pass"
        } else {
            "stage timers"
        };
        assert_eq!(record["kinds_timed_by"], timed_by);
        assert_eq!(
            record["instrumented_seconds"].is_null(),
            engine == "wavefront"
        );
    }
}

#[test]
fn bench_json_and_saved_records_validate() {
    let Some(python) = python() else { return };
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let out = raywave(
        dir.path(),
        &words(
            "bench cornell_box_reflective_spheres.obj --size 16 12 --runs 2 -q --json - \
             --save s",
        ),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let printed: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_valid(python, "bench-record.schema.json", &printed);
    let saved: Value =
        serde_json::from_slice(&std::fs::read(dir.path().join(".raywave-bench/s.json")).unwrap())
            .unwrap();
    assert_valid(python, "bench-record.schema.json", &saved);
    // The wavefront engine's kinds are measured by its stage timers; the reference's are not
    // (the bench times it without timers) and say so with null.
    for (i, measured) in [(0, false), (1, true)] {
        let rays = &printed["engines"][i]["median"]["rays"];
        for kind in ["camera", "shadow", "reflection"] {
            let rate = &rays[kind]["rays_per_thread_second"];
            assert_eq!(rate.is_number(), measured, "engine {i} {kind}: {rays}");
        }
        assert!(rays["total"]["rays_per_second"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn doctored_records_do_not_validate() {
    let Some(python) = python() else { return };
    let record = stats_json("wavefront");
    type Doctor = fn(&mut Value);
    let doctored: [(&str, Doctor); 6] = [
        ("an older format", |r| r["format"] = json!(2)),
        ("no format", |r| {
            r.as_object_mut().unwrap().remove("format");
        }),
        ("a rate that is text", |r| {
            r["rays"]["total"]["rays_per_second"] = json!("fast")
        }),
        ("a negative ray count", |r| {
            r["rays"]["camera"]["rays"] = json!(-1)
        }),
        ("an unknown engine", |r| r["engine"] = json!("gpu")),
        ("kinds timed some other way", |r| {
            r["kinds_timed_by"] = json!("guessed")
        }),
    ];
    for (what, doctor) in doctored {
        let mut r = record.clone();
        doctor(&mut r);
        assert!(
            !violations(python, "render-record.schema.json", &r).is_empty(),
            "{what} validated"
        );
    }
}

/// The study file's schema (docs/schema/study.schema.json): the checked-in file is the one
/// `StudyFile` generates, a study file the tests run (read by Python's own TOML parser)
/// validates, and one with a misspelt key, a seed count below two or a size of one number
/// does not.
#[test]
fn the_study_file_schema_is_the_generated_one_and_judges_study_files() {
    let name = "study.schema.json";
    let generated = raywave::variance::study::study_file::schema();
    let path = schema_dir().join(name);
    if std::env::var_os("RAYWAVE_UPDATE_SCHEMA").is_some_and(|v| v == "1") {
        std::fs::write(&path, &generated).unwrap();
    }
    assert!(
        std::fs::read_to_string(&path).unwrap_or_default() == generated,
        "docs/schema/{name} differs from the schema `StudyFile` generates: run \
         `RAYWAVE_UPDATE_SCHEMA=1 cargo test --release --test commands schema::` and review the diff"
    );
    let Some(python) = python() else { return };
    let toml = |text: &str| -> Value {
        let out = std::process::Command::new(python)
            .args([
                "-c",
                "import json, sys, tomllib; print(json.dumps(tomllib.loads(sys.argv[1])))",
            ])
            .arg(text)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    assert_valid(python, name, &toml(crate::variance_shards::STUDY));
    for bad in [
        "budget = [4]",
        "seeds = 1",
        "sizes = [[8]]",
        "samplers = [\"randm\"]",
    ] {
        assert!(
            !violations(python, name, &toml(bad)).is_empty(),
            "{bad} validates against docs/schema/{name}"
        );
    }
}

/// The first metric of a BMF file's first benchmark.
fn first_metric(bmf: &mut Value) -> &mut Value {
    let (_, measures) = bmf.as_object_mut().unwrap().iter_mut().next().unwrap();
    let (_, metric) = measures.as_object_mut().unwrap().iter_mut().next().unwrap();
    metric
}

/// A tiny sweep's exports for the trackers, parsed.
fn exports() -> (Value, Value) {
    let dir = tempfile::tempdir().unwrap();
    let flags = "bench --size 16 12 --threads 1,2 --runs 6 --engine wavefront -q";
    let read = |name: &str| -> Value {
        serde_json::from_slice(&std::fs::read(dir.path().join(name)).unwrap()).unwrap()
    };
    let out = raywave(
        dir.path(),
        &words(&format!(
            "{flags} --export-bmf bmf.json --export-github-action-benchmark gab.json"
        )),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    (read("bmf.json"), read("gab.json"))
}

/// Real output validates against the checked-in schemas written from Bencher's reference and
/// github-action-benchmark's README; doctored output does not.
#[test]
fn tracker_exports_validate() {
    let Some(python) = python() else { return };
    let (bmf, gab) = exports();
    assert_valid(python, "bencher-metric-format.schema.json", &bmf);
    assert_valid(python, "github-action-benchmark.schema.json", &gab);
    type Doctor = fn(&mut Value);
    let bmf_doctored: [(&str, Doctor); 4] = [
        ("a metric without a value", |b| {
            first_metric(b).as_object_mut().unwrap().remove("value");
        }),
        ("a bound that is text", |b| {
            first_metric(b)["lower_value"] = json!("12")
        }),
        ("a measure name longer than 64 characters", |b| {
            let (_, measures) = b.as_object_mut().unwrap().iter_mut().next().unwrap();
            measures["m".repeat(65)] = json!({"value": 1.0});
        }),
        ("a benchmark that is a number", |b| b["x"] = json!(3)),
    ];
    let mut b = bmf.clone();
    assert!(first_metric(&mut b)["upper_value"].is_number());
    for (what, doctor) in bmf_doctored {
        let mut b = bmf.clone();
        doctor(&mut b);
        assert!(
            !violations(python, "bencher-metric-format.schema.json", &b).is_empty(),
            "BMF with {what} validated"
        );
    }
    let gab_doctored: [(&str, Doctor); 4] = [
        ("no entries", |g| *g = json!([])),
        ("an entry without a unit", |g| {
            g[0].as_object_mut().unwrap().remove("unit");
        }),
        ("a value that is text", |g| g[0]["value"] = json!("fast")),
        ("a range that is a number", |g| g[0]["range"] = json!(3)),
    ];
    for (what, doctor) in gab_doctored {
        let mut g = gab.clone();
        doctor(&mut g);
        assert!(
            !violations(python, "github-action-benchmark.schema.json", &g).is_empty(),
            "github-action-benchmark JSON with {what} validated"
        );
    }
}
