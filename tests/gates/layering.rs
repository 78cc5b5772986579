//! The lane layer stays one layer: `src/render/wavefront/lanes.rs` is the only source file that
//! names the `wide` crate or `bytemuck`. Every other file, kernels included, takes lane types,
//! loads, masks and bit casts from it, so that the lane width and its tricks live in one place.

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read src/") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn only_the_lane_layer_names_wide_or_bytemuck() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lanes = src.join("render").join("wavefront").join("lanes.rs");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.contains(&lanes), "{} is missing", lanes.display());
    let mut offenders = Vec::new();
    for path in files.iter().filter(|p| **p != lanes) {
        let text = std::fs::read_to_string(path).expect("read a source file");
        for (n, line) in text.lines().enumerate() {
            if ["wide::", "use wide", "bytemuck"]
                .iter()
                .any(|name| line.contains(name))
            {
                offenders.push(format!("{}:{}: {}", path.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "only src/render/wavefront/lanes.rs may name `wide` or `bytemuck`; take lane types, loads \
         and casts from it instead:\n{}",
        offenders.join("\n")
    );
}
