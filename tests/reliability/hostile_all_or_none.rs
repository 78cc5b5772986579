//! All outputs or none: a run that fails on one output changes none of the others. Each case
//! starts with every output but one already there (old contents), sends the one left to a
//! full device (`/dev/full`, a character device that answers ENOSPC, named as it is or through
//! a symlink), and must exit 1 naming it, with every earlier output unchanged and no temporary
//! file left (`common::hostile` compares every file before and after).

use crate::common;

use common::hostile::{Case, check_all, setup};
use std::path::Path;

/// The lab's box, old contents in every output name the cases use, and a symlink to the full
/// device.
fn outputs_there(d: &Path) {
    setup::cornell_box(d);
    for name in [
        "x.png", "x.pfm", "x.json", "t.json", "t.obj", "t.ply", "t.png", "b.json", "b.csv", "b.md",
        "d.png",
    ] {
        setup::file(d, name, b"the old contents\n");
    }
    setup::symlink(d, "full.json", "/dev/full");
    let mut pfm = b"PF\n8 8\n-1.0\n".to_vec();
    for _ in 0..8 * 8 * 3 {
        pfm.extend_from_slice(&0.25f32.to_le_bytes());
    }
    std::fs::write(d.join("a.pfm"), &pfm).unwrap();
    std::fs::write(d.join("b.pfm"), &pfm).unwrap();
}

/// A case whose last output is on a full device: exit 1, nothing changed. `render`, `trace`
/// and `bench` put that command, the scene and a tiny size before the case's own arguments.
macro_rules! full {
    ($name:expr, render [$($a:expr),*]) => {
        full!($name, ["render", "cornell_box.obj", "--size", "8", "8", "-q", $($a),*])
    };
    ($name:expr, trace [$($a:expr),*]) => {
        full!($name, ["trace-pixel", "1", "1", "cornell_box.obj", "--size", "8", "8", $($a),*])
    };
    ($name:expr, bench [$($a:expr),*]) => {
        full!($name, ["bench", "cornell_box.obj", "--size", "8", "8", "--runs", "1", "-q", $($a),*])
    };
    ($name:expr, [$($a:expr),*]) => {
        Case {
            name: $name,
            setup: outputs_there,
            args: &[$($a),*],
            stdin: None,
            exit: 1,
            stderr: &["cannot write", "No space left", "no file output was changed"],
            outputs: &[],
        }
    };
}

#[test]
#[rustfmt::skip]
fn a_run_that_fails_on_one_output_changes_none() {
    check_all(&[
        full!("render: --hdr on a full device after -o", render ["-o", "x.png", "--hdr", "/dev/full"]),
        full!("render: --stats-json on a full device after -o and --hdr",
            render ["-o", "x.png", "--hdr", "x.pfm", "--stats-json", "/dev/full"]),
        full!("render: --stats-json on a symlink to a full device",
            render ["-o", "x.png", "--stats-json", "full.json"]),
        full!("trace-pixel: --obj on a full device after --json",
            trace ["--json", "t.json", "--obj", "/dev/full"]),
        full!("trace-pixel: --ply on a full device after --json and --obj",
            trace ["--json", "t.json", "--obj", "t.obj", "--ply", "/dev/full"]),
        full!("trace-pixel: --png on a full device after the three others",
            trace ["--json", "t.json", "--obj", "t.obj", "--ply", "t.ply", "--png", "/dev/full"]),
        full!("bench: --export-csv on a full device after --json",
            bench ["--json", "b.json", "--export-csv", "/dev/full"]),
        full!("bench: --export-markdown on a full device after --json and --export-csv",
            bench ["--json", "b.json", "--export-csv", "b.csv", "--export-markdown", "/dev/full"]),
        full!("diff: --json on a full device after --out",
            ["diff", "a.pfm", "b.pfm", "--out", "d.png", "--json", "/dev/full"]),
    ]);
}
