//! Embeds what the binary was built from, for bench records and `raywave info`
//! (`raywave::build_info`): the git commit and whether the tracked files had uncommitted
//! changes, at build time ("unknown" without git, e.g. from a tarball), the cargo profile, the
//! target triple, the target features and the RUSTFLAGS.
//!
//! Cargo reruns this script when HEAD moves (`.git/HEAD`, the ref it names, packed-refs), when
//! the index changes (a commit or `git add`) and when a source file changes (the dirty flag).

use std::path::{Path, PathBuf};
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .stderr(std::process::Stdio::null())
        .output()
        .ok()
        .filter(|o| o.status.success())?;
    Some(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn watch(path: &Path) {
    if path.exists() {
        println!("cargo:rerun-if-changed={}", path.display());
    }
}

fn main() {
    for p in [
        "build.rs",
        "src",
        "Cargo.toml",
        "Cargo.lock",
        ".cargo/config.toml",
    ] {
        println!("cargo:rerun-if-changed={p}");
    }
    let commit = git(&["rev-parse", "HEAD"]).filter(|c| c.len() >= 40);
    let dirty = commit.as_ref().and_then(|_| {
        git(&["status", "--porcelain", "--untracked-files=no"]).map(|s| !s.is_empty())
    });
    if commit.is_some() {
        // In a worktree, HEAD lives in the worktree's git dir and the refs in the common one.
        let dir = |arg| git(&["rev-parse", arg]).map(PathBuf::from);
        if let (Some(git_dir), Some(common)) = (dir("--git-dir"), dir("--git-common-dir")) {
            watch(&git_dir.join("HEAD"));
            watch(&git_dir.join("index"));
            watch(&common.join("packed-refs"));
            if let Some(head_ref) = git(&["symbolic-ref", "-q", "HEAD"]) {
                watch(&common.join(&head_ref));
                watch(&git_dir.join(&head_ref));
            }
        }
    }
    let env = |k: &str| std::env::var(k).unwrap_or_default();
    let rustflags = env("CARGO_ENCODED_RUSTFLAGS").replace('\u{1f}', " ");
    let values = [
        (
            "RAYWAVE_GIT_COMMIT",
            commit.unwrap_or_else(|| "unknown".into()),
        ),
        (
            "RAYWAVE_GIT_DIRTY",
            dirty.map_or("unknown".into(), |d| d.to_string()),
        ),
        ("RAYWAVE_BUILD_PROFILE", env("PROFILE")),
        ("RAYWAVE_BUILD_TARGET", env("TARGET")),
        ("RAYWAVE_TARGET_FEATURES", env("CARGO_CFG_TARGET_FEATURE")),
        ("RAYWAVE_RUSTFLAGS", rustflags),
    ];
    for (k, v) in values {
        println!("cargo:rustc-env={k}={v}");
    }
}
