//! Every command the user-facing pages show is run or checked here (tests/common/docs.rs says
//! how), so no page can drift from the code: README.md, docs/BENCHMARKING.md, docs/DIFF.md
//! and docs/SAMPLING.md. (docs/TRACE.md and README's debug view are also run by
//! tests/commands/trace_pixel.rs, which checks what they wrote.)

use crate::common;

use common::docs::{
    Page, check_cargo, commands, nothing, run_in_page_order, shorten, stale_manual, uncovered,
};
use std::path::Path;

const ROOT: &str = env!("RAYWAVE_REPO");

/// `raywave view` serves until stopped; tests/commands/view_http.rs and view_browser.rs run it.
const VIEW: &str =
    "a server that runs until Ctrl-C; tests/commands/view_http.rs and view_browser.rs run it";

/// README.md: the set-up commands and the tour. Renders run at the page's sizes (each takes
/// under a few seconds in a release build); the variance study is shortened.
const README: Page = Page {
    path: "README.md",
    text: include_str!("../../README.md"),
    quick: &[
        ("variance", "--size", &["16", "16"]),
        ("variance", "--seeds", &["2"]),
        ("variance", "--reference-samples", &["64"]),
        ("variance", "--mask-samples", &["16"]),
    ],
    manual: &[
        ("raywave view", VIEW),
        (
            "raywave view scenes/cornell_box_reflective_spheres.obj --size 256 256 --bounces 3 --port 8080",
            VIEW,
        ),
    ],
    after: nothing,
};

/// docs/BENCHMARKING.md, shortened so that the whole page runs in seconds; the page points
/// here for this table.
const BENCHMARKING: Page = Page {
    path: "docs/BENCHMARKING.md",
    text: include_str!("../../docs/BENCHMARKING.md"),
    quick: &[
        ("bench", "--size", &["24", "24"]),
        ("bench", "--runs", &["6"]),
        ("bench", "--shadow-samples", &["4"]),
        ("render", "--size", &["24", "24"]),
        ("render", "--shadow-samples", &["4"]),
        ("variance", "--size", &["16", "16"]),
        ("variance", "--seeds", &["2"]),
        ("variance", "--reference-samples", &["64"]),
        ("variance", "--mask-samples", &["16"]),
    ],
    manual: &[
        (
            "python3 -m venv /tmp/embree4-venv && /tmp/embree4-venv/bin/pip install embreex==4.4.0",
            "installs a package from PyPI",
        ),
        (
            "export RAYWAVE_EMBREE4_DIR=$(echo /tmp/embree4-venv/lib/python3*/site-packages/embreex.libs)",
            "points the embree4 feature at the wheel installed above",
        ),
        (
            "cargo bench --features embree4 --bench mesh_rays",
            "needs libembree4 (the embreex wheel); .ci/run builds without the embree4 feature",
        ),
        (
            "RAYWAVE_INTERLEAVE=20 cargo bench --features embree4 --bench mesh_rays",
            "needs libembree4 (the embreex wheel); .ci/run builds without the embree4 feature",
        ),
        (
            "RAYWAVE_PEER_TABLE=9 cargo bench --bench mesh_rays --features embree4,tinybvh",
            "needs libembree4 and builds tinybvh's C++; .ci/run builds without either feature",
        ),
        (
            "RAYWAVE_TREE_TABLE=15 cargo bench --bench mesh_rays --features embree4",
            "needs libembree4 (the embreex wheel); .ci/run builds without the embree4 feature",
        ),
    ],
    after: nothing,
};

/// docs/DIFF.md: its renders shortened as BENCHMARKING.md's are, so that the page runs in
/// seconds; the page repeats this table.
const DIFF: Page = Page {
    path: "docs/DIFF.md",
    text: include_str!("../../docs/DIFF.md"),
    quick: &[
        ("render", "--size", &["24", "24"]),
        ("render", "--shadow-samples", &["4"]),
        // The page's thresholds are for its 512×512 images; 24×24 ones with 4 points are noisier.
        ("diff", "--fail-above", &["10"]),
    ],
    manual: &[],
    after: nothing,
};

/// docs/SAMPLING.md: every study at 16×16 with 2 seeds and a cheap reference and mask (the
/// page's "Reproduce" says so); each must write its report.
const SAMPLING: Page = Page {
    path: "docs/SAMPLING.md",
    text: include_str!("../../docs/SAMPLING.md"),
    quick: &[
        ("variance", "--size", &["16", "16"]),
        ("variance", "--seeds", &["2"]),
        ("variance", "--reference-samples", &["64"]),
        ("variance", "--mask-samples", &["16"]),
    ],
    manual: &[],
    after: study_wrote_its_report,
};

const PAGES: [&Page; 4] = [&README, &BENCHMARKING, &DIFF, &SAMPLING];

/// A study (not `--clean-cache`) leaves its table, results, per-seed rows and contact sheet.
fn study_wrote_its_report(dir: &Path, args: &[String]) {
    if args.first().map(String::as_str) != Some("variance")
        || args.iter().any(|a| a == "--clean-cache")
    {
        return;
    }
    let report = args
        .iter()
        .position(|w| w == "--out")
        .map_or("variance-report", |i| args[i + 1].as_str());
    for name in [
        "table.txt",
        "results.json",
        "seeds.csv",
        "contact_sheet.png",
    ] {
        assert!(
            dir.join(report).join(name).is_file(),
            "`raywave {}` left no {report}/{name}",
            args.join(" ")
        );
    }
}

#[test]
fn every_command_is_run_covered_by_ci_or_listed_as_manual() {
    let mut problems = Vec::new();
    for page in PAGES {
        problems.extend(uncovered(page));
        problems.extend(stale_manual(page));
    }
    assert!(
        problems.is_empty(),
        "commands that neither this test nor .ci/run covers (run them here, make them covered, \
         or list them as manual with the page saying why):\n{}",
        problems.join("\n")
    );
}

#[test]
fn readme_commands_run_in_page_order() {
    let ran = run_in_page_order(&README);
    assert!(ran >= 10, "ran only {ran} of README's commands");
}

#[test]
fn benchmarking_commands_run_in_page_order() {
    let ran = run_in_page_order(&BENCHMARKING);
    assert!(ran >= 6, "ran only {ran} of BENCHMARKING.md's commands");
}

#[test]
fn diff_commands_run_in_page_order() {
    let ran = run_in_page_order(&DIFF);
    assert!(ran >= 6, "ran only {ran} of DIFF.md's commands");
}

#[test]
fn sampling_commands_run_in_page_order() {
    let cmds = commands(SAMPLING.text);
    assert!(
        cmds.iter().all(|c| c.starts_with("raywave ")),
        "docs/SAMPLING.md shows only raywave commands: {cmds:?}"
    );
    let ran = run_in_page_order(&SAMPLING);
    assert!(ran >= 5, "ran only {ran} of SAMPLING.md's commands");
}

#[test]
fn continued_lines_are_one_command() {
    let page =
        "```sh\nraywave trace-pixel 1 2 \\\n    --json t.json  # the tree\nraywave info\n```\n";
    assert_eq!(
        commands(page),
        ["raywave trace-pixel 1 2 --json t.json", "raywave info"]
    );
}

#[test]
fn the_shortening_replaces_adds_and_keeps_sweep_points_apart() {
    let quick = BENCHMARKING.quick;
    let out = shorten(
        &["bench", "--size", "512", "512", "--size", "256", "256"],
        quick,
    );
    assert_eq!(
        out.join(" "),
        "bench --size 24 24 --size 32 24 --runs 6 --shadow-samples 4"
    );
    let out = shorten(&["variance", "--seeds", "16", "--out", "x"], SAMPLING.quick);
    assert_eq!(
        out.join(" "),
        "variance --seeds 2 --out x --size 16 16 --reference-samples 64 --mask-samples 16"
    );
    // The A/B mode against this build, in its fewest rounds: `--max-rounds` until decided.
    let out = shorten(&["bench", "--against", "x", "--until-decided"], quick);
    assert_eq!(
        out[1..]
            .join(" ")
            .replace(crate::common::bin::exe(), "THIS"),
        "--against THIS --until-decided --max-rounds 6 --warmup 0 --size 24 24 \
         --shadow-samples 4"
    );
    for as_written in [
        &["bench", "compare", "a", "b"][..],
        &["bench", "list"],
        &[
            "bench",
            "merge",
            "parts/bench-shard-0-of-2.part",
            "--export-bmf",
            "b.json",
        ],
        &["variance", "--clean-cache"],
    ] {
        assert_eq!(shorten(as_written, quick), as_written);
    }
    // A scene path or a flag first: the default command, render.
    let out = shorten(&["scenes/x.obj", "-o", "x.png"], quick);
    assert_eq!(
        out.join(" "),
        "scenes/x.obj -o x.png --size 24 24 --shadow-samples 4"
    );
}

/// CI runs the README's set-up block as written: the two commands of the ```sh block under
/// "## Set up" are, in that order, the first and last commands `.ci/run` runs with cargo. A
/// command line of `.ci/run` is one that starts with `cargo `; what it pipes its output into
/// (`| tee …`) or redirects it to (`> …`) is how CI reads the output, not part of the command.
/// The newcomer's other commands (`cargo install`, `cargo run --release -- ARGS`) come between
/// the two, reusing the first one's build.
/// The commands of the README's set-up block, without their comments.
fn readme_setup(readme: &str) -> Vec<String> {
    let section = &readme[readme
        .find("\n## Set up")
        .expect("README.md has a \"## Set up\" heading")..];
    let mut lines = section.lines().skip_while(|l| !l.starts_with("```sh"));
    assert!(
        lines.next().is_some(),
        "README.md's \"## Set up\" has a ```sh block"
    );
    lines
        .take_while(|l| !l.starts_with("```"))
        .map(|l| l.split(" #").next().unwrap_or("").trim().to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

/// The cargo commands `.ci/run` runs, in order, each without what reads its output.
fn ci_cargo_commands(script: &str) -> Vec<String> {
    script
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("cargo "))
        .map(|l| {
            l.split(['|', '>', '#'])
                .next()
                .unwrap_or("")
                .trim()
                .to_string()
        })
        .collect()
}

/// The README's two commands against `.ci/run`'s: `None` when CI runs exactly the block.
fn mismatch(readme: &str, script: &str) -> Option<String> {
    let setup = readme_setup(readme);
    let ci = ci_cargo_commands(script);
    if setup.len() != 2 {
        return Some(format!(
            "README.md's set-up block has {} command(s), expected two (the render, the tests): {setup:?}",
            setup.len()
        ));
    }
    if ci.first() != Some(&setup[0]) {
        return Some(format!(
            ".ci/run's first cargo command is {:?}, expected the README's first, {:?}",
            ci.first(),
            setup[0]
        ));
    }
    if ci.last() != Some(&setup[1]) {
        return Some(format!(
            ".ci/run's last cargo command is {:?}, expected the README's test command, {:?}",
            ci.last(),
            setup[1]
        ));
    }
    None
}

#[test]
fn ci_runs_the_readme_set_up_block_as_written() {
    let root = Path::new(ROOT);
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let script = std::fs::read_to_string(root.join(".ci/run")).expect(".ci/run");
    if let Some(why) = mismatch(&readme, &script) {
        panic!("{why}");
    }
}

/// The check itself can fail: either README command changed, or dropped from CI, is caught.
#[test]
fn a_changed_readme_command_is_caught() {
    let root = Path::new(ROOT);
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let script = std::fs::read_to_string(root.join(".ci/run")).expect(".ci/run");
    let first = "cargo run --release ";
    let test = "cargo test --release --all-targets";
    assert!(readme.contains(first) && readme.contains(test));
    let changed_render = readme.replacen(first, "cargo run --release --locked ", 1);
    assert!(mismatch(&changed_render, &script).is_some());
    let changed_tests = readme.replacen(test, "cargo test --release", 1);
    assert!(mismatch(&changed_tests, &script).is_some());
    let no_render = script.replace("cargo run --release", "true");
    assert!(mismatch(&readme, &no_render).is_some());
}

#[test]
fn the_checker_refuses_what_ci_does_not_run() {
    for bad in [
        "cargo bench --bench no_such_bench",
        "cargo bench --features embree4 --bench mesh_rays",
        "cargo run --release -- bench",
        "cargo test --release --test no_such_test",
        "cargo test --release --test no_such_test sample_streams::",
        "cargo test --release --test sampling no_such_file::",
        "cargo test --release --test sampling cli::",
        "cargo test --release --test commands trace_demo::",
        "cargo test --release --test commands main::",
        "cargo test --release --test sampling sample_streams:: schema::",
        "cargo bench --bench wavefront -- --profile-time 5",
        "FOO=1 cargo bench --bench variance",
        "RAYWAVE_MESH=2M cargo bench --bench mesh_rays",
        "RAYWAVE_ROUNDS=many cargo bench --bench scaling",
        "RAYWAVE_ROUNDS=0 cargo bench --bench scaling",
        "RAYWAVE_INTERLEAVE=20 cargo test --release --all-targets",
        "RAYWAVE_ROUNDS=9 cargo bench --bench mesh_rays",
        "RAYWAVE_RECORD=1 cargo bench --bench wavefront",
        "RAYWAVE_RECORD=1 cargo test --release --test sampling sample_streams::",
        "RAYWAVE_RECORD=1 cargo test --release --test kernels icount",
        "cargo test --release --test icount",
    ] {
        let words: Vec<&str> = bad.split_whitespace().collect();
        assert!(check_cargo(&words).is_err(), "`{bad}` passed the checker");
    }
    for good in [
        "cargo bench --bench wavefront -- --save-baseline main stages/film",
        "RAYWAVE_RECORD=1 cargo bench --bench variance -- --test",
        "RAYWAVE_RECORD=1 cargo test --release --test gates icount",
        "cargo test --release --test sampling sample_streams::",
        "cargo test --release --test sampling sample_streams::light_points -- --nocapture",
        "cargo test --release --test kernels mesh_bvh::mesh_occlusion::",
        "cargo test --release --test gates icount -- --nocapture",
        "RAYWAVE_INTERLEAVE=20 RAYWAVE_MESH=12k cargo bench --bench mesh_rays",
        "RAYWAVE_ROUNDS=9 cargo bench --bench scaling",
    ] {
        let words: Vec<&str> = good.split_whitespace().collect();
        assert_eq!(check_cargo(&words), Ok(()), "`{good}`");
    }
}

/// docs/examples/bench-regression.yml, the pull-request gate BENCHMARKING.md shows: valid
/// YAML (when python3 has PyYAML), run on pull requests, building the base and the head and
/// timing one against the other until decided, one-sided (a regression or not), failing on
/// exit 3 and only warning on 4; its export step
/// runs here with this build (shortened), so its flags cannot rot.
#[test]
fn the_ci_workflow_example_gates_on_a_regression_and_its_exports_run() {
    let path = Path::new(ROOT).join("docs/examples/bench-regression.yml");
    let text = std::fs::read_to_string(&path).unwrap();
    let page = include_str!("../../docs/BENCHMARKING.md");
    assert!(
        page.contains("examples/bench-regression.yml"),
        "BENCHMARKING.md does not link it"
    );
    let parsed = std::process::Command::new("python3")
        .args([
            "-c",
            "import sys, yaml, json; print(json.dumps(yaml.safe_load(sys.stdin)))",
        ])
        .stdin(std::fs::File::open(&path).unwrap())
        .output();
    match parsed {
        Ok(out) if out.status.success() => {
            let yaml: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            // YAML 1.1 reads the key `on` as true.
            let on = yaml.get("on").or_else(|| yaml.get("true")).unwrap();
            assert!(on.get("pull_request").is_some(), "{on}");
            let steps = yaml["jobs"]["against-base"]["steps"].as_array().unwrap();
            let runs: Vec<&str> = steps.iter().filter_map(|s| s["run"].as_str()).collect();
            for needle in [
                "cargo build --release --locked --manifest-path base/Cargo.toml",
                "cargo build --release --locked --manifest-path head/Cargo.toml",
                "--against base/target/release/raywave",
            ] {
                assert!(
                    runs.iter().any(|r| r.contains(needle)),
                    "no step runs `{needle}`"
                );
            }
            let gate = runs.iter().find(|r| r.contains("--against")).unwrap();
            assert!(gate.contains("3) ") && gate.contains("exit 3"), "{gate}");
            assert!(gate.contains("4) ") && gate.contains("::warning"), "{gate}");
            assert!(
                gate.contains("--until-decided") && gate.contains("--verdict regression"),
                "{gate}"
            );
        }
        _ => println!("SKIPPED the YAML check: no python3 with PyYAML"),
    }
    // The export step, with this build, at a tiny size.
    let export = text
        .split("run: |")
        .find(|block| block.contains("--export-bmf"))
        .unwrap()
        .lines()
        .take_while(|l| !l.trim().starts_with("cat "))
        .collect::<Vec<_>>()
        .join("\n");
    let command = commands(&format!("```sh\n{export}\n```\n")).join(" ");
    let words: Vec<&str> = command.split_whitespace().collect();
    assert_eq!(
        words[..2],
        ["head/target/release/raywave", "bench"],
        "{command}"
    );
    let args = shorten(&words[1..], BENCHMARKING.quick);
    let dir = tempfile::tempdir().unwrap();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = common::bin::raywave(dir.path(), &args);
    assert!(
        out.status.success(),
        "{command}: {}",
        common::bin::stderr(&out)
    );
    for name in ["bmf.json", "gab.json", "bench.md"] {
        assert!(dir.path().join(name).is_file(), "{command} wrote no {name}");
    }
}
