//! The hostile-output catalogue: outputs that name an input or each other, devices, FIFOs,
//! symlinks, standard output, unusable directories and memory limits, for render (bench,
//! variance and meshgen: hostile_outputs_commands.rs). Each case checks the exit code, the
//! message, no panic, no hang, and that no input or earlier output changed
//! (`common::hostile`).

use crate::common;

use common::hostile::setup_outputs as out;
use common::hostile::{Case, TIMEOUT, check_all, run, setup};
use std::path::Path;

/// The lab's box under a name with an image extension: the scene parser does not care.
fn scene_png(d: &Path) {
    setup::cornell_box(d);
    std::fs::copy(d.join("cornell_box.obj"), d.join("scene.png")).unwrap();
}

/// Builds a render case: `cornell_box.obj`, tiny size, then `extra`.
macro_rules! render {
    ($name:expr, $setup:expr, [$($a:expr),*], $exit:expr, [$($m:expr),*], [$($o:expr),*]) => {
        Case {
            name: $name,
            setup: $setup,
            args: &["render", "cornell_box.obj", "--size", "8", "8", "-q", $($a),*],
            stdin: None,
            exit: $exit,
            stderr: &[$($m),*],
            outputs: &[$($o),*],
        }
    };
}

#[test]
fn render_outputs_that_are_inputs_or_each_other() {
    const SAME_INPUT: &str = "is the same file as the input";
    const SAME_OUTPUT: &str = "are the same file";
    check_all(&[
        Case {
            name: "-o is the scene",
            setup: scene_png,
            args: &[
                "render",
                "scene.png",
                "--size",
                "8",
                "8",
                "-q",
                "-o",
                "scene.png",
            ],
            stdin: None,
            exit: 2,
            stderr: &[SAME_INPUT, "-o scene.png", "SCENE scene.png"],
            outputs: &[],
        },
        Case {
            name: "-o is the scene through ./",
            setup: scene_png,
            args: &[
                "render",
                "scene.png",
                "--size",
                "8",
                "8",
                "-q",
                "-o",
                "./scene.png",
            ],
            stdin: None,
            exit: 2,
            stderr: &[SAME_INPUT],
            outputs: &[],
        },
        Case {
            name: "-o is the scene through ../work/",
            setup: scene_png,
            args: &[
                "render",
                "scene.png",
                "--size",
                "8",
                "8",
                "-q",
                "-o",
                "../work/scene.png",
            ],
            stdin: None,
            exit: 2,
            stderr: &[SAME_INPUT],
            outputs: &[],
        },
        Case {
            name: "-o is the scene by its absolute path",
            setup: scene_png,
            args: &[
                "render",
                "scene.png",
                "--size",
                "8",
                "8",
                "-q",
                "-o",
                "{dir}/scene.png",
            ],
            stdin: None,
            exit: 2,
            stderr: &[SAME_INPUT],
            outputs: &[],
        },
        Case {
            name: "the lab's -input is the output",
            setup: scene_png,
            args: &[
                "render",
                "-input",
                "scene.png",
                "--size",
                "8",
                "8",
                "-q",
                "-o",
                "scene.png",
            ],
            stdin: None,
            exit: 2,
            stderr: &[SAME_INPUT],
            outputs: &[],
        },
        render!(
            "-o is a symlink to the scene",
            |d| {
                setup::cornell_box(d);
                setup::symlink(d, "link.png", "cornell_box.obj")
            },
            ["-o", "link.png"],
            2,
            [SAME_INPUT, "link.png"],
            []
        ),
        render!(
            "-o is a hard link to the scene",
            |d| {
                setup::cornell_box(d);
                out::hard_link(d, "hard.png", "cornell_box.obj")
            },
            ["-o", "hard.png"],
            2,
            [SAME_INPUT, "hard.png"],
            []
        ),
        render!(
            "--hdr is a hard link to the scene",
            |d| {
                setup::cornell_box(d);
                out::hard_link(d, "hard.exr", "cornell_box.obj")
            },
            ["--hdr", "hard.exr"],
            2,
            [SAME_INPUT, "--hdr hard.exr"],
            []
        ),
        render!(
            "--stats-json is the scene",
            setup::cornell_box,
            ["--stats-json", "cornell_box.obj"],
            2,
            [SAME_INPUT, "--stats-json"],
            []
        ),
        render!(
            "-o and --hdr are the same EXR",
            setup::cornell_box,
            ["-o", "a.exr", "--hdr", "./a.exr"],
            2,
            [SAME_OUTPUT, "-o a.exr", "--hdr ./a.exr"],
            []
        ),
        render!(
            "--hdr and --stats-json are the same file",
            setup::cornell_box,
            ["--hdr", "a.exr", "--stats-json", "a.exr"],
            2,
            [SAME_OUTPUT, "--stats-json a.exr"],
            []
        ),
        render!(
            "-o and --stats-json are the same existing file",
            |d| {
                setup::cornell_box(d);
                setup::file(d, "x.png", b"old")
            },
            ["-o", "x.png", "--stats-json", "{dir}/x.png"],
            2,
            [SAME_OUTPUT],
            []
        ),
        render!(
            "-o and --hdr meet through a subdirectory's ..",
            |d| {
                setup::cornell_box(d);
                out::dir(d, "sub")
            },
            ["-o", "x.pfm", "--hdr", "sub/../x.pfm"],
            2,
            [SAME_OUTPUT],
            []
        ),
        render!(
            "--hdr is a symlink to -o",
            |d| {
                setup::cornell_box(d);
                setup::symlink(d, "l.pfm", "x.pfm")
            },
            ["-o", "x.pfm", "--hdr", "l.pfm"],
            2,
            [SAME_OUTPUT],
            []
        ),
        render!(
            "-o and --stats-json both standard output",
            setup::cornell_box,
            ["-o", "-", "--stats-json", "-"],
            2,
            [SAME_OUTPUT, "standard output"],
            []
        ),
    ]);
}

#[test]
fn render_special_files_and_directories() {
    check_all(&[
        render!(
            "-o /dev/null",
            setup::cornell_box,
            ["-o", "/dev/null"],
            0,
            [],
            []
        ),
        render!(
            "every output /dev/null",
            setup::cornell_box,
            [
                "-o",
                "/dev/null",
                "--hdr",
                "/dev/null",
                "--stats-json",
                "/dev/null"
            ],
            0,
            [],
            []
        ),
        render!(
            "-o /dev/full",
            setup::cornell_box,
            ["-o", "/dev/full"],
            1,
            ["cannot write /dev/full", "No space left"],
            []
        ),
        render!(
            "--hdr /dev/full",
            setup::cornell_box,
            ["-o", "x.png", "--hdr", "/dev/full"],
            1,
            ["cannot write /dev/full"],
            []
        ),
        render!(
            "--stats-json /dev/full",
            setup::cornell_box,
            ["-o", "x.png", "--stats-json", "/dev/full"],
            1,
            ["cannot write /dev/full"],
            []
        ),
        render!(
            "a symlink to /dev/null stays a symlink",
            |d| {
                setup::cornell_box(d);
                setup::symlink(d, "null.png", "/dev/null")
            },
            ["-o", "null.png"],
            0,
            [],
            []
        ),
        render!(
            "a symlink to /dev/full",
            |d| {
                setup::cornell_box(d);
                setup::symlink(d, "full.exr", "/dev/full")
            },
            ["-o", "x.png", "--hdr", "full.exr"],
            1,
            ["cannot write full.exr", "No space left"],
            []
        ),
        render!(
            "a symlink to a regular file is written through, atomically",
            |d| {
                setup::cornell_box(d);
                setup::file(d, "real.png", b"old");
                setup::symlink(d, "l.png", "real.png")
            },
            ["-o", "l.png"],
            0,
            [],
            ["real.png"]
        ),
        render!(
            "a dangling symlink creates its target",
            |d| {
                setup::cornell_box(d);
                setup::symlink(d, "l.png", "made.png")
            },
            ["-o", "l.png"],
            0,
            [],
            ["made.png"]
        ),
        render!(
            "a symlink loop is refused before rendering",
            |d| {
                setup::cornell_box(d);
                setup::symlink(d, "a.png", "b.png");
                setup::symlink(d, "b.png", "a.png")
            },
            ["-o", "a.png"],
            1,
            ["cannot write a.png", "loop"],
            []
        ),
        render!(
            "a FIFO with a reader gets the PNG",
            |d| {
                setup::cornell_box(d);
                out::fifo_with_reader(d, "pipe.png")
            },
            ["-o", "pipe.png"],
            0,
            [],
            []
        ),
        render!(
            "a FIFO without an extension gets PNG",
            |d| {
                setup::cornell_box(d);
                out::fifo_with_reader(d, "pipe")
            },
            ["-o", "pipe"],
            0,
            [],
            []
        ),
        render!(
            "an EXR into a FIFO is encoded in memory first",
            |d| {
                setup::cornell_box(d);
                out::fifo_with_reader(d, "pipe.exr")
            },
            ["-o", "x.png", "--hdr", "pipe.exr"],
            0,
            [],
            ["x.png"]
        ),
        render!(
            "--stats-json into a FIFO with a reader",
            |d| {
                setup::cornell_box(d);
                out::fifo_with_reader(d, "stats")
            },
            ["-o", "x.png", "--stats-json", "stats"],
            0,
            [],
            ["x.png"]
        ),
        render!(
            "-o /dev/stdout is standard output, not a path to rename over",
            setup::cornell_box,
            ["-o", "/dev/stdout"],
            0,
            [],
            []
        ),
        render!(
            "-o /dev/stdout and --stats-json - collide",
            setup::cornell_box,
            ["-o", "/dev/stdout", "--stats-json", "-"],
            2,
            ["are the same file"],
            []
        ),
        render!(
            "-o - writes PNG to stdout",
            setup::cornell_box,
            ["-o", "-"],
            0,
            [],
            []
        ),
        render!(
            "missing directory",
            setup::cornell_box,
            ["-o", "nodir/x.png"],
            1,
            ["cannot write nodir/x.png", "does not exist"],
            []
        ),
        render!(
            "--stats-json in a missing directory, found before rendering",
            setup::cornell_box,
            ["-o", "x.png", "--stats-json", "nodir/s.json"],
            1,
            ["nodir", "does not exist"],
            []
        ),
        render!(
            "parent is a file",
            |d| {
                setup::cornell_box(d);
                setup::file(d, "f.txt", b"x")
            },
            ["-o", "f.txt/x.png"],
            1,
            ["f.txt is not a directory"],
            []
        ),
        render!(
            "-o is a directory",
            |d| {
                setup::cornell_box(d);
                out::dir(d, "d.png")
            },
            ["-o", "d.png"],
            1,
            ["it is a directory"],
            []
        ),
        render!(
            "--hdr is a directory",
            |d| {
                setup::cornell_box(d);
                out::dir(d, "d.exr")
            },
            ["--hdr", "d.exr"],
            1,
            ["cannot write d.exr", "it is a directory"],
            []
        ),
        render!(
            "--max-memory too small",
            setup::cornell_box,
            ["--max-memory", "1M"],
            1,
            ["needs about", "--max-memory 1 MiB"],
            []
        ),
        Case {
            name: "a huge render under --max-memory keeps the old output",
            setup: |d| {
                setup::cornell_box(d);
                setup::file(d, "render.png", b"old")
            },
            args: &[
                "render",
                "cornell_box.obj",
                "--size",
                "16384",
                "16384",
                "-q",
                "--max-memory",
                "2G",
            ],
            stdin: None,
            exit: 1,
            stderr: &["needs about 4.0 GiB", "GiB", "--max-memory 2.0 GiB"],
            outputs: &[],
        },
        render!(
            "--max-memory is not a size",
            setup::cornell_box,
            ["--max-memory", "12X"],
            2,
            ["expected a size"],
            []
        ),
    ]);
}

#[test]
fn stdout_gets_the_png_and_the_summary_goes_to_stderr() {
    let dir = tempfile::tempdir().unwrap();
    setup::cornell_box(dir.path());
    let r = run(
        dir.path(),
        &["render", "cornell_box.obj", "--size", "8", "8", "-o", "-"],
        None,
        TIMEOUT,
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(r.stdout.starts_with("\u{FFFD}PNG"), "stdout is not a PNG");
    assert!(r.stderr.contains("wrote   -"), "{}", r.stderr);
    let r = run(
        dir.path(),
        &[
            "render",
            "cornell_box.obj",
            "--size",
            "8",
            "8",
            "-q",
            "-o",
            "/dev/null",
            "--hdr",
            "-",
        ],
        None,
        TIMEOUT,
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stdout.starts_with("PF\n8 8\n-1.0\n"),
        "stdout is not a PFM"
    );
}
