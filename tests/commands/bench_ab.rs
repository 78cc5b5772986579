//! `raywave bench --against OTHER`: the A/B mode's verdicts, end to end. The other build is a
//! stand-in script that reports a fixed render time, so each verdict is certain: against a
//! build that claims a microsecond per frame this build must be called a regression (exit 3),
//! against one that claims a thousand seconds it must not (exit 0): "not slower" by default,
//! "faster" with `--verdict three-way`.

use crate::common;

use common::bin::{raywave, stderr, stdout};
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

/// An executable script standing in for another raywave build: it writes `--stats-json` with
/// `seconds` and this scene's ray counts at 8×8 (taken from a real run of this build).
fn fake_build(dir: &Path, seconds: f64, rays: &str) -> PathBuf {
    let path = dir.join(format!("fake-{seconds}"));
    let script = format!(
        "#!/bin/sh\nwhile [ $# -gt 0 ]; do\n  if [ \"$1\" = --stats-json ]; then \
         printf '{{\"seconds\": {seconds}, \"rays\": {rays}}}' > \"$2\"; fi\n  shift\ndone\n"
    );
    std::fs::write(&path, script).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

/// This build's ray counts on the 8×8 frame, as `--stats-json` writes them.
fn real_rays(dir: &Path) -> String {
    let out = raywave(
        dir,
        &[
            "--size",
            "8",
            "8",
            "-q",
            "-o",
            "r.png",
            "--stats-json",
            "r.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r.json")).unwrap()).unwrap();
    json["rays"].to_string()
}

/// `bench --against OTHER` in 6 rounds at 8×8, wavefront only, no warm-up, plus `extra`.
fn against_with(dir: &Path, other: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "bench",
        "--against",
        other.to_str().unwrap(),
        "--size",
        "8",
        "8",
        "--rounds",
        "6",
        "--warmup",
        "0",
        "--engine",
        "wavefront",
        "-q",
    ];
    args.extend(extra);
    raywave(dir, &args)
}

fn against(dir: &Path, other: &Path) -> std::process::Output {
    against_with(dir, other, &[])
}

#[test]
fn a_build_claiming_a_microsecond_makes_this_one_a_regression() {
    let dir = tempfile::tempdir().unwrap();
    let rays = real_rays(dir.path());
    let out = against(dir.path(), &fake_build(dir.path(), 1e-6, &rays));
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(
        table.contains("slower by more than 5%: a regression"),
        "{table}"
    );
    assert!(table.contains("one-sided: a regression or not"), "{table}");
    assert!(!table.contains("different work"), "{table}");
    // The three-way form calls a regression by the same rule.
    let out = against_with(
        dir.path(),
        &fake_build(dir.path(), 1e-6, &rays),
        &["--verdict", "three-way"],
    );
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("slower by more than 5%: a regression"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn a_build_claiming_a_thousand_seconds_makes_this_one_not_slower_or_faster() {
    let dir = tempfile::tempdir().unwrap();
    let rays = real_rays(dir.path());
    let slow = fake_build(dir.path(), 1000.0, &rays);
    let out = against(dir.path(), &slow);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(
        table.contains("not slower by more than 5%: not a regression"),
        "{table}"
    );
    assert!(!table.contains("faster"), "{table}");
    let out = against_with(dir.path(), &slow, &["--verdict", "three-way"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(table.contains("faster by more than 5%"), "{table}");
    assert!(
        table.contains("three-way: slower, faster or no change"),
        "{table}"
    );
}

#[test]
fn different_work_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let rays =
        r#"{"camera":{"rays":1},"shadow":{"rays":2},"reflection":{"rays":3},"total":{"rays":6}}"#;
    let out = against(dir.path(), &fake_build(dir.path(), 1000.0, rays));
    assert!(stdout(&out).contains("other 1 2 3 6"), "{}", stdout(&out));
}

#[test]
fn a_missing_or_unusable_other_build_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("not-executable"), "").unwrap();
    for other in ["missing", "not-executable", "."] {
        let out = against(dir.path(), Path::new(other));
        assert_eq!(out.status.code(), Some(2), "{other}: {}", stderr(&out));
        assert!(stderr(&out).contains("expected an executable raywave binary"));
    }
    // A script that is not raywave: its failure is reported with what it printed.
    let liar = dir.path().join("liar");
    std::fs::write(&liar, "#!/bin/sh\necho 'no such command' >&2\nexit 9\n").unwrap();
    std::fs::set_permissions(&liar, std::fs::Permissions::from_mode(0o755)).unwrap();
    let out = against(dir.path(), &liar);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("no such command"), "{}", stderr(&out));
    // Too few rounds for an interval.
    let out = raywave(dir.path(), &["bench", "--against", "liar", "--rounds", "5"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    // Flags of the A/B mode without it.
    let out = raywave(dir.path(), &["bench", "--rounds", "8"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}

/// A stand-in build whose render time alternates between a microsecond and a thousand
/// seconds from one run to the next: the ratios alternate far above and far below 1, so no
/// interval of their median ever clears the threshold and `--until-decided` must end undecided.
fn seesaw_build(dir: &Path, rays: &str) -> PathBuf {
    let path = dir.join("seesaw");
    let script = format!(
        "#!/bin/sh\nn=$(cat \"$0.count\" 2>/dev/null || echo 0)\necho $((n + 1)) > \"$0.count\"\n\
         if [ $((n % 2)) -eq 0 ]; then s=0.000001; else s=1000; fi\n\
         while [ $# -gt 0 ]; do\n  if [ \"$1\" = --stats-json ]; then \
         printf '{{\"seconds\": %s, \"rays\": {rays}}}' \"$s\" > \"$2\"; fi\n  shift\ndone\n"
    );
    std::fs::write(&path, script).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

/// `bench --against OTHER --until-decided` at 8×8, wavefront only, no warm-up, plus `extra`.
fn until_decided(dir: &Path, other: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "bench",
        "--against",
        other.to_str().unwrap(),
        "--until-decided",
        "--size",
        "8",
        "8",
        "--warmup",
        "0",
        "--engine",
        "wavefront",
        "-q",
    ];
    args.extend(extra);
    raywave(dir, &args)
}

/// The rounds the report says the engine used (`N rounds used; ...`).
fn rounds_used(table: &str) -> u32 {
    let at = table.find(" rounds used").expect(table);
    let start = table[..at].rfind(char::is_whitespace).unwrap() + 1;
    table[start..at].parse().expect(table)
}

#[test]
fn until_decided_stops_at_the_first_look_that_decides() {
    let dir = tempfile::tempdir().unwrap();
    let rays = real_rays(dir.path());
    // A regression at the default plan's first look, 9 rounds (5% over 9 looks: the fewest
    // rounds whose extremes hold the median with 99.44%, 2·2^-9 ≤ 0.56%).
    let out = until_decided(dir.path(), &fake_build(dir.path(), 1e-6, &rays), &[]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(
        table.contains("slower by more than 5%: a regression"),
        "{table}"
    );
    assert!(table.contains("looks at 9 (slower); decided"), "{table}");
    assert_eq!(rounds_used(&table), 9, "{table}");
    // Not slower is decided at the first look too: exit 0.
    let slow = fake_build(dir.path(), 1000.0, &rays);
    let out = until_decided(dir.path(), &slow, &[]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(table.contains("not a regression"), "{table}");
    assert!(
        table.contains("looks at 9 (not slower); decided"),
        "{table}"
    );
    // The three-way form: faster, at the first look.
    let out = until_decided(dir.path(), &slow, &["--verdict", "three-way"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(table.contains("faster by more than 5%"), "{table}");
    assert!(table.contains("looks at 9 (faster); decided"), "{table}");
}

#[test]
fn until_decided_ends_undecided_at_the_budget_with_exit_4() {
    let dir = tempfile::tempdir().unwrap();
    let rays = real_rays(dir.path());
    let seesaw = seesaw_build(dir.path(), &rays);
    for form in ["regression", "three-way"] {
        let out = until_decided(
            dir.path(),
            &seesaw,
            &["--max-rounds", "14", "--verdict", form],
        );
        assert_eq!(out.status.code(), Some(4), "{form}: {}", stderr(&out));
        let table = stdout(&out);
        assert!(table.contains("undecided at the budget"), "{table}");
        assert!(table.contains("--max-rounds 14 reached"), "{table}");
        assert_eq!(rounds_used(&table), 14, "{table}");
    }
    // Out of time long before 10 000 rounds: stopped by --max-time, still exit 4.
    let started = std::time::Instant::now();
    let out = until_decided(
        dir.path(),
        &seesaw,
        &["--max-rounds", "10000", "--max-time", "2s"],
    );
    assert_eq!(out.status.code(), Some(4), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(
        table.contains("--max-time 2s left too little time for the next look"),
        "{table}"
    );
    assert!(rounds_used(&table) < 10_000, "{table}");
    // The pace rule stops before a look it cannot reach; a round or two may overrun.
    assert!(started.elapsed().as_secs_f64() < 10.0, "{table}");
}

/// This build against itself: no verdict is certain on a shared machine (a sub-millisecond
/// frame's noise may even call one "slower"), so the test asks only that the exit code is one
/// of the documented ones and agrees with the report, which names the rounds used.
#[test]
fn until_decided_against_itself_reports_its_rounds_and_a_documented_code() {
    let dir = tempfile::tempdir().unwrap();
    let this = Path::new(crate::common::bin::exe());
    let out = until_decided(dir.path(), this, &["--max-rounds", "9"]);
    let table = stdout(&out);
    let expected = if table.contains("slower by more than 5%: a regression") {
        3
    } else if table.contains("undecided at the budget") {
        4
    } else {
        0
    };
    assert_eq!(out.status.code(), Some(expected), "{table}{}", stderr(&out));
    assert!((1..=9).contains(&rounds_used(&table)), "{table}");
    assert!(
        table.contains("until decided (at most 9 rounds)"),
        "{table}"
    );
}

#[test]
fn until_decided_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let this = crate::common::bin::exe();
    for (args, says) in [
        (
            &["--against", this, "--until-decided", "--max-rounds", "5"][..],
            "--max-rounds",
        ),
        (&["--until-decided"], "--against"),
        (&["--max-rounds", "50"], "--until-decided"),
        (&["--max-time", "10m"], "--until-decided"),
        (&["--verdict", "three-way"], "--against"),
        (
            &["--against", this, "--verdict", "sideways"],
            "possible values: regression, three-way",
        ),
        (
            &["--against", this, "--until-decided", "--rounds", "30"],
            "--rounds",
        ),
        (
            &[
                "--against",
                this,
                "--until-decided",
                "--max-time",
                "ten minutes",
            ],
            "expected a duration such as 10m",
        ),
        (
            &["--against", this, "--until-decided", "--max-time", "0s"],
            "expected a positive duration",
        ),
    ] {
        let mut all = vec!["bench"];
        all.extend(args);
        let out = raywave(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
    }
}
