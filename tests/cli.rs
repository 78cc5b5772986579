//! The command line: the lab's three run lines verbatim, the no-argument run, usage errors
//! (exit 2), scene errors (exit 1, file:line, no output left behind) and output checks that
//! happen before the render.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

fn raywave(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raywave"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run raywave")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A temp dir holding copies of the given scenes.
fn dir_with(names: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in names {
        std::fs::copy(scenes().join(name), dir.path().join(name)).unwrap();
    }
    dir
}

/// Only the files a test expects: no `render.png`, no leftover temporary files.
fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn check_lab_image(dir: &Path, size: (u32, u32)) -> image::RgbImage {
    let img = image::open(dir.join("render.png"))
        .expect("render.png is a readable image")
        .to_rgb8();
    assert_eq!(img.dimensions(), size);
    img
}

/// -background_color 0.2 0.1 0.6 in 8 bits, clamped, no gamma: round(255 · c).
const LAB_BACKGROUND: [u8; 3] = [51, 26, 153];

#[test]
fn lab_run_line_1() {
    let dir = dir_with(&["reflective_spheres.obj"]);
    let line = "-size 200 200 -input reflective_spheres.obj -background_color 0.2 0.1 0.6";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (200, 200));
    // The top-left corner looks over the floor and spheres into the background.
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
}

#[test]
fn lab_run_line_2() {
    let dir = dir_with(&["reflective_spheres.obj"]);
    let line = "-size 200 200 -input reflective_spheres.obj -background_color 0.2 0.1 0.6 -num_shadow_samples 10";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (200, 200));
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
    // The summary says the shadows are soft with 10 points.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("soft") && stdout.contains("10"), "{stdout}");
}

#[test]
fn lab_run_line_3() {
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let line = "-size 200 200 -input cornell_box_reflective_spheres.obj -soft_shadow -background_color 0.2 0.1 0.6 -num_bounces 5";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (200, 200));
    // The box spans less than the field of view: the corners are background.
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
    assert_eq!(img.get_pixel(199, 199).0, LAB_BACKGROUND);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("soft") && stdout.contains("5 bounces"),
        "{stdout}"
    );
}

#[test]
fn lab_run_line_3_matches_the_no_argument_render_at_the_same_size() {
    // The built-in scene is the lab's third scene with its background: rendering it with no
    // scene argument must give the same image as the lab's run line (both soft, 16 points,
    // 5 bounces).
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let line = "-size 64 64 -input cornell_box_reflective_spheres.obj -soft_shadow -background_color 0.2 0.1 0.6 -num_bounces 5 -o lab.png";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let out = raywave(dir.path(), &["--size", "64", "64", "-o", "builtin.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let a = image::open(dir.path().join("lab.png")).unwrap().to_rgb8();
    let b = image::open(dir.path().join("builtin.png"))
        .unwrap()
        .to_rgb8();
    assert!(
        a == b,
        "the built-in default differs from the lab's third run line"
    );
}

#[test]
fn no_argument_run_writes_render_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(dir.path(), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (512, 512));
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
    assert_eq!(files_in(dir.path()), ["render.png"]);
}

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
fn bad_scene_exits_1_with_file_line_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let text = "material\ndiffuse 1 1 1\nm 0\nv 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n";
    std::fs::write(dir.path().join("bad.obj"), text).unwrap();
    let out = raywave(dir.path(), &["bad.obj", "--size", "8", "8"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("bad.obj:6:"), "{err}");
    assert!(err.contains("zero"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        files_in(dir.path()),
        ["bad.obj"],
        "an output file was left behind"
    );

    // With the lab's spelling and -o too.
    let out = raywave(dir.path(), &["-input", "bad.obj", "-o", "out.png"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(files_in(dir.path()), ["bad.obj"]);

    // An existing output file is left untouched.
    std::fs::write(dir.path().join("render.png"), b"precious").unwrap();
    let out = raywave(dir.path(), &["bad.obj", "--size", "8", "8"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        std::fs::read(dir.path().join("render.png")).unwrap(),
        b"precious"
    );
    assert_eq!(files_in(dir.path()), ["bad.obj", "render.png"]);
}

#[test]
fn missing_scene_file_exits_1_and_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(dir.path(), &["nothere.obj", "--size", "8", "8"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("nothere.obj"), "{}", stderr(&out));
    assert!(files_in(dir.path()).is_empty());
    // A directory instead of a file: not an empty scene.
    std::fs::create_dir(dir.path().join("sub.obj")).unwrap();
    let out = raywave(dir.path(), &["sub.obj", "--size", "8", "8"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(files_in(dir.path()), ["sub.obj"]);
}

#[test]
fn nonexistent_output_directory_fails_before_rendering() {
    // A 16384² soft-shadowed render would take many minutes: failing within seconds shows the
    // check happens first.
    let dir = dir_with(&["cornell_box.obj"]);
    let start = Instant::now();
    let out = raywave(
        dir.path(),
        &[
            "cornell_box.obj",
            "--size",
            "16384",
            "16384",
            "--shadows",
            "soft",
            "-o",
            "no/such/dir/out.png",
        ],
    );
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "it rendered first"
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("no/such/dir"), "{}", stderr(&out));
    assert_eq!(files_in(dir.path()), ["cornell_box.obj"]);
    // The same for --hdr.
    let out = raywave(
        dir.path(),
        &[
            "cornell_box.obj",
            "--size",
            "16384",
            "16384",
            "--hdr",
            "no/such/dir/out.pfm",
        ],
    );
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "it rendered first"
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(files_in(dir.path()), ["cornell_box.obj"]);
}

#[test]
fn output_path_that_is_a_directory_fails_before_rendering() {
    let dir = dir_with(&["cornell_box.obj"]);
    std::fs::create_dir(dir.path().join("d.png")).unwrap();
    let start = Instant::now();
    let out = raywave(
        dir.path(),
        &[
            "cornell_box.obj",
            "--size",
            "16384",
            "16384",
            "--shadows",
            "soft",
            "-o",
            "d.png",
        ],
    );
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "it rendered first"
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("d.png"), "{}", stderr(&out));
    assert_eq!(files_in(dir.path()), ["cornell_box.obj", "d.png"]);
}

#[test]
fn bad_output_extension_fails_before_rendering() {
    let dir = dir_with(&["cornell_box.obj"]);
    let out = raywave(
        dir.path(),
        &[
            "cornell_box.obj",
            "--size",
            "16384",
            "16384",
            "-o",
            "out.jpg",
        ],
    );
    // A flag value raywave cannot use is a usage error, like clap's own: exit 2.
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("out.jpg"));
    assert_eq!(files_in(dir.path()), ["cornell_box.obj"]);
}

#[test]
fn scene_warnings_name_file_and_line_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let text = "material\ndiffuse 1 1 1\nm 0\nfrob 1\ns 0 0 0 1\n";
    std::fs::write(dir.path().join("w.obj"), text).unwrap();
    let out = raywave(dir.path(), &["w.obj", "--size", "8", "8", "-o", "w.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("w.obj:4:"), "{}", stderr(&out));
    assert!(dir.path().join("w.png").exists());
}

#[test]
fn hdr_output_is_written_with_the_image() {
    let dir = dir_with(&["cornell_box.obj"]);
    let out = raywave(
        dir.path(),
        &[
            "cornell_box.obj",
            "--size",
            "6",
            "4",
            "-o",
            "a.png",
            "--hdr",
            "a.pfm",
            "--quiet",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let pfm = std::fs::read(dir.path().join("a.pfm")).unwrap();
    let header = b"PF\n6 4\n-1.0\n";
    assert_eq!(&pfm[..header.len()], header);
    assert_eq!(pfm.len(), header.len() + 6 * 4 * 3 * 4);
    assert_eq!(files_in(dir.path()), ["a.pfm", "a.png", "cornell_box.obj"]);
}
