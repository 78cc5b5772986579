//! Embeds what the binary was built from, for bench records and `raywave info`
//! (`raywave::output::build_info`): the git commit and whether the compiled files had uncommitted
//! changes, at build time ("unknown" without git, e.g. from a tarball), the cargo profile, the
//! target triple, the target features and the RUSTFLAGS.
//!
//! Cargo reruns this script only when what is compiled changes (`src/`, the manifest, the lock
//! file, this script, `.cargo/config.toml`), never when HEAD or the index moves: a rerun
//! rebuilds the library and every test binary, and a commit changes no compiled byte. So the
//! commit is HEAD as it was when these sources were last compiled, and `dirty` says whether
//! they differed from it then; a binary built before a commit of its own sources and not
//! touched since says "(dirty)" with the commit before.

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

fn main() {
    // What the library and the binary are compiled from.
    let compiled = [
        "build.rs",
        "src",
        "Cargo.toml",
        "Cargo.lock",
        ".cargo/config.toml",
    ];
    for p in compiled {
        println!("cargo:rerun-if-changed={p}");
    }
    let commit = git(&["rev-parse", "HEAD"]).filter(|c| c.len() >= 40);
    let dirty = commit.as_ref().and_then(|_| {
        let mut args = vec!["status", "--porcelain", "--untracked-files=no", "--"];
        args.extend(compiled);
        git(&args).map(|s| !s.is_empty())
    });
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
