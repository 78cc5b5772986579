//! Every `raywave` command in docs/SAMPLING.md is run here, shortened, so the page cannot drift
//! from the code.
//!
//! ```text
//! for each line of every ```sh block of docs/SAMPLING.md (comments stripped):
//!     raywave ...   run with the built binary in one temporary directory (holding the page's
//!                   scenes/ files), in page order, shortened by QUICK (16×16, 2 seeds, a cheap
//!                   reference and mask); exit 0, and a study writes its report
//!     anything else fails the test: the page shows only raywave commands
//! ```

mod common;

use common::bin::{raywave, scenes, stderr, stdout};
use std::path::Path;

const DOC: &str = include_str!("../docs/SAMPLING.md");

/// How the test shortens a `raywave variance` study: (flag, values). A flag the command gives
/// is replaced, one it lacks is added. docs/SAMPLING.md's "Reproduce" says so.
const QUICK: [(&str, &[&str]); 4] = [
    ("--size", &["16", "16"]),
    ("--seeds", &["2"]),
    ("--reference-samples", &["64"]),
    ("--mask-samples", &["16"]),
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

/// The command with QUICK's values; `--clean-cache` runs as written (it takes no study flags).
fn shorten(words: &[&str]) -> Vec<String> {
    let mut out: Vec<String> = words.iter().map(|w| w.to_string()).collect();
    if words.contains(&"--clean-cache") {
        return out;
    }
    for (flag, values) in QUICK {
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
fn the_page_shows_only_raywave_commands_in_sh_blocks() {
    let cmds = commands(DOC);
    assert!(
        cmds.iter()
            .filter(|c| c.starts_with("raywave variance"))
            .count()
            >= 5,
        "expected the page's raywave variance commands, found {cmds:?}"
    );
    for c in &cmds {
        assert!(c.starts_with("raywave "), "`{c}` is not a raywave command");
    }
    // No command outside a ```sh block: a `raywave ...` or `cargo ...` line elsewhere (plain,
    // indented, or in a block of another language) is a command the test would not run.
    let mut in_block = false;
    for line in DOC.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            in_block = !in_block && t == "```sh";
            continue;
        }
        assert!(
            in_block || !(t.starts_with("raywave ") || t.starts_with("cargo ")),
            "`{t}` is a command outside a ```sh block"
        );
    }
}

#[test]
fn the_shortening_replaces_and_adds() {
    let words = ["raywave", "variance", "--seeds", "16", "--out", "x"];
    let out = shorten(&words);
    assert_eq!(
        out.join(" "),
        "raywave variance --seeds 2 --out x --size 16 16 --reference-samples 64 --mask-samples 16"
    );
    let out = shorten(&["raywave", "variance", "--size", "96", "96"]);
    assert!(out.join(" ").starts_with("raywave variance --size 16 16 "));
}

#[test]
fn raywave_commands_run_in_page_order() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("scenes")).unwrap();
    let mut ran = 0;
    for command in commands(DOC) {
        let words: Vec<&str> = command.split_whitespace().collect();
        assert!(
            !command.contains(['"', '\'', '|', '>', '<', '$', '`']),
            "`{command}`: quoting, pipes and redirections are not supported here"
        );
        // The page's scene files: copies of the bundled ones.
        for w in &words {
            if let Some(name) = w.strip_prefix("scenes/") {
                std::fs::copy(scenes().join(name), dir.path().join(w)).unwrap();
            }
        }
        let args = shorten(&words);
        let flags: Vec<&str> = args[1..].iter().map(String::as_str).collect();
        let out = raywave(dir.path(), &flags);
        assert_eq!(
            out.status.code(),
            Some(0),
            "`{command}` (run as `{}`):\n{}\n{}",
            args.join(" "),
            stdout(&out),
            stderr(&out)
        );
        if !words.contains(&"--clean-cache") {
            let report = words
                .iter()
                .position(|w| *w == "--out")
                .map_or("variance-report", |i| words[i + 1]);
            for name in [
                "table.txt",
                "results.json",
                "seeds.csv",
                "contact_sheet.png",
            ] {
                assert!(
                    Path::new(&dir.path().join(report).join(name)).is_file(),
                    "`{command}` left no {report}/{name}"
                );
            }
        }
        println!("ran `{}`", args.join(" "));
        ran += 1;
    }
    assert!(ran >= 5, "ran only {ran} raywave commands");
}
