//! The page's JavaScript (src/view/assets/*.mjs) under node's own test runner: the modules'
//! logic (camera maths, fitting, the ray tree's table and lines, the settings check, the
//! token, debouncing, progress and keys) is tested by tests/js/*.test.mjs, without a browser.
//!
//! Needs `node` (Debian's `nodejs`; `.ci/run` installs it). Without it the test prints
//! SKIPPED and passes, unless CI is set: then it fails.

use crate::common::skip::skip_or_fail;
use std::process::Command;

#[test]
fn the_page_modules_pass_their_node_tests() {
    let root = env!("RAYWAVE_REPO");
    let run = Command::new("node")
        .args(["--test", "--test-reporter=tap", "tests/js/"])
        .current_dir(root)
        .output();
    let output = match run {
        Ok(output) => output,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return skip_or_fail("node is not installed (Debian's nodejs; .ci/run installs it)");
        }
        Err(e) => panic!("cannot run node --test tests/js/ in {root}: {e}"),
    };
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "node --test tests/js/ failed ({}):\n{stdout}\n{stderr}",
        output.status
    );
    // The runner found the tests: a summary line with a count above zero and no failures.
    let count = |name: &str| {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(&format!("# {name} ")))
            .and_then(|n| n.trim().parse::<u32>().ok())
    };
    assert!(
        count("pass").is_some_and(|n| n > 0) && count("fail") == Some(0),
        "no passing node tests found:\n{stdout}\n{stderr}"
    );
}
