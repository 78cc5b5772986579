//! The mutant check's patches still apply. Each `tests/mutants/*.patch` is a `git diff` against
//! `src/`; when the code it patches moves, `git apply` refuses it and `tests/mutants/run.sh`
//! reports it STALE, but only when someone runs the check, a minute or more per mutant. This gate
//! runs `git apply --check` on every patch (no build) and names each one that no longer applies,
//! so that the change that moved the code is the one that re-plants its mutants.
//!
//! The check needs git and a git checkout (run.sh does too): without them it fails when CI is
//! set, else says why and passes, as the icount gate does.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Says why the check could not run: a failure under CI, a note elsewhere.
fn not_gated(why: &str) {
    let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false" && v != "0");
    assert!(
        !ci,
        "mutants_apply: the check did not run, and CI is set: {why}"
    );
    eprintln!("mutants_apply: SKIPPED: {why}");
}

/// The root of the git checkout `repo` is, or why there is none: git missing, or `repo` not
/// the top of a work tree (a patch names its files from there).
fn checkout_root(repo: &Path) -> Result<PathBuf, String> {
    let out = Command::new("git")
        .args(["rev-parse", "--show-toplevel"])
        .current_dir(repo)
        .output()
        .map_err(|e| format!("git could not be run ({e}); Debian: apt-get install git"))?;
    if !out.status.success() {
        return Err(format!(
            "{} is not a git checkout: {}",
            repo.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let top = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let same = |p: &Path| p.canonicalize().ok();
    if same(&top) != same(repo) {
        return Err(format!(
            "{} is inside the git checkout {}, not the top of one",
            repo.display(),
            top.display()
        ));
    }
    Ok(top)
}

#[test]
fn every_mutant_patch_applies_to_today_s_src() {
    let repo = Path::new(env!("RAYWAVE_REPO"));
    let root = match checkout_root(repo) {
        Ok(root) => root,
        Err(why) => return not_gated(&why),
    };
    let mut patches: Vec<PathBuf> = std::fs::read_dir(root.join("tests/mutants"))
        .expect("read tests/mutants/")
        .map(|entry| entry.expect("a directory entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "patch"))
        .collect();
    patches.sort();
    assert!(!patches.is_empty(), "tests/mutants/ holds no patch");
    let mut stale = Vec::new();
    for patch in &patches {
        let out = Command::new("git")
            .arg("apply")
            .arg("--check")
            .arg(patch)
            .current_dir(&root)
            .output()
            .expect("run git apply --check");
        if !out.status.success() {
            let name = patch.strip_prefix(&root).unwrap_or(patch);
            let why = String::from_utf8_lossy(&out.stderr);
            stale.push(format!(
                "{} does not apply: re-plant it by hand (tests/mutants/run.sh)\n    {}",
                name.display(),
                why.trim().replace('\n', "\n    ")
            ));
        }
    }
    assert!(
        stale.is_empty(),
        "{} of {} mutant patches no longer apply to src/, whose code they patch has moved; \
         plant the bug each one's `Mutant:` line names again, as a fresh `git diff -- src` under \
         its two header lines:\n{}",
        stale.len(),
        patches.len(),
        stale.join("\n")
    );
}
