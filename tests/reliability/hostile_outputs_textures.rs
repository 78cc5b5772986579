//! No output is ever a texture the scene reads: every output flag of render, trace-pixel,
//! bench, diff and variance against the texture of `tx/ok.obj` (`tx/ok.ppm`), named as it is,
//! through a symlink and through `..`. Each is a usage error (exit 2) naming the texture, and
//! the texture, the scene and every other file are left as they were (`common::hostile`).
//!
//! Textures are read while the scene is parsed, so these outputs are checked against them once
//! the scene is read, before any output is opened.

use crate::common;

use common::hostile::{Case, check_all, setup};
use std::path::Path;

/// `tx/ok.obj`: the bundled textured box with its texture named `ok.ppm` (so `tx/ok.ppm`),
/// `tx/sub/` for a path through `..`, and symlinks to the texture under output-like names.
fn textured(d: &Path) {
    let scenes = common::bin::scenes();
    let text = std::fs::read_to_string(scenes.join("textured_box.obj"))
        .unwrap()
        .replace(
            "texture_file textures/asymmetric.ppm",
            "texture_file ok.ppm",
        );
    assert!(text.contains("texture_file ok.ppm"));
    std::fs::create_dir_all(d.join("tx/sub")).unwrap();
    std::fs::write(d.join("tx/ok.obj"), text).unwrap();
    std::fs::copy(scenes.join("textures/asymmetric.ppm"), d.join("tx/ok.ppm")).unwrap();
    for link in ["link.png", "link.pfm", "link.json", "link.csv"] {
        setup::symlink(d, link, "tx/ok.ppm");
    }
}

/// `textured`, and two 8×8 PFM images for diff.
fn textured_and_images(d: &Path) {
    textured(d);
    let mut pfm = b"PF\n8 8\n-1.0\n".to_vec();
    for _ in 0..8 * 8 * 3 {
        pfm.extend_from_slice(&0.5f32.to_le_bytes());
    }
    std::fs::write(d.join("a.pfm"), &pfm).unwrap();
    std::fs::write(d.join("b.pfm"), &pfm).unwrap();
}

/// What every case's stderr says.
const TEXTURE: &str = "is the same file as the input SCENE's texture_file";

/// A case that must be refused (exit 2) with every file left as it was. `render`, `trace` and
/// `bench` put that command, the scene and a tiny size before the case's own arguments.
macro_rules! case {
    ($name:expr, render [$($a:expr),*]) => {
        case!($name, ["render", "tx/ok.obj", "--size", "8", "8", "-q", $($a),*])
    };
    ($name:expr, trace [$($a:expr),*]) => {
        case!($name, ["trace-pixel", "1", "1", "tx/ok.obj", "--size", "8", "8", $($a),*])
    };
    ($name:expr, bench [$($a:expr),*]) => {
        case!($name, ["bench", "tx/ok.obj", "--size", "8", "8", "--runs", "1", "-q", $($a),*])
    };
    ($name:expr, [$($a:expr),*]) => {
        case!($name, textured, [$($a),*], [TEXTURE])
    };
    ($name:expr, $setup:expr, [$($a:expr),*], [$($m:expr),*]) => {
        Case {
            name: $name,
            setup: $setup,
            args: &[$($a),*],
            stdin: None,
            exit: 2,
            stderr: &[$($m),*],
            outputs: &[],
        }
    };
}

#[test]
#[rustfmt::skip]
fn no_output_is_a_texture_the_scene_reads() {
    const PENUMBRA: &str = "is the same file as the input --scene's texture_file";
    check_all(&[
        case!("render -o is the texture", render ["-o", "tx/ok.ppm"]),
        case!("render -o is the texture through ..", render ["-o", "tx/sub/../ok.ppm"]),
        case!("render -o is a symlink to the texture", render ["-o", "link.png"]),
        case!("render -input, -o is the texture",
            ["-input", "tx/ok.obj", "-size", "8", "8", "-o", "tx/ok.ppm"]),
        case!("render --hdr is a symlink to the texture",
            render ["-o", "x.png", "--hdr", "link.pfm"]),
        case!("render --stats-json is the texture",
            render ["-o", "x.png", "--stats-json", "tx/ok.ppm"]),
        case!("render --stats-json is the texture through ..",
            render ["-o", "x.png", "--stats-json", "tx/sub/../ok.ppm"]),
        case!("trace-pixel --json is the texture", trace ["--json", "tx/ok.ppm"]),
        case!("trace-pixel --obj is the texture through ..", trace ["--obj", "tx/sub/../ok.ppm"]),
        case!("trace-pixel --ply is the texture", trace ["--ply", "tx/ok.ppm"]),
        case!("trace-pixel --png is a symlink to the texture", trace ["--png", "link.png"]),
        case!("bench --json is the texture", bench ["--json", "tx/ok.ppm"]),
        case!("bench --export-csv is a symlink to the texture", bench ["--export-csv", "link.csv"]),
        case!("bench --export-markdown is the texture through ..",
            bench ["--export-markdown", "tx/sub/../ok.ppm"]),
        case!("diff --out is the texture of the penumbra scene", textured_and_images,
            ["diff", "a.pfm", "b.pfm", "--mask", "penumbra", "--scene", "tx/ok.obj",
             "--mask-samples", "4", "--out", "tx/ok.ppm"],
            [PENUMBRA]),
        case!("diff --json is a symlink to the texture of the penumbra scene", textured_and_images,
            ["diff", "a.pfm", "b.pfm", "--mask", "penumbra", "--scene", "tx/ok.obj",
             "--mask-samples", "4", "--json", "link.json"],
            [PENUMBRA]),
    ]);
}

/// A variance report file that is the texture: the report's `--out` directory holds the
/// scene's texture under the name of one of the report's files.
#[test]
#[rustfmt::skip]
fn no_variance_report_file_is_a_texture() {
    check_all(&[case!(
        "variance --out holds the texture under a report file's name",
        |d| {
            textured(d);
            let text = std::fs::read_to_string(d.join("tx/ok.obj"))
                .unwrap()
                .replace("texture_file ok.ppm", "texture_file report/table.txt");
            std::fs::write(d.join("tx/ok.obj"), text).unwrap();
            std::fs::create_dir_all(d.join("tx/report")).unwrap();
            std::fs::copy(d.join("tx/ok.ppm"), d.join("tx/report/table.txt")).unwrap();
        },
        ["variance", "tx/ok.obj", "--size", "8", "8", "--budgets", "1", "--samplers", "random",
         "--seeds", "2", "--reference-samples", "4", "--mask-samples", "4", "--cache", "cache",
         "--out", "tx/report", "-q"],
        ["is the same file as the input case", "texture_file"]
    )]);
}
