//! `raywave bench --against OTHER`: the A/B mode's verdicts, end to end. The other build is a
//! stand-in script that reports a fixed render time, so each verdict is certain: against a
//! build that claims a microsecond per frame this build must be called a regression (exit 3),
//! against one that claims a thousand seconds it must not.

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

fn against(dir: &Path, other: &Path) -> std::process::Output {
    let other = other.to_str().unwrap();
    raywave(
        dir,
        &[
            "bench",
            "--against",
            other,
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
        ],
    )
}

#[test]
fn a_build_claiming_a_microsecond_makes_this_one_a_regression() {
    let dir = tempfile::tempdir().unwrap();
    let rays = real_rays(dir.path());
    let out = against(dir.path(), &fake_build(dir.path(), 1e-6, &rays));
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(table.contains("a regression"), "{table}");
    assert!(!table.contains("different work"), "{table}");
}

#[test]
fn a_build_claiming_a_thousand_seconds_makes_this_one_faster() {
    let dir = tempfile::tempdir().unwrap();
    let rays = real_rays(dir.path());
    let out = against(dir.path(), &fake_build(dir.path(), 1000.0, &rays));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("faster by more than 5%"),
        "{}",
        stdout(&out)
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
