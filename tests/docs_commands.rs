//! Every command the user-facing pages show is run or checked here (tests/common/docs.rs says
//! how), so no page can drift from the code.

mod common;

use common::docs::{Page, run_in_page_order, stale_manual, uncovered};

/// README.md: the set-up commands and the tour. Renders run at the page's sizes (each takes
/// under a few seconds in a release build); the variance study is shortened.
const README: Page = Page {
    path: "README.md",
    text: include_str!("../README.md"),
    quick: &[
        ("variance", "--size", &["16", "16"]),
        ("variance", "--seeds", &["2"]),
        ("variance", "--reference-samples", &["64"]),
        ("variance", "--mask-samples", &["16"]),
    ],
    manual: &[],
};

const PAGES: [&Page; 1] = [&README];

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
    assert!(ran >= 8, "ran only {ran} of README's commands");
}
