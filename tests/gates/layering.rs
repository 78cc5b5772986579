//! The layers stay layers. The lane layer: `src/render/wavefront/lanes.rs` is the only source
//! file that names the `wide` crate or `bytemuck`; every other file, kernels included, takes
//! lane types, loads, masks and bit casts from it, so that the lane width and its tricks live
//! in one place. The module layers: the renderer names neither the outputs nor a tool, and the
//! outputs name no tool.

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
    let src = Path::new(env!("RAYWAVE_REPO")).join("src");
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

/// `crate::<module>` paths named in the non-comment lines of the files under `dir`, for the
/// given modules: (file:line, module).
fn uses_of(dir: &Path, modules: &[&str]) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(dir, &mut files);
    let mut found = Vec::new();
    for path in files {
        let text = std::fs::read_to_string(&path).expect("read a source file");
        for (n, line) in text.lines().enumerate() {
            let code = line.trim_start();
            if code.starts_with("//") {
                continue;
            }
            for m in modules {
                if code.contains(&format!("crate::{m}::")) || code.contains(&format!("crate::{m};"))
                {
                    found.push(format!("{}:{}: {}", path.display(), n + 1, code));
                }
            }
        }
    }
    found
}

const TOOLS: [&str; 6] = ["bench", "diff", "frame", "trace", "variance", "view"];

/// The layers of docs/ARCHITECTURE.md, each depending only on those above it: the renderer
/// names neither the outputs nor a tool (its `--no-default-features` build would fail
/// anyway), the outputs and records name neither the sharding layer nor a tool, and the
/// sharding layer names no tool; the statistics name no other module.
#[test]
fn each_layer_names_only_the_layers_above_it() {
    let src = &Path::new(env!("RAYWAVE_REPO")).join("src");
    let mut offenders = uses_of(
        &src.join("render"),
        &[&["output", "shard"][..], &TOOLS].concat(),
    );
    offenders.extend(uses_of(
        &src.join("output"),
        &[&["shard"][..], &TOOLS].concat(),
    ));
    offenders.extend(uses_of(&src.join("shard"), &TOOLS));
    // The statistics are a leaf: numbers in, numbers out.
    offenders.extend(uses_of(
        &src.join("stats"),
        &[&["render", "output", "shard"][..], &TOOLS].concat(),
    ));
    assert!(
        offenders.is_empty(),
        "a layer names one below it (render/ < output/ < shard/ < the tools, \
         docs/ARCHITECTURE.md):\n{}",
        offenders.join("\n")
    );
}

/// The check sees a use: the view names the trace module.
#[test]
fn a_use_across_layers_is_seen() {
    assert!(
        !uses_of(
            &Path::new(env!("RAYWAVE_REPO")).join("src/view"),
            &["trace"]
        )
        .is_empty()
    );
}
