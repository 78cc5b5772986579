//! The reference pages stay reference. Each page that keeps growing back into a log has a line
//! budget, and docs/TESTING.md states what CI costs as one current figure, not as a diary of
//! runs. What was tried, with its before/after figures, goes to docs/TRIED.md (or stays in git).
//!
//! The diary check is deliberately plain: a diary of CI timings shows as many wall-clock
//! durations (`4 min 52 s`, `5:20`) and as comparisons with earlier runs ("the tree before",
//! "the day before", a date). One current figure may be a range, so two durations are allowed.

use std::path::Path;

/// One page's budget: the most lines it may have, and why that many.
struct Budget {
    /// The page, from the repository root.
    path: &'static str,
    /// The most lines the page may have.
    max_lines: usize,
    /// What the page is for, which is what the budget protects.
    why: &'static str,
}

/// Every page budget, in one table.
const BUDGETS: [Budget; 3] = [
    Budget {
        path: "docs/BENCHMARKING.md",
        max_lines: 600,
        why: "how to run the benchmarks and read what they print; figures belong in \
              PERFORMANCE.md, history in TRIED.md",
    },
    Budget {
        path: "docs/PERFORMANCE.md",
        max_lines: 300,
        why: "today's figures, each with its command; before/after A/Bs belong in TRIED.md",
    },
    Budget {
        path: "README.md",
        max_lines: 240,
        why: "a newcomer's first page: set-up, a tour, pointers into docs/; detail belongs there",
    },
];

/// The page whose CI timings must not become a diary again.
const TESTING: &str = "docs/TESTING.md";

/// The most wall-clock durations TESTING.md may give: one current figure, possibly a range.
const MAX_DURATIONS: usize = 2;

/// Phrases that compare a run with an earlier one: the mark of a diary, not of reference.
const DIARY_PHRASES: [&str; 7] = [
    "the tree before",
    "the build before",
    "the day before",
    "that day",
    "yesterday",
    "in the hour of",
    "last week",
];

fn read(path: &str) -> String {
    let full = Path::new(env!("RAYWAVE_REPO")).join(path);
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("cannot read {}: {e}", full.display()))
}

/// The message for a page over its budget, or `None` when it keeps it.
fn over_budget(budget: &Budget, text: &str) -> Option<String> {
    let lines = text.lines().count();
    (lines > budget.max_lines).then(|| {
        format!(
            "{}: {lines} lines, budget {} ({})",
            budget.path, budget.max_lines, budget.why
        )
    })
}

/// Wall-clock durations in `text`: `N min` (as in `4 min 52 s`) and `M:SS` (as in `5:20`).
fn durations(text: &str) -> Vec<String> {
    let words: Vec<&str> = text.split_whitespace().collect();
    let mut found = Vec::new();
    for (i, word) in words.iter().enumerate() {
        let bare = word.trim_matches(|c: char| !c.is_ascii_alphanumeric() && c != ':');
        let number = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        if number(bare) && words.get(i + 1).is_some_and(|next| next.starts_with("min")) {
            found.push(format!("{bare} min"));
        } else if let Some((m, s)) = bare.split_once(':')
            && number(m)
            && s.len() == 2
            && number(s)
        {
            found.push(bare.to_string());
        }
    }
    found
}

/// A date such as 2025-03-14 in `line`.
fn has_date(line: &str) -> bool {
    line.as_bytes().windows(10).any(|w| {
        let digits = |r: std::ops::Range<usize>| w[r].iter().all(u8::is_ascii_digit);
        digits(0..4) && w[4] == b'-' && digits(5..7) && w[7] == b'-' && digits(8..10)
    })
}

/// What makes `text` a timing diary, one message per finding; empty when it is reference.
fn diary(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    let durations = durations(text);
    if durations.len() > MAX_DURATIONS {
        found.push(format!(
            "{} wall-clock durations ({}), at most {MAX_DURATIONS} (one current figure)",
            durations.len(),
            durations.join(", ")
        ));
    }
    for (n, line) in text.lines().enumerate() {
        let lower = line.to_lowercase();
        if let Some(phrase) = DIARY_PHRASES.iter().find(|p| lower.contains(*p)) {
            found.push(format!("line {}: \"{phrase}\": {}", n + 1, line.trim()));
        }
        if has_date(line) {
            found.push(format!("line {}: a date: {}", n + 1, line.trim()));
        }
    }
    found
}

#[test]
fn pages_keep_their_line_budgets() {
    let over: Vec<String> = BUDGETS
        .iter()
        .filter_map(|b| over_budget(b, &read(b.path)))
        .collect();
    assert!(
        over.is_empty(),
        "pages over their budget (move history to docs/TRIED.md, duplicated reference to the \
         page that owns it):\n{}",
        over.join("\n")
    );
}

#[test]
fn testing_md_has_no_timing_diary() {
    let found = diary(&read(TESTING));
    assert!(
        found.is_empty(),
        "{TESTING} reads as a diary of CI runs; keep one current figure with its command:\n{}",
        found.join("\n")
    );
}

/// The checks themselves can fail: a page one line over its budget, and the CI diary that
/// docs/TESTING.md once held, are both caught; the budget's own page length passes.
#[test]
fn the_checks_catch_what_they_guard_against() {
    let budget = &BUDGETS[1];
    let at_budget = "line\n".repeat(budget.max_lines);
    assert_eq!(over_budget(budget, &at_budget), None);
    let over = over_budget(budget, &format!("{at_budget}one more\n")).expect("caught");
    assert!(over.contains("301 lines, budget 300"), "{over}");

    let old_diary = "for the current tree in four runs over two hours. The slowest: 9 min 2 s \
        of CPU; 4:00 the build (the fastest built in 3:22). The tree before textures took 5:20 \
        in the hour of the slowest; the same tree had taken 4:58 and 5:05 the day before.";
    let found = diary(old_diary);
    assert!(
        found.iter().any(|f| f.contains("wall-clock durations")),
        "{found:?}"
    );
    assert!(
        found.iter().any(|f| f.contains("the tree before")),
        "{found:?}"
    );
    assert!(diary("CI ran on 2025-03-14.").len() == 1);
    let current = "**4 min 52 s to 5 min 27 s** (four runs), `file:line`, 127.0.0.1:8080";
    assert_eq!(diary(current), Vec::<String>::new());
}
