//! The hostile-output catalogue for bench, variance and meshgen (render's is in
//! hostile_outputs.rs): outputs that name an input or each other, devices, symlinks, standard
//! output and unusable directories.

use crate::common;

use common::hostile::setup_outputs as out;
use common::hostile::{Case, check_all, setup};

#[test]
fn bench_variance_and_meshgen_outputs() {
    check_all(&[
        Case {
            name: "bench --json is the scene",
            setup: setup::cornell_box,
            args: &[
                "bench",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--runs",
                "1",
                "-q",
                "--json",
                "cornell_box.obj",
            ],
            stdin: None,
            exit: 2,
            stderr: &["--json cornell_box.obj is the same file as the input SCENE"],
            outputs: &[],
        },
        Case {
            name: "bench --save and --json are the same file",
            setup: setup::cornell_box,
            args: &[
                "bench",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--runs",
                "1",
                "-q",
                "--save",
                "a",
                "--dir",
                "r",
                "--json",
                "r/a.json",
            ],
            stdin: None,
            exit: 2,
            stderr: &["--save r/a.json and --json r/a.json are the same file"],
            outputs: &[],
        },
        Case {
            name: "bench --json would overwrite the --compare record",
            setup: |d| {
                setup::cornell_box(d);
                std::fs::create_dir(d.join(".raywave-bench")).unwrap();
                setup::file(d, ".raywave-bench/b.json", b"{}");
            },
            args: &[
                "bench",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--runs",
                "1",
                "-q",
                "--compare",
                "b",
                "--json",
                ".raywave-bench/b.json",
            ],
            stdin: None,
            exit: 2,
            stderr: &["is the same file as the input --compare"],
            outputs: &[],
        },
        Case {
            name: "bench --json /dev/full",
            setup: setup::cornell_box,
            args: &[
                "bench",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--runs",
                "1",
                "-q",
                "--json",
                "/dev/full",
            ],
            stdin: None,
            exit: 1,
            stderr: &["cannot write /dev/full"],
            outputs: &[],
        },
        Case {
            name: "bench --json /dev/null",
            setup: setup::cornell_box,
            args: &[
                "bench",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--runs",
                "1",
                "-q",
                "--json",
                "/dev/null",
            ],
            stdin: None,
            exit: 0,
            stderr: &[],
            outputs: &[],
        },
        Case {
            name: "bench --json in a missing directory",
            setup: setup::cornell_box,
            args: &[
                "bench",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--runs",
                "1",
                "-q",
                "--json",
                "no/b.json",
            ],
            stdin: None,
            exit: 1,
            stderr: &["cannot write no/b.json", "does not exist"],
            outputs: &[],
        },
        Case {
            name: "variance would write its table over the scene",
            setup: |d| {
                setup::cornell_box(d);
                std::fs::rename(d.join("cornell_box.obj"), d.join("table.txt")).unwrap()
            },
            args: &[
                "variance",
                "table.txt",
                "--size",
                "8",
                "8",
                "--out",
                ".",
                "-q",
            ],
            stdin: None,
            exit: 2,
            stderr: &["--out ./table.txt is the same file as the input SCENE table.txt"],
            outputs: &[],
        },
        Case {
            name: "variance --out under a file",
            setup: |d| {
                setup::cornell_box(d);
                setup::file(d, "f", b"x")
            },
            args: &[
                "variance",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--out",
                "f/report",
                "-q",
            ],
            stdin: None,
            exit: 1,
            stderr: &["f is not a directory"],
            outputs: &[],
        },
        Case {
            name: "bench --json is a symlink to the scene",
            setup: |d| {
                setup::cornell_box(d);
                setup::symlink(d, "b.json", "cornell_box.obj")
            },
            args: &[
                "bench",
                "cornell_box.obj",
                "--size",
                "8",
                "8",
                "--runs",
                "1",
                "-q",
                "--json",
                "b.json",
            ],
            stdin: None,
            exit: 2,
            stderr: &["--json b.json is the same file as the input SCENE"],
            outputs: &[],
        },
        Case {
            name: "variance would draw a heat map over the scene",
            setup: |d| {
                setup::cornell_box(d);
                std::fs::rename(d.join("cornell_box.obj"), d.join("heat_random_N16.png")).unwrap()
            },
            args: &[
                "variance",
                "heat_random_N16.png",
                "--size",
                "8",
                "8",
                "--samplers",
                "random",
                "--out",
                ".",
                "-q",
            ],
            stdin: None,
            exit: 2,
            stderr: &["is the same file as the input SCENE heat_random_N16.png"],
            outputs: &[],
        },
        Case {
            name: "meshgen -o a symlink to /dev/null",
            setup: |d| setup::symlink(d, "m.obj", "/dev/null"),
            args: &["meshgen", "--triangles", "36", "-o", "m.obj"],
            stdin: None,
            exit: 0,
            stderr: &[],
            outputs: &[],
        },
        Case {
            name: "meshgen -o /dev/full",
            setup: setup::nothing,
            args: &["meshgen", "--triangles", "36", "-o", "/dev/full"],
            stdin: None,
            exit: 1,
            stderr: &["cannot write /dev/full", "No space left"],
            outputs: &[],
        },
        Case {
            name: "meshgen -o /dev/null",
            setup: setup::nothing,
            args: &["meshgen", "--triangles", "36", "-o", "/dev/null"],
            stdin: None,
            exit: 0,
            stderr: &[],
            outputs: &[],
        },
        Case {
            name: "meshgen -o - says what it wrote on stderr",
            setup: setup::nothing,
            args: &["meshgen", "--triangles", "36", "-o", "-"],
            stdin: None,
            exit: 0,
            stderr: &["wrote   -: 36 triangles"],
            outputs: &[],
        },
        Case {
            name: "meshgen -o a directory",
            setup: |d| out::dir(d, "m.obj"),
            args: &["meshgen", "--triangles", "36", "-o", "m.obj"],
            stdin: None,
            exit: 1,
            stderr: &["cannot write m.obj", "it is a directory"],
            outputs: &[],
        },
        Case {
            name: "meshgen -o in a missing directory",
            setup: setup::nothing,
            args: &["meshgen", "--triangles", "36", "-o", "no/m.obj"],
            stdin: None,
            exit: 1,
            stderr: &["does not exist"],
            outputs: &[],
        },
        Case {
            name: "meshgen -o a symlink to a file writes the file",
            setup: |d| {
                setup::file(d, "old.obj", b"old");
                setup::symlink(d, "m.obj", "old.obj")
            },
            args: &["meshgen", "--triangles", "36", "-o", "m.obj"],
            stdin: None,
            exit: 0,
            stderr: &[],
            outputs: &["old.obj"],
        },
    ]);
}
