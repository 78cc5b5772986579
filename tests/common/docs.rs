//! Running the commands a documentation page shows, so that no page can drift from the code.
//!
//! ```text
//! for each line of every ```sh block of the page (comments stripped):
//!     raywave ...                 run with the built binary in one scratch directory holding a
//!     cargo run --release [-- A]  copy of scenes/, in page order, shortened by the page's
//!                                 QUICK table; exit 0 (a comparison may also exit 3, having
//!                                 compared)
//!     cargo ...                   must be a command `.ci/run` covers: `cargo bench`/`cargo
//!                                 test` of a target that exists, with only known flags
//!     anything else               must be in the page's MANUAL list, with the page saying why
//! ```

use super::bin::{raywave, scenes, stderr, stdout};
use std::collections::BTreeSet;
use std::path::Path;

const ROOT: &str = env!("RAYWAVE_REPO");

/// How to shorten one subcommand's runs: (subcommand, flag, values). A flag the command gives
/// is replaced, one it lacks is added.
pub type Quick = [(&'static str, &'static str, &'static [&'static str])];

/// A page and how its commands are run.
pub struct Page {
    /// Path from the repository root, for messages.
    pub path: &'static str,
    /// The page's text.
    pub text: &'static str,
    /// Shortenings.
    pub quick: &'static Quick,
    /// Commands not run, each with the reason the page gives.
    pub manual: &'static [(&'static str, &'static str)],
    /// Checks what a command left in the scratch directory (its arguments as run).
    pub after: fn(&Path, &[String]),
}

/// An `after` that checks nothing.
pub fn nothing(_: &Path, _: &[String]) {}

/// The ```sh lines of a page, comments and blank lines dropped, a line ending in `\` joined
/// with the next.
pub fn commands(doc: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_sh = false;
    let mut pending = String::new();
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
        if let Some(head) = command.strip_suffix('\\') {
            pending.push_str(head.trim_end());
            pending.push(' ');
            continue;
        }
        let whole = std::mem::take(&mut pending) + command;
        let whole = whole.trim();
        if !whole.is_empty() && !whole.starts_with('#') {
            out.push(whole.to_string());
        }
    }
    out
}

/// The binary's arguments when `words` runs it: `raywave ARGS` or `cargo run --release [--
/// ARGS]`; `None` for any other command.
pub fn raywave_args<'a>(words: &[&'a str]) -> Option<Vec<&'a str>> {
    match words {
        ["raywave", args @ ..] => Some(args.to_vec()),
        ["cargo", "run", "--release"] => Some(Vec::new()),
        ["cargo", "run", "--release", "--", args @ ..] => Some(args.to_vec()),
        _ => None,
    }
}

/// The subcommand `args` runs: `render` when the first word is a scene, a flag or absent.
fn subcommand(args: &[String]) -> &str {
    match args.first().map(String::as_str) {
        Some(w) if !w.starts_with('-') && !w.contains(['.', '/']) => w,
        _ => "render",
    }
}

/// `args` with QUICK's values for its subcommand. Every occurrence of a flag is shortened (a
/// bench sweep repeats `--size`: the k-th size is made 8k pixels wider, so that its points stay
/// distinct). A `bench --against OTHER` runs against this build itself (an A/A comparison), in
/// its fewest rounds (`--max-rounds` with `--until-decided`) and without `--runs` (which the A/B
/// mode does not take). `bench compare`, `bench list`, `bench merge` and `variance
/// --clean-cache` take no image flags and run as written.
pub fn shorten(args: &[&str], quick: &Quick) -> Vec<String> {
    let mut out: Vec<String> = args.iter().map(|w| w.to_string()).collect();
    let sub = subcommand(&out).to_string();
    let as_written = (sub == "bench"
        && matches!(args.get(1).copied(), Some("compare" | "list" | "merge")))
        || (sub == "variance" && args.contains(&"--clean-cache"));
    if as_written {
        return out;
    }
    if let Some(i) = out.iter().position(|w| w == "--against") {
        out[i + 1] = crate::common::bin::exe().to_string();
        let rounds = if out.iter().any(|w| w == "--until-decided") {
            "--max-rounds"
        } else {
            "--rounds"
        };
        out.extend([rounds, "6", "--warmup", "0"].map(String::from));
    }
    let ab = out.iter().any(|w| w == "--against");
    for (s, flag, values) in quick {
        if *s != sub || (ab && *flag == "--runs") {
            continue;
        }
        let at: Vec<usize> = (0..out.len()).filter(|&i| out[i] == *flag).collect();
        for (k, &i) in at.iter().enumerate() {
            let mut values: Vec<String> = values.iter().map(|v| v.to_string()).collect();
            if *flag == "--size" {
                let w: usize = values[0].parse().unwrap();
                values[0] = (w + 8 * k).to_string();
            }
            out.splice(i + 1..i + 1 + values.len(), values);
        }
        if at.is_empty() {
            out.push(flag.to_string());
            out.extend(values.iter().map(|v| v.to_string()));
        }
    }
    out
}

/// Copies the folder `from` to `to`, subfolders (RPI's scenes, textures) included.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_tree(&path, &target);
        } else {
            std::fs::copy(&path, target).unwrap();
        }
    }
}

/// Runs every raywave command of `page` in page order in one scratch directory (holding a copy
/// of scenes/ and, as `scene.obj`, the bundled Cornell box); returns how many ran.
pub fn run_in_page_order(page: &Page) -> usize {
    let dir = tempfile::tempdir().unwrap();
    copy_tree(&scenes(), &dir.path().join("scenes"));
    std::fs::copy(
        scenes().join("cornell_box.obj"),
        dir.path().join("scene.obj"),
    )
    .unwrap();
    let mut ran = 0;
    for command in commands(page.text) {
        let words: Vec<&str> = command.split_whitespace().collect();
        let Some(args) = raywave_args(&words) else {
            continue;
        };
        if page.manual.iter().any(|(m, _)| *m == command) {
            continue;
        }
        assert!(
            !command.contains(['"', '\'', '|', '>', '<', '$', '`']),
            "{}: `{command}`: quoting, pipes and redirections are not supported here",
            page.path
        );
        let args = shorten(&args, page.quick);
        let flags: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = raywave(dir.path(), &flags);
        let (stdout, stderr) = (stdout(&out), stderr(&out));
        let code = out.status.code();
        // A comparison of sub-millisecond renders may call noise a regression (exit 3), or leave
        // it undecided at --until-decided's budget (exit 4); it must still have compared.
        let until_decided = args.iter().any(|a| a == "--until-decided");
        let compared = code == Some(3)
            && (args.iter().any(|a| a == "--compare" || a == "compare")
                && stdout.contains("verdict")
                || args.iter().any(|a| a == "--against") && stdout.contains("interval"))
            || code == Some(4) && until_decided && stdout.contains("undecided at the budget");
        assert!(
            code == Some(0) || compared,
            "{}: `{command}` (run as `raywave {}`) exited {code:?}:\n{stdout}\n{stderr}",
            page.path,
            args.join(" ")
        );
        println!(
            "{}: ran `raywave {}`: exit {code:?}",
            page.path,
            args.join(" ")
        );
        ran += 1;
    }
    ran
}

/// Commands of `page` that are neither run here nor covered by `.ci/run` nor listed as manual.
pub fn uncovered(page: &Page) -> Vec<String> {
    let mut problems = Vec::new();
    for command in commands(page.text) {
        let words: Vec<&str> = command.split_whitespace().collect();
        if raywave_args(&words).is_some() || page.manual.iter().any(|(m, _)| *m == command) {
            continue;
        }
        if let Err(why) = check_cargo(&words) {
            problems.push(format!("{}: `{command}`: {why}", page.path));
        }
    }
    problems
}

/// Manual commands the page no longer shows.
pub fn stale_manual(page: &Page) -> Vec<String> {
    let cmds = commands(page.text);
    page.manual
        .iter()
        .filter(|(m, _)| !cmds.iter().any(|c| c == m))
        .map(|(m, why)| {
            format!(
                "{}: MANUAL lists `{m}` ({why}), no longer on the page",
                page.path
            )
        })
        .collect()
}

/// The targets of one kind (`bench` or `test`) declared in the two manifests (the top one and
/// tests/Cargo.toml's): name and path from the top folder (empty when the table gives none).
fn targets(kind: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for folder in ["", "tests/"] {
        let path = Path::new(ROOT).join(folder).join("Cargo.toml");
        let manifest: toml::Table = std::fs::read_to_string(&path)
            .unwrap()
            .parse()
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let tables = manifest.get(kind).and_then(toml::Value::as_array);
        for target in tables.into_iter().flatten() {
            let field = |key: &str| target.get(key).and_then(toml::Value::as_str);
            let name = field("name").unwrap_or_default().to_string();
            let path = field("path").map_or(String::new(), |p| format!("{folder}{p}"));
            out.push((name, path));
        }
    }
    out
}

/// Names declared by `[[bench]]` in Cargo.toml.
fn bench_targets() -> BTreeSet<String> {
    targets("bench").into_iter().map(|(name, _)| name).collect()
}

/// Why `filter` (the test name filter after `--test NAME`) selects nothing that the docs can
/// mean, or Ok. A kind's binary (`tests/KIND/main.rs`) holds one module per file, so its filter
/// must start with one of them (`sample_streams::`, `sample_streams::light_points`); a
/// one-file binary takes any filter.
fn check_filter(test: &str, path: &str, filter: &str) -> Result<(), String> {
    let Some(dir) = path.strip_suffix("/main.rs") else {
        return Ok(());
    };
    let module = filter.split("::").next().unwrap_or("");
    if !module.is_empty()
        && module != "main"
        && Path::new(ROOT)
            .join(dir)
            .join(format!("{module}.rs"))
            .is_file()
    {
        return Ok(());
    }
    Err(format!(
        "the filter {filter} names no file of the test binary {test} (a filter starts with \
         one, as in `--test {test} FILE::`)"
    ))
}

/// Why a `cargo` command is not covered by `.ci/run`, or Ok.
pub fn check_cargo(words: &[&str]) -> Result<(), String> {
    let mut words = words;
    // Environment assignments a page may use, each only on the command it belongs to: the
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
    // The icount gate: its file in the gates binary (`--test gates icount`).
    let filter = words
        .iter()
        .position(|w| *w == "--test")
        .and_then(|i| words.get(i + 2))
        .filter(|w| !w.starts_with('-'));
    let icount =
        target("--test") == Some("gates") && filter.is_some_and(|f| f.starts_with("icount"));
    for w in &env {
        let bench = target("--bench");
        let known = match w.split_once('=') {
            Some(("RAYWAVE_RECORD", "1")) => bench == Some("variance") || icount,
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
                let tests = targets("test");
                let Some((_, path)) = tests.iter().find(|(n, _)| n == name) else {
                    return Err(format!("no [[test]] named {name} in Cargo.toml"));
                };
                i += 2;
                // An optional test name filter: `--test sampling sample_streams::`.
                if let Some(filter) = rest.get(i).filter(|w| !w.starts_with('-')) {
                    check_filter(name, path, filter)?;
                    i += 1;
                }
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
