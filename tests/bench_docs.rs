//! Every command in docs/BENCHMARKING.md is run or checked here, so the page cannot drift from
//! the code.
//!
//! ```text
//! for each line of every ```sh block of docs/BENCHMARKING.md (comments stripped):
//!     raywave ...      run with the built binary in one temporary directory, in page order,
//!                      shortened (QUICK below: smaller images, one run, fewer seeds); exit 0
//!                      (a `--compare` may also exit 3: tiny timings are noise)
//!     cargo ...        must be a command `.ci/run` covers: `cargo bench`/`cargo test` of a
//!                      target that exists, with only the flags listed below; `.ci/run`
//!                      (`cargo test --release --all-targets`) builds every target and runs each
//!                      benchmark once in criterion's test mode
//!     anything else    must be in MANUAL, with the page saying why
//! ```
//!
//! A command added to the page that is none of these fails the test. Nested `cargo` is never
//! run from here (it would wait on the target directory's lock this test build holds).

use std::collections::BTreeSet;
mod common;

use common::bin::{raywave, stderr, stdout};
use std::path::Path;

const DOC: &str = include_str!("../docs/BENCHMARKING.md");
const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Commands not run by CI, each with the reason the page gives.
const MANUAL: [(&str, &str); 3] = [
    (
        "sudo apt-get install libembree-dev",
        "installs a system package",
    ),
    (
        "cargo bench --features embree --bench mesh_rays",
        "needs libembree3; .ci/run builds without the embree feature",
    ),
    (
        "RAYWAVE_INTERLEAVE=20 cargo bench --features embree --bench mesh_rays",
        "needs libembree3; .ci/run builds without the embree feature",
    ),
];

/// How the test shortens a `raywave` command: (subcommand, flag, values). A flag the command
/// gives is replaced, one it lacks is added. docs/BENCHMARKING.md repeats this table.
const QUICK: [(&str, &str, &[&str]); 10] = [
    ("bench", "--size", &["24", "24"]),
    ("bench", "--runs", &["1"]),
    ("bench", "--shadow-samples", &["4"]),
    ("render", "--size", &["24", "24"]),
    ("render", "--shadow-samples", &["4"]),
    ("variance", "--size", &["16", "16"]),
    ("variance", "--seeds", &["2"]),
    ("variance", "--reference-samples", &["64"]),
    ("variance", "--mask-samples", &["16"]),
    // The page's thresholds are for its 512×512 images; 24×24 ones with 4 points are noisier.
    ("diff", "--fail-above", &["10"]),
];

/// The ```sh lines of the page, comments and blank lines dropped.
fn commands(doc: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_sh = false;
    for line in doc.lines() {
        let trimmed = line.trim();
        if let Some(lang) = trimmed.strip_prefix("```") {
            in_sh = !in_sh && matches!(lang, "sh" | "bash" | "shell" | "console");
            continue;
        }
        if !in_sh {
            continue;
        }
        let command = trimmed.split(" #").next().unwrap_or("").trim();
        if !command.is_empty() && !command.starts_with('#') {
            out.push(command.to_string());
        }
    }
    out
}

/// Names declared by `[[bench]]` in Cargo.toml.
fn bench_targets() -> BTreeSet<String> {
    let toml = std::fs::read_to_string(Path::new(ROOT).join("Cargo.toml")).unwrap();
    let mut names = BTreeSet::new();
    let mut in_bench = false;
    for line in toml.lines().map(str::trim) {
        if line.starts_with('[') {
            in_bench = line == "[[bench]]";
        } else if in_bench && let Some(v) = line.strip_prefix("name") {
            names.insert(
                v.trim_start_matches([' ', '='])
                    .trim_matches('"')
                    .to_string(),
            );
        }
    }
    names
}

/// Integration tests: the files of tests/.
fn test_targets() -> BTreeSet<String> {
    std::fs::read_dir(Path::new(ROOT).join("tests"))
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            if p.extension()? != "rs" {
                return None;
            }
            Some(p.file_stem()?.to_string_lossy().into_owned())
        })
        .collect()
}

/// Why a `cargo` command is not covered by `.ci/run`, or Ok.
fn check_cargo(words: &[&str]) -> Result<(), String> {
    let mut words = words;
    // Environment assignments the page may use, each only on the command it belongs to: the
    // deliberate re-record switch (the variance bench, the icount test), and the switches of
    // two benches' measuring modes. CI runs those benches in test mode, which ignores the
    // switches but runs the same measuring code once (mesh_rays: one interleaved round;
    // scaling: one round at 64²).
    let mut env = Vec::new();
    while let Some(w) = words.first().filter(|w| w.contains('=')) {
        env.push(*w);
        words = &words[1..];
    }
    let target = |flag: &str| {
        words
            .iter()
            .position(|w| *w == flag)
            .and_then(|i| words.get(i + 1))
            .copied()
    };
    let positive = |v: &str| v.parse::<u32>().is_ok_and(|n| n > 0);
    for w in &env {
        let (bench, test) = (target("--bench"), target("--test"));
        let known = match w.split_once('=') {
            Some(("RAYWAVE_RECORD", "1")) => bench == Some("variance") || test == Some("icount"),
            Some(("RAYWAVE_INTERLEAVE", v)) => positive(v) && bench == Some("mesh_rays"),
            Some(("RAYWAVE_MESH", "12k" | "1M")) => bench == Some("mesh_rays"),
            Some(("RAYWAVE_ROUNDS", v)) => positive(v) && bench == Some("scaling"),
            _ => false,
        };
        if !known {
            return Err(format!(
                "environment assignment {w} is not one this command takes"
            ));
        }
    }
    let (cargo_args, program_args) = match words.iter().position(|w| *w == "--") {
        Some(i) => (&words[..i], &words[i + 1..]),
        None => (words, &[][..]),
    };
    let [cargo, sub, rest @ ..] = cargo_args else {
        return Err("expected `cargo SUBCOMMAND ...`".into());
    };
    if *cargo != "cargo" {
        return Err("not a cargo command".into());
    }
    let mut i = 0;
    while i < rest.len() {
        match (rest[i], rest.get(i + 1)) {
            ("--release" | "--all-targets", _) => i += 1,
            ("--bench", Some(name)) if *sub != "build" => {
                if !bench_targets().contains(*name) {
                    return Err(format!("no [[bench]] named {name} in Cargo.toml"));
                }
                i += 2;
            }
            ("--test", Some(name)) if *sub == "test" => {
                if !test_targets().contains(*name) {
                    return Err(format!("no tests/{name}.rs"));
                }
                i += 2;
            }
            (flag, _) => {
                return Err(format!(
                    "`{flag}` is not built by .ci/run (cargo test --release --all-targets)"
                ));
            }
        }
    }
    match *sub {
        "build" | "test" => {
            if let Some(a) = program_args.iter().find(|a| **a != "--nocapture") {
                return Err(format!("test argument {a} is not what .ci/run passes"));
            }
        }
        "bench" => {
            // Criterion's own flags: .ci/run runs the same target once in test mode.
            let mut j = 0;
            while j < program_args.len() {
                match program_args[j] {
                    "--save-baseline" | "--baseline" | "--warm-up-time" | "--measurement-time"
                    | "--noise-threshold" | "--sample-size"
                        if j + 1 < program_args.len() =>
                    {
                        j += 2
                    }
                    "--test" | "--quick" => j += 1,
                    filter if !filter.starts_with('-') => j += 1,
                    flag => return Err(format!("criterion flag {flag} is not in the list")),
                }
            }
        }
        other => return Err(format!("cargo {other} is not run by .ci/run")),
    }
    Ok(())
}

/// The command with QUICK's values for its subcommand. A `bench --against OTHER` runs
/// against this build itself (an A/A comparison), in its fewest rounds and without `--runs`
/// (which the A/B mode does not take).
fn shorten(words: &[&str]) -> Vec<String> {
    let sub = words.get(1).copied().unwrap_or("");
    let mut out: Vec<String> = words.iter().map(|w| w.to_string()).collect();
    if let Some(i) = out.iter().position(|w| w == "--against") {
        out[i + 1] = env!("CARGO_BIN_EXE_raywave").to_string();
        out.extend(["--rounds", "6", "--warmup", "0"].map(String::from));
    }
    let ab = out.iter().any(|w| w == "--against");
    for (s, flag, values) in QUICK {
        if s != sub || (ab && flag == "--runs") {
            continue;
        }
        if let Some(i) = out.iter().position(|w| w == flag) {
            out.splice(
                i + 1..i + 1 + values.len(),
                values.iter().map(|v| v.to_string()),
            );
        } else {
            out.push(flag.to_string());
            out.extend(values.iter().map(|v| v.to_string()));
        }
    }
    out
}

#[test]
fn the_page_has_commands_and_manual_ones_are_still_on_it() {
    let cmds = commands(DOC);
    assert!(
        cmds.iter().filter(|c| c.starts_with("raywave ")).count() >= 6,
        "expected the page's raywave commands, found {cmds:?}"
    );
    for (command, why) in MANUAL {
        assert!(
            cmds.iter().any(|c| c == command),
            "MANUAL lists `{command}` ({why}), which is no longer on the page: remove it"
        );
    }
}

#[test]
fn ci_runs_the_readme_test_command() {
    let run = std::fs::read_to_string(Path::new(ROOT).join(".ci/run")).unwrap();
    let last = run
        .lines()
        .map(str::trim)
        .rfind(|l| !l.is_empty() && !l.starts_with('#'))
        .unwrap_or("");
    assert_eq!(
        last, "cargo test --release --all-targets",
        ".ci/run changed"
    );
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    assert!(readme.contains("cargo test --release --all-targets"));
}

#[test]
fn cargo_commands_are_covered_by_ci_and_others_are_listed() {
    let mut problems = Vec::new();
    for command in commands(DOC) {
        let words: Vec<&str> = command.split_whitespace().collect();
        if words[0] == "raywave" || MANUAL.iter().any(|(m, _)| *m == command) {
            continue;
        }
        if let Err(why) = check_cargo(&words) {
            problems.push(format!("`{command}`: {why}"));
        }
    }
    assert!(
        problems.is_empty(),
        "commands in docs/BENCHMARKING.md that neither this test nor .ci/run covers (run them \
         here, make them covered, or list them in MANUAL with the page saying why):\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_checker_refuses_what_ci_does_not_run() {
    for bad in [
        "cargo bench --bench no_such_bench",
        "cargo bench --features embree --bench mesh_rays",
        "cargo run --release -- bench",
        "cargo test --release --test no_such_test",
        "cargo bench --bench wavefront -- --profile-time 5",
        "FOO=1 cargo bench --bench variance",
        "RAYWAVE_MESH=2M cargo bench --bench mesh_rays",
        "RAYWAVE_ROUNDS=many cargo bench --bench scaling",
        "RAYWAVE_ROUNDS=0 cargo bench --bench scaling",
        "RAYWAVE_INTERLEAVE=20 cargo test --release --all-targets",
        "RAYWAVE_ROUNDS=9 cargo bench --bench mesh_rays",
        "RAYWAVE_RECORD=1 cargo bench --bench wavefront",
    ] {
        let words: Vec<&str> = bad.split_whitespace().collect();
        assert!(check_cargo(&words).is_err(), "`{bad}` passed the checker");
    }
    for good in [
        "cargo bench --bench wavefront -- --save-baseline main stages/film",
        "RAYWAVE_RECORD=1 cargo bench --bench variance -- --test",
        "RAYWAVE_RECORD=1 cargo test --release --test icount",
        "RAYWAVE_INTERLEAVE=20 RAYWAVE_MESH=12k cargo bench --bench mesh_rays",
        "RAYWAVE_ROUNDS=9 cargo bench --bench scaling",
    ] {
        let words: Vec<&str> = good.split_whitespace().collect();
        assert_eq!(check_cargo(&words), Ok(()), "`{good}`");
    }
}

#[test]
fn raywave_commands_run_in_page_order() {
    let dir = tempfile::tempdir().unwrap();
    // The page's `scene.obj`: one of the bundled scenes.
    std::fs::copy(
        Path::new(ROOT).join("scenes/cornell_box.obj"),
        dir.path().join("scene.obj"),
    )
    .unwrap();
    let mut ran = 0;
    for command in commands(DOC) {
        let words: Vec<&str> = command.split_whitespace().collect();
        if words[0] != "raywave" {
            continue;
        }
        assert!(
            !command.contains(['"', '\'', '|', '>', '<', '$', '`']),
            "`{command}`: quoting, pipes and redirections are not supported here"
        );
        let args = shorten(&words);
        let flags: Vec<&str> = args[1..].iter().map(String::as_str).collect();
        let out = raywave(dir.path(), &flags);
        let (stdout, stderr) = (stdout(&out), stderr(&out));
        let code = out.status.code();
        // A comparison of sub-millisecond renders may call noise a regression (exit 3); it must
        // still have compared.
        let compared = (words.contains(&"--compare") && stdout.contains("verdict:")
            || words.contains(&"--against") && stdout.contains("95% interval"))
            && code == Some(3);
        assert!(
            code == Some(0) || compared,
            "`{command}` (run as `{}`) exited {code:?}:\n{stdout}\n{stderr}",
            args.join(" ")
        );
        println!("ran `{}`: exit {code:?}", args.join(" "));
        ran += 1;
    }
    assert!(ran >= 6, "ran only {ran} raywave commands");
}
