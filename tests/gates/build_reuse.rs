//! `cargo test` reuses what `cargo run` built. Feature resolver 2 leaves dev-dependencies'
//! features out of `cargo build`, so a dependency that a dev-dependency gives one more feature is
//! compiled twice, and with it every crate above it: once `either` (criterion's itertools turns
//! on `use_std`) made CI compile rayon and raywave's whole library a second time. The fix is to
//! ask for the same features in `[dependencies]` (Cargo.toml, beside `either`).

use std::collections::BTreeMap;
use std::process::Command;

/// Each package of the build's tree (normal and build edges) with its enabled features, as
/// `cargo tree` resolves them with or without the dev-dependencies.
fn features(with_dev: bool) -> BTreeMap<String, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let edges = if with_dev {
        "normal,build,dev"
    } else {
        "normal,build"
    };
    let out = Command::new(cargo)
        .args([
            "tree",
            "--offline",
            "--prefix",
            "none",
            "-f",
            "{p}|{f}",
            "-e",
            edges,
        ])
        .current_dir(env!("RAYWAVE_REPO"))
        .output()
        .expect("run cargo tree");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.trim_end_matches(" (*)").split_once('|'))
        .map(|(p, f)| (p.to_string(), f.to_string()))
        .collect()
}

#[test]
fn the_tests_build_each_dependency_with_the_features_of_the_main_build() {
    let run = features(false);
    let test = features(true);
    let differ: Vec<String> = run
        .iter()
        .filter_map(|(p, f)| {
            let t = test.get(p)?;
            (t != f).then(|| format!("{p}: cargo build [{f}], cargo test [{t}]"))
        })
        .collect();
    assert!(
        differ.is_empty(),
        "these would be compiled twice on a clean clone (add their test features to \
         [dependencies]):\n{}",
        differ.join("\n")
    );
}
