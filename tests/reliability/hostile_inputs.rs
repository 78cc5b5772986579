//! The hostile-input catalogue for scene files, numbers and messages: directories, devices,
//! FIFOs and standard input as scenes, oversized and binary files, escape sequences and huge
//! tokens, numbers at the parser's bounds, scales from 1e-6 to 1e6, across render, bench and
//! variance (repeated and meaningless flags: `hostile_flags.rs`). Every case checks the exit
//! code, a message fragment, no panic, no hang, and that no input changed
//! (`common::hostile`).

use crate::common;

use common::hostile::setup_streams::{fifo_feeding, scaled, sparse};
use common::hostile::{Case, TIMEOUT, case, check_all, run, setup};
use std::path::Path;

/// The lab's box, fed through FIFOs and standard input.
const BOX: &[u8] = include_bytes!("../../scenes/cornell_box.obj");

const DIR_MSG: &str = "found a directory";
const DEV_MSG: &str = "found a character device";

fn subdir(d: &Path) {
    std::fs::create_dir(d.join("scene.obj")).unwrap();
}

const VARIANCE_OUT: &[&str] = &[
    "r",
    "r/table.txt",
    "r/results.csv",
    "r/seeds.csv",
    "r/perceived.csv",
    "r/spectra.csv",
    "r/results.json",
    "r/mse.png",
    "r/contact_sheet.png",
    "r/heat_random_N4.png",
    "r/spectrum_N1.png",
    "r/spectrum_N4.png",
];

#[test]
fn inputs_that_are_not_scene_files() {
    check_all(&[
        case(
            "directory as scene",
            subdir,
            &["scene.obj", "-q"],
            1,
            &["scene.obj: expected a scene file", DIR_MSG],
            &[],
        ),
        case(
            "/dev/zero as scene",
            setup::nothing,
            &["/dev/zero", "-q"],
            1,
            &["/dev/zero", DEV_MSG],
            &[],
        ),
        case(
            "/dev/null as scene",
            setup::nothing,
            &["/dev/null", "-q"],
            1,
            &["/dev/null", DEV_MSG],
            &[],
        ),
        case(
            "lab -input /dev/zero",
            setup::nothing,
            &["-input", "/dev/zero", "-size", "8", "8"],
            1,
            &[DEV_MSG],
            &[],
        ),
        case(
            "empty scene file",
            |d| setup::file(d, "empty.obj", b""),
            &["empty.obj", "-q"],
            1,
            &["empty.obj:1:", "at least one face"],
            &[],
        ),
        case(
            "oversized scene (sparse, 257 MiB)",
            |d| sparse(d, "huge.obj", 257 << 20),
            &["huge.obj", "-q"],
            1,
            &[
                "huge.obj: expected a scene of at most 256 MiB",
                "269484032 bytes",
            ],
            &[],
        ),
        case(
            "symlink to a directory",
            |d| {
                subdir(d);
                setup::symlink(d, "link.obj", "scene.obj")
            },
            &["link.obj", "-q"],
            1,
            &[DIR_MSG],
            &[],
        ),
        case(
            "bench: directory",
            subdir,
            &["bench", "scene.obj", "--runs", "1", "-q"],
            1,
            &[DIR_MSG],
            &[],
        ),
        case(
            "bench: /dev/zero",
            setup::nothing,
            &["bench", "/dev/zero", "--runs", "1", "-q"],
            1,
            &[DEV_MSG],
            &[],
        ),
        case(
            "variance: directory",
            subdir,
            &["variance", "scene.obj", "-q", "--out", "r"],
            1,
            &[DIR_MSG],
            &[],
        ),
        case(
            "variance: /dev/zero",
            setup::nothing,
            &["variance", "/dev/zero", "-q", "--out", "r"],
            1,
            &[DEV_MSG],
            &[],
        ),
    ]);
}

#[test]
fn fifos_and_standard_input_are_read_once() {
    let mut cases = vec![
        case(
            "render: FIFO scene",
            |d| fifo_feeding(d, "pipe.obj", BOX),
            &["pipe.obj", "--size", "8", "8", "-q", "-o", "a.png"],
            0,
            &[],
            &["a.png"],
        ),
        case(
            "bench: FIFO scene",
            |d| fifo_feeding(d, "pipe.obj", BOX),
            &["bench", "pipe.obj", "--runs", "1", "--size", "8", "8", "-q"],
            0,
            &[],
            &[],
        ),
        case(
            "variance: FIFO scene",
            |d| fifo_feeding(d, "pipe.obj", BOX),
            &[
                "variance",
                "pipe.obj",
                "--budgets",
                "1,4",
                "--heatmap-n",
                "4",
                "--seeds",
                "2",
                "--size",
                "8",
                "8",
                "--reference-samples",
                "4",
                "--mask-samples",
                "4",
                "--samplers",
                "random",
                "-q",
                "--no-cache",
                "--out",
                "r",
            ],
            0,
            &[],
            VARIANCE_OUT,
        ),
        case(
            "render: garbage through a FIFO names the FIFO and line",
            |d| fifo_feeding(d, "pipe.obj", b"material\nv 0 0 x\n"),
            &["pipe.obj", "-q"],
            1,
            &["pipe.obj:2:", "3rd number of `v`"],
            &[],
        ),
    ];
    for (name, args, exit, stderr, outputs) in [
        (
            "render: - reads the scene from stdin",
            &["-", "--size", "8", "8", "-q", "-o", "a.png"][..],
            0,
            &[][..],
            &["a.png"][..],
        ),
        (
            "render: lab -input -",
            &["-input", "-", "-size", "8", "8", "-output", "a.png"],
            0,
            &[],
            &["a.png"],
        ),
        (
            "bench: - reads the scene from stdin",
            &["bench", "-", "--runs", "1", "--size", "8", "8"],
            0,
            &[],
            &[],
        ),
        (
            "variance: - reads the scene from stdin",
            &[
                "variance",
                "-",
                "--budgets",
                "1,4",
                "--heatmap-n",
                "4",
                "--seeds",
                "2",
                "--size",
                "8",
                "8",
                "--reference-samples",
                "4",
                "--mask-samples",
                "4",
                "--samplers",
                "random",
                "-q",
                "--no-cache",
                "--out",
                "r",
            ],
            0,
            &[],
            VARIANCE_OUT,
        ),
    ] {
        cases.push(Case {
            stdin: Some(BOX),
            ..case(name, setup::nothing, args, exit, stderr, outputs)
        });
    }
    cases.push(Case {
        stdin: Some(b""),
        ..case(
            "render: empty stdin",
            setup::nothing,
            &["-", "-q"],
            1,
            &["<stdin>:1:", "at least one face"],
            &[],
        )
    });
    cases.push(Case {
        stdin: Some(b"v 1 2 3 4\n"),
        ..case(
            "bench: bad stdin names <stdin>:line",
            setup::nothing,
            &["bench", "-", "-q"],
            1,
            &["<stdin>:1:", "extra `4`"],
            &[],
        )
    });
    check_all(&cases);
}

#[test]
fn bytes_that_are_not_text_and_tokens_that_are_not_polite() {
    check_all(&[
        case(
            "binary garbage",
            |d| setup::file(d, "bin.obj", b"v 0 0 0\n\x89PNG\r\n\x1a\n\xff\xfe"),
            &["bin.obj", "-q"],
            1,
            &["bin.obj:2:", "UTF-8"],
            &[],
        ),
        case(
            "NUL bytes in a number",
            |d| setup::file(d, "nul.obj", b"v 0 0 1\0\n"),
            &["nul.obj", "-q"],
            1,
            &["nul.obj:1:", "`1\\x00`"],
            &[],
        ),
        case(
            "NUL bytes as a keyword: a warning, escaped",
            |d| setup::file(d, "nul.obj", &[b"\0\0 1\n", BOX].concat()),
            &["nul.obj", "--size", "8", "8", "-q", "-o", "a.png"],
            0,
            &["nul.obj:1: warning: unknown keyword `\\x00\\x00`"],
            &["a.png"],
        ),
        case(
            "CRLF line ends render",
            |d| {
                setup::file(
                    d,
                    "crlf.obj",
                    String::from_utf8_lossy(BOX)
                        .replace('\n', "\r\n")
                        .as_bytes(),
                )
            },
            &["crlf.obj", "--size", "8", "8", "-q", "-o", "a.png"],
            0,
            &[],
            &["a.png"],
        ),
        case(
            "ANSI escape in a bad number is escaped",
            |d| setup::file(d, "esc.obj", b"v 0 0 \x1b[2J\x1b]0;pwned\x07\n"),
            &["esc.obj", "-q"],
            1,
            &["esc.obj:1:", "`\\x1b[2J\\x1b]0;pwned\\x07`"],
            &[],
        ),
        case(
            "ANSI escape in an unknown keyword: a warning, escaped",
            |d| setup::file(d, "esc.obj", &[b"\x1b[31mred 1\n", BOX].concat()),
            &["esc.obj", "--size", "8", "8", "-q", "-o", "a.png"],
            0,
            &["esc.obj:1: warning: unknown keyword `\\x1b[31mred`"],
            &["a.png"],
        ),
        case(
            "a 10 MB token is cut",
            |d| {
                setup::file(
                    d,
                    "long.obj",
                    format!("v 0 0 {}\n", "9".repeat(10_000_000)).as_bytes(),
                )
            },
            &["long.obj", "-q"],
            1,
            &["long.obj:1:", "99999…`"],
            &[],
        ),
        case(
            "a number past 1e9",
            |d| setup::file(d, "big.obj", b"v 0 0 1e10\n"),
            &["big.obj", "-q"],
            1,
            &["big.obj:1:", "magnitude at most 1e9"],
            &[],
        ),
        case(
            "NaN literal",
            |d| setup::file(d, "nan.obj", b"material\ndiffuse NaN 0 0\n"),
            &["nan.obj", "-q"],
            1,
            &["nan.obj:2:", "finite number", "`NaN`"],
            &[],
        ),
        case(
            "inf literal",
            |d| setup::file(d, "inf.obj", b"v inf 0 0\n"),
            &["inf.obj", "-q"],
            1,
            &["inf.obj:1:", "finite number"],
            &[],
        ),
        case(
            "f32 overflow literal",
            |d| setup::file(d, "ovf.obj", b"v 1e39 0 0\n"),
            &["ovf.obj", "-q"],
            1,
            &["ovf.obj:1:", "of magnitude at most 1e9", "`1e39`"],
            &[],
        ),
        case(
            "control characters in a file name",
            |d| setup::file(d, "a\x1bb.obj", b"v 0 0 q\n"),
            &["a\x1bb.obj", "-q"],
            1,
            &["a\\x1bb.obj:1:"],
            &[],
        ),
    ]);
}

#[test]
fn no_escape_byte_and_no_flood_reach_the_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup::file(d, "esc.obj", b"\x1b[31mred 1\nv 0 0 \x1b[2J\n");
    setup::file(
        d,
        "long.obj",
        format!(
            "{} 1\nv 0 0 {}\n",
            "k".repeat(10_000_000),
            "x".repeat(10_000_000)
        )
        .as_bytes(),
    );
    for (scene, max) in [("esc.obj", 400), ("long.obj", 600)] {
        let r = run(d, &[scene, "-q"], None, TIMEOUT);
        assert_eq!(r.code, Some(1), "{}", r.stderr);
        assert!(!r.stderr.contains('\u{1b}'), "raw ESC in {:?}", r.stderr);
        assert!(r.stderr.len() < max, "{} bytes of stderr", r.stderr.len());
    }
}

#[test]
fn numbers_at_the_bounds_and_scales_from_1e_minus_6_to_1e6() {
    check_all(&[
        case(
            "scale 1e-6 renders",
            |d| scaled(d, "s.obj", "cornell_box.obj", 1e-6),
            &["s.obj", "--size", "8", "8", "-q", "-o", "a.png"],
            0,
            &[],
            &["a.png"],
        ),
        case(
            "scale 1e6 renders",
            |d| scaled(d, "s.obj", "cornell_box.obj", 1e6),
            &["s.obj", "--size", "8", "8", "-q", "-o", "a.png"],
            0,
            &[],
            &["a.png"],
        ),
        case(
            "spheres at scale 1e-6",
            |d| scaled(d, "s.obj", "reflective_spheres.obj", 1e-6),
            &["s.obj", "--size", "8", "8", "-q", "-o", "a.png"],
            0,
            &[],
            &["a.png"],
        ),
        case(
            "a sliver face is still degenerate",
            |d| {
                setup::file(
                    d,
                    "sl.obj",
                    b"material\nm 0\nv 0 0 0\nv 1 0 0\nv 2 1e-12 0\nf 1 2 3\n",
                )
            },
            &["sl.obj", "-q"],
            1,
            &["sl.obj:6:", "degenerate"],
            &[],
        ),
        case(
            "mirrors of 1e9 over 64 bounces: finite, with a warning",
            |d| setup::file(d, "m.obj", MIRRORS),
            &[
                "m.obj",
                "--bounces",
                "64",
                "--size",
                "8",
                "8",
                "-q",
                "-o",
                "a.pfm",
            ],
            0,
            &["overflowed f32 and were clamped"],
            &["a.pfm"],
        ),
    ]);
}

/// Mirrors that reflect a billion times what they receive, facing each other.
const MIRRORS: &[u8] =
    b"material\ndiffuse 1e9 1e9 1e9\nreflective 1e9 1e9 1e9\nemitted 1e9 1e9 1e9\n\
v -1e9 -1e9 -1e9\nv 1e9 -1e9 -1e9\nv 1e9 1e9 -1e9\nv -1e9 1e9 -1e9\n\
v -1e9 -1e9 1e9\nv 1e9 -1e9 1e9\nv 1e9 1e9 1e9\nv -1e9 1e9 1e9\n\
m 0\nf 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 4 3 7 8\n\
PerspectiveCamera {\ncamera_position 0 0 0\npoint_of_interest 0 0 -1\nangle 90\n}\n";

/// Lights of 1e9 a billion units wide, next to surfaces of diffuse 1e9, seen close up.
const BRIGHT: &[u8] = b"material\ndiffuse 1e9 1e9 1e9\nemitted 1e9 1e9 1e9\nmaterial\ndiffuse 1e9 1e9 1e9\nreflective 1 1 1\n\
v -1e9 -1e9 0\nv 1e9 -1e9 0\nv 1e9 1e9 0\nv -1e9 1e9 0\nv -1e9 -1e9 1e-3\nv 1e9 -1e9 1e-3\nv 1e9 1e9 1e-3\nv -1e9 1e9 1e-3\n\
m 1\nf 1 2 3 4\nm 0\nf 8 7 6 5\ns 0 0 5e-4 1e-4\n\
PerspectiveCamera {\ncamera_position 0 0 4e-4\npoint_of_interest 0 0 0\nangle 170\n}\n";

/// Every pixel of every accepted scene is finite, with either engine, in either light model.
#[test]
fn adversarial_accepted_scenes_render_finite_pixels_with_both_engines() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup::file(d, "mirrors.obj", MIRRORS);
    setup::file(d, "bright.obj", BRIGHT);
    let mut checked = 0;
    for scene in ["mirrors.obj", "bright.obj"] {
        for engine in ["wavefront", "reference"] {
            for model in ["lab", "rpi"] {
                let args = [
                    scene,
                    "--engine",
                    engine,
                    "--light-model",
                    model,
                    "--bounces",
                    "64",
                    "--size",
                    "12",
                    "12",
                    "--shadows",
                    "soft",
                    "--shadow-samples",
                    "4",
                    "--two-sided",
                    "-q",
                    "-o",
                    "a.pfm",
                ];
                let r = run(d, &args, None, TIMEOUT);
                assert_eq!(r.code, Some(0), "{args:?}: {}", r.stderr);
                let film = raywave::render::film::Film::read_pfm(&d.join("a.pfm")).unwrap();
                let bad = film.pixels.iter().filter(|p| !p.is_finite()).count();
                assert_eq!(bad, 0, "{args:?}: {bad} non-finite pixels");
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 8);
}

/// A bundled scene scaled by 1e-6 and by 1e6 renders the same image as at scale 1 (with RPI's
/// light model, whose 1/(π·d²) cancels the light's area; the lab's model grows with it).
#[test]
fn scales_1e_minus_6_and_1e6_render_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup::cornell_box(d);
    scaled(d, "small.obj", "cornell_box.obj", 1e-6);
    scaled(d, "large.obj", "cornell_box.obj", 1e6);
    for engine in ["wavefront", "reference"] {
        let image = |scene: &str| {
            let args = [
                scene,
                "--engine",
                engine,
                "--light-model",
                "rpi",
                "--size",
                "24",
                "24",
                "-q",
                "-o",
                "a.pfm",
            ];
            let r = run(d, &args, None, TIMEOUT);
            assert_eq!(r.code, Some(0), "{args:?}: {}", r.stderr);
            raywave::render::film::Film::read_pfm(&d.join("a.pfm")).unwrap()
        };
        let unit = image("cornell_box.obj");
        for scene in ["small.obj", "large.obj"] {
            let other = image(scene);
            // A ray through a silhouette edge may round to the other side at another scale:
            // at most two of the 576 pixels may differ.
            let differ: Vec<String> = unit
                .pixels
                .iter()
                .zip(&other.pixels)
                .enumerate()
                .filter(|(_, (a, b))| {
                    (**a - **b).abs().max_element() > 1e-3 * a.max_element().max(1.0)
                })
                .map(|(i, (a, b))| format!("pixel {i}: {a} vs {b}"))
                .collect();
            assert!(differ.len() <= 2, "{engine} {scene}: {}", differ.join("; "));
        }
    }
}
