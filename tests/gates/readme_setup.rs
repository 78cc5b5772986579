//! CI runs the README's set-up block as written: the two commands of the ```sh block under
//! "## Set up" in README.md are, in that order, the commands `.ci/run` runs with cargo.
//!
//! A command line of `.ci/run` is one that starts with `cargo `; what it pipes its output into
//! (`| tee …`) or redirects it to (`> …`) is how CI reads the output, not part of the command.
//! Every other cargo line `.ci/run` runs (the newcomer's other commands) must come between the
//! README's two, after the first has built the binary they reuse.

use std::path::Path;

/// The commands of the README's set-up block, without their comments.
fn readme_setup(readme: &str) -> Vec<String> {
    let section = &readme[readme
        .find("\n## Set up")
        .expect("README.md has a \"## Set up\" heading")..];
    let mut lines = section
        .lines()
        .skip_while(|l| !l.starts_with("```sh"));
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
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let script = std::fs::read_to_string(root.join(".ci/run")).expect(".ci/run");
    if let Some(why) = mismatch(&readme, &script) {
        panic!("{why}");
    }
}

/// The check itself can fail: either README command changed, or dropped from CI, is caught.
#[test]
fn a_changed_readme_command_is_caught() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
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
