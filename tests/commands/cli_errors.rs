//! The command line's failures: usage errors (exit 2, clap's message), and scene and output
//! errors (exit 1, file:line), all caught before the render, with no output left behind.

use crate::common;

use common::bin::{dir_with, files_in, raywave, scenes, stderr, words};
use std::time::{Duration, Instant};

#[test]
fn bad_flags_are_usage_errors_with_exit_code_2() {
    let dir = dir_with(&["cornell_box.obj"]);
    let cases: &[&[&str]] = &[
        &["--frobnicate"],
        &["-frobnicate"],
        &["--size", "0", "10"],
        &["--size", "10", "0"],
        &["--size", "abc", "5"],
        &["--size", "5"],
        &["--shadows", "maybe"],
        &["--background", "1", "nan", "0"],
        &["--background", "1", "inf", "0"],
        &["--background", "1", "-1", "0"],
        &["--background", "1", "0"],
        &["--shadow-samples", "0"],
        &["--bounces", "-1"],
        &["--threads", "0"],
        &["--sampler", "best"],
        &["-size", "200"],
        &["-num_bounces", "x"],
        &["-num_bounces", "-1"],
        &["-background_color", "1", "0"],
        &["-ambient_light", "1", "nan", "0"],
        &["-sphere_rasterization", "16"],
        &["-num_photons_to_shoot", "many"],
        &["--num_glossy_samples"],
        // The lab's and RPI 2023's spellings on one line.
        &["-num_bounces", "1", "--num_shadow_samples", "4"],
        // One setting twice under two spellings.
        &["-num_bounces", "1", "--bounces", "2"],
        &["-soft_shadow", "--shadows", "hard"],
        &["-input", "cornell_box.obj", "-i", "cornell_box.obj"],
        &["--light-model", "phong"],
        &["--ambient", "1", "-1", "0"],
        &["--ring-segments", "2"],
        &["--defaults", "pbrt"],
        &["cornell_box.obj", "--aa", "0"],
    ];
    for args in cases {
        let out = raywave(dir.path(), args);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: expected exit 2, got {:?}: {}",
            out.status,
            stderr(&out)
        );
        // clap prints the usage line for unknown or missing arguments, and for a bad value the
        // flag, what was expected and a pointer to --help.
        let err = stderr(&out);
        assert!(err.starts_with("error:"), "{args:?}: {err}");
        assert!(
            err.contains("Usage:") || err.contains("--help"),
            "{args:?}: no usage message: {err}"
        );
        assert!(
            !dir.path().join("render.png").exists(),
            "{args:?} wrote an image"
        );
    }
}

#[test]
fn float_flags_past_their_type_get_the_magnitude_message_and_infinities_do_not() {
    let dir = dir_with(&["cornell_box.obj"]);
    const F32: &str = "of magnitude past the largest f32, 3.4e38";
    // (arguments, the flag as the message names it, the value, whether it is past the range)
    let cases: &[(&str, &str, &str, bool)] = &[
        ("--background 1 1e39 0", "--background", "1e39", true),
        ("--ambient 0 0 1e39", "--ambient", "1e39", true),
        (
            "-background_color 1 1e39 0",
            "-background_color",
            "1e39",
            true,
        ),
        ("-ambient_light -1e39 0 0", "-ambient_light", "-1e39", true),
        (
            "trace-pixel 1 1 cornell_box.obj --orbit 1e39",
            "--orbit",
            "1e39",
            true,
        ),
        (
            "trace-pixel 1 1 cornell_box.obj --orbit -1e39",
            "--orbit",
            "-1e39",
            true,
        ),
        (
            "trace-pixel 1 1 cornell_box.obj --view-distance 1e39",
            "--view-distance",
            "1e39",
            true,
        ),
        (
            "trace-pixel 1 1 cornell_box.obj --view-from 0 -1e39 0",
            "--view-from",
            "-1e39",
            true,
        ),
        ("--background 1 inf 0", "--background", "inf", false),
        (
            "-background_color 1 -inf 0",
            "-background_color",
            "-inf",
            false,
        ),
        (
            "trace-pixel 1 1 cornell_box.obj --orbit NaN",
            "--orbit",
            "NaN",
            false,
        ),
    ];
    for &(args, flag, value, past) in cases {
        let out = raywave(dir.path(), &words(args));
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args}: {err}");
        assert!(err.contains(flag), "{args}: no {flag} in {err}");
        assert!(err.contains(&format!("found `{value}`")), "{args}: {err}");
        assert_eq!(err.contains(F32), past, "{args}: {err}");
    }
    // f64 flags: past f64's range.
    let out = raywave(dir.path(), &words("diff a.png b.png --fail-above -1e309"));
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("found `-1e309`, of magnitude past the largest f64, 1.8e308"),
        "{err}"
    );
}

/// A scene whose line 6 has a word where a number belongs.
const BAD_SCENE: &str = "material\ndiffuse 1 1 1\nm 0\nv 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n";
/// A ring whose inner radius is not below its outer one, on line 4.
const BAD_RING: &str = "material\ndiffuse 1 1 1\nm 0\nr 0 0 0 1 2 1\n";

/// Something in the scratch directory before a run.
enum Entry {
    /// A copy of a bundled scene.
    Scene(&'static str),
    /// A file with these contents.
    File(&'static str, &'static str),
    /// An empty directory.
    Dir(&'static str),
}
use Entry::{Dir, File, Scene};

/// A run that must fail before rendering: the directory it starts in, its arguments and how it
/// fails.
struct FailsEarly {
    /// What the directory holds before the run.
    setup: &'static [Entry],
    /// The command line, split at white space.
    args: &'static str,
    /// The exit code: 1 for a scene or output error, 2 for a usage error.
    code: i32,
    /// Fragments stderr must contain.
    stderr: &'static [&'static str],
}

/// A textured quad over `tex.ppm`, the texture named on line 2.
const TEXTURED: &str = "material\ntexture_file tex.ppm\nv 0 0 0\nvt 0 0\nv 1 0 0\nvt 1 0\n\
v 1 1 0\nvt 1 1\nm 0\nf 1 2 3\n";

const FAILS_EARLY: &[FailsEarly] = &[
    // A texture that is missing, not a PPM, truncated, empty or too large is an error at its
    // scene line, and the render's output is never started.
    FailsEarly {
        setup: &[File("t.obj", TEXTURED)],
        args: "t.obj --size 8 8",
        code: 1,
        stderr: &["t.obj:2:", "tex.ppm", "cannot read"],
    },
    FailsEarly {
        setup: &[
            File("t.obj", TEXTURED),
            File("tex.ppm", "P2\n1 1\n255\n0\n"),
        ],
        args: "t.obj --size 8 8 -o out.png",
        code: 1,
        stderr: &["t.obj:2:", "`P3` or `P6`", "PGM"],
    },
    FailsEarly {
        setup: &[
            File("t.obj", TEXTURED),
            File("tex.ppm", "P3\n2 2\n255\n1 2 3\n"),
        ],
        args: "t.obj --size 8 8",
        code: 1,
        stderr: &["t.obj:2:", "truncated"],
    },
    FailsEarly {
        setup: &[File("t.obj", TEXTURED), File("tex.ppm", "P3\n0 0\n255\n")],
        args: "t.obj --size 8 8",
        code: 1,
        stderr: &["t.obj:2:", "0×0"],
    },
    FailsEarly {
        setup: &[
            File("t.obj", TEXTURED),
            File("tex.ppm", "P6\n65536 65536\n255\n"),
        ],
        args: "t.obj --size 8 8",
        code: 1,
        stderr: &["t.obj:2:", "65536×65536", "refused before reading"],
    },
    FailsEarly {
        setup: &[File("t.obj", TEXTURED), Dir("tex.ppm")],
        args: "t.obj --size 8 8",
        code: 1,
        stderr: &["t.obj:2:", "directory"],
    },
    // A parse error names file and line and the word it could not read.
    FailsEarly {
        setup: &[File("bad.obj", BAD_SCENE)],
        args: "bad.obj --size 8 8",
        code: 1,
        stderr: &["bad.obj:6:", "zero"],
    },
    // With the lab's spelling and -o too.
    FailsEarly {
        setup: &[File("bad.obj", BAD_SCENE)],
        args: "-input bad.obj -o out.png",
        code: 1,
        stderr: &[],
    },
    // An existing output file is left untouched.
    FailsEarly {
        setup: &[File("bad.obj", BAD_SCENE), File("render.png", "precious")],
        args: "bad.obj --size 8 8",
        code: 1,
        stderr: &[],
    },
    FailsEarly {
        setup: &[File("ring.obj", BAD_RING)],
        args: "ring.obj --size 8 8",
        code: 1,
        stderr: &["ring.obj:4:", "inner < outer"],
    },
    // A missing scene file is named.
    FailsEarly {
        setup: &[],
        args: "nothere.obj --size 8 8",
        code: 1,
        stderr: &["nothere.obj"],
    },
    // A directory instead of a file: not an empty scene.
    FailsEarly {
        setup: &[Dir("sub.obj")],
        args: "sub.obj --size 8 8",
        code: 1,
        stderr: &[],
    },
    // A 16384² soft-shadowed render would take many minutes: failing within seconds shows the
    // output path is checked first.
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "cornell_box.obj --size 16384 16384 --shadows soft -o no/such/dir/out.png",
        code: 1,
        stderr: &["no/such/dir"],
    },
    // The same for --hdr.
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "cornell_box.obj --size 16384 16384 --hdr no/such/dir/out.pfm",
        code: 1,
        stderr: &[],
    },
    // An output path that is a directory.
    FailsEarly {
        setup: &[Scene("cornell_box.obj"), Dir("d.png")],
        args: "cornell_box.obj --size 16384 16384 --shadows soft -o d.png",
        code: 1,
        stderr: &["d.png"],
    },
    // A flag value raywave cannot use is a usage error, like clap's own: exit 2.
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "cornell_box.obj --size 16384 16384 -o out.jpg",
        code: 2,
        stderr: &["out.jpg"],
    }, // A sampler past its limit: the error names the sampler, the limit and why.
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "cornell_box.obj --sampler pmj02 --shadow-samples 0",
        code: 2,
        stderr: &["--shadow-samples 0", "pmj02", "1 to 4096"],
    },
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "cornell_box.obj --sampler pmj02 --shadow-samples 8192",
        code: 2,
        stderr: &["pmj02", "8192", "4096", "tables"],
    },
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "cornell_box.obj --sampler bluenoise --shadow-samples 64 --aa 8",
        code: 2,
        stderr: &["bluenoise", "512 per pixel", "256"],
    },
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "cornell_box.obj --sampler zsobol --size 16384 16384 --shadow-samples 64",
        code: 2,
        stderr: &["zsobol", "34-bit", "32"],
    },
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "bench cornell_box.obj --sampler bluenoise --shadow-samples 16,512 --runs 1",
        code: 2,
        stderr: &["bluenoise", "512", "256"],
    },
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "variance cornell_box.obj --samplers random,bluenoise --budgets 4,1024 --out study",
        code: 2,
        stderr: &["bluenoise", "1024", "--samplers"],
    },
    FailsEarly {
        setup: &[Scene("cornell_box.obj")],
        args: "trace-pixel 1 1 cornell_box.obj --sampler pmj02 --shadow-samples 5000",
        code: 2,
        stderr: &["pmj02", "4096"],
    },
];

#[test]
fn scene_and_output_errors_fail_before_rendering_and_write_nothing() {
    for case in FAILS_EARLY {
        let dir = tempfile::tempdir().unwrap();
        let at = |name: &str| dir.path().join(name);
        for entry in case.setup {
            match *entry {
                Scene(name) => {
                    std::fs::copy(scenes().join(name), at(name)).unwrap();
                }
                File(name, text) => std::fs::write(at(name), text).unwrap(),
                Dir(name) => std::fs::create_dir(at(name)).unwrap(),
            }
        }
        let before = files_in(dir.path());
        let start = Instant::now();
        let out = raywave(dir.path(), &words(case.args));
        let args = case.args;
        // The largest cases would render for minutes: seconds mean nothing was rendered.
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "{args}: it rendered first"
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(case.code), "{args}: {err}");
        for fragment in case.stderr {
            assert!(err.contains(fragment), "{args}: no `{fragment}` in {err}");
        }
        assert!(!err.contains("panicked"), "{args}: {err}");
        // No output file, no temporary file, and what was there is untouched.
        assert_eq!(
            files_in(dir.path()),
            before,
            "{args}: a file was left behind"
        );
        for entry in case.setup {
            if let File(name, text) = *entry {
                let now = std::fs::read(at(name)).unwrap();
                assert_eq!(now, text.as_bytes(), "{args}: {name} was changed");
            }
        }
    }
}
