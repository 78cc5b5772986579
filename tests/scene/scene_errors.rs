//! Scene errors: every parse error names `file:line` and says what was expected; a file that
//! cannot be read is an error naming it, never an empty scene.

use crate::common;

use common::scenes::{WHITE_MATERIAL as MAT, error_at};
use raywave::render::scene::{Scene, SceneError, parse_scene_str};
use std::path::Path;

#[test]
fn missing_file_is_an_error_naming_it() {
    let path = Path::new("/nonexistent-dir/f.obj");
    match Scene::load(path) {
        Err(SceneError::Io { .. }) => {}
        other => panic!("expected an I/O error, got {other:?}"),
    }
    let msg = Scene::load(path).unwrap_err().to_string();
    assert!(msg.contains("/nonexistent-dir/f.obj"), "{msg}");
}

#[test]
fn unreadable_file_is_an_error_not_an_empty_scene() {
    // A directory cannot be read as text; invalid UTF-8 cannot be read either.
    let dir = tempfile::tempdir().unwrap();
    let e = Scene::load(dir.path()).unwrap_err().to_string();
    assert!(e.contains(&dir.path().display().to_string()), "{e}");
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, b"v 0 0 0\n\xff\xfe\n").unwrap();
    let e = Scene::load(&bad).unwrap_err().to_string();
    assert!(e.contains("bad.obj"), "{e}");
}

#[test]
fn bad_number_names_the_line() {
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 0 1.5x 0\nf 1 2 3\n");
    error_at(&text, 9, &["1.5x"]);
    let text = format!("{MAT}m 0\nv 0 0\nf 1 2 3\n");
    error_at(&text, 7, &["end of the line"]);
    let text = "material\ndiffuse 1 one 1\n";
    error_at(text, 2, &["one"]);
    let text = format!("{MAT}m 0\ns 0 0 0 r\n");
    error_at(&text, 7, &["`r`"]);
    let text = format!("{MAT}m 0\nv 0 0 0 7\n");
    error_at(&text, 7, &["7"]);
}

#[test]
fn vertex_index_out_of_range_names_the_line() {
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    error_at(&text, 10, &["4"]);
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n");
    error_at(&text, 10, &["0"]);
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 -2 -1\n");
    error_at(&text, 10, &["-4"]);
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
    error_at(&text, 10, &["x"]);
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nf 1 2\n");
    error_at(&text, 9, &["3"]);
}

#[test]
fn face_or_sphere_before_any_material_names_the_line() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    error_at(text, 4, &["m "]);
    let text = format!("{MAT}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    error_at(&text, 9, &["material"]);
    let text = format!("{MAT}s 0 0 0 1\n");
    error_at(&text, 6, &["material"]);
    // `diffuse` outside any material block.
    error_at("diffuse 1 1 1\n", 1, &["material"]);
}

#[test]
fn material_index_out_of_range_names_the_m_line() {
    let text = format!("{MAT}{MAT}v 0 0 0\nv 1 0 0\nv 0 1 0\nm 2\nf 1 2 3\n");
    error_at(&text, 14, &["2"]);
    let text = format!("{MAT}m -1\ns 0 0 0 1\n");
    error_at(&text, 6, &["-1"]);
    // No material at all, then `m 0`.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nm 0\nf 1 2 3\n";
    error_at(text, 4, &["0"]);
}

#[test]
fn material_declared_later_is_accepted() {
    // Geometry is assembled at the end, so `m 1` may name a material declared further down.
    let text = format!("{MAT}m 1\ns 0 0 0 1\n{MAT}");
    let scene = parse_scene_str(&text, "f.obj").unwrap();
    assert_eq!(scene.spheres[0].material, 1);
}

#[test]
fn nan_and_infinity_name_the_line() {
    for bad in ["nan", "NaN", "inf", "-inf", "infinity", "1e39"] {
        let text = format!("{MAT}m 0\nv 0 {bad} 0\n");
        error_at(&text, 7, &[bad]);
        let text = format!("{MAT}m 0\ns 0 0 0 {bad}\n");
        error_at(&text, 7, &[bad]);
        let text = format!("material\nemitted 1 {bad} 1\n");
        error_at(&text, 2, &[bad]);
        let text = format!("material\nglossiness {bad}\n");
        error_at(&text, 2, &[bad]);
    }
}

#[test]
fn non_positive_radius_names_the_line() {
    let text = format!("{MAT}m 0\ns 0 0 0 0\n");
    error_at(&text, 7, &["radius"]);
    let text = format!("{MAT}m 0\ns 0 0 0 -0.5\n");
    error_at(&text, 7, &["radius", "-0.5"]);
    let text = format!("{MAT}m 0\ns 0 0 0 -0\n");
    error_at(&text, 7, &["radius"]);
}

#[test]
fn degenerate_face_names_the_line() {
    // Collinear corners.
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    error_at(&text, 10, &["degenerate"]);
    // A repeated corner.
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n");
    error_at(&text, 10, &["degenerate"]);
    // A quad whose four corners lie on one line.
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 1 1\nv 2 2 2\nv 3 3 3\nf 1 2 3 4\n");
    error_at(&text, 11, &["degenerate"]);
}

#[test]
fn camera_block_errors_name_the_line() {
    let body = format!("{MAT}m 0\ns 0 0 0 1\n");
    // Unclosed: names the line the block starts on.
    let text = format!("{body}PerspectiveCamera {{\n camera_position 0 0 5\n angle 30\n");
    error_at(&text, 8, &["}"]);
    // An unknown key names its own line.
    let text = format!(
        "{body}PerspectiveCamera {{\n camera_position 0 0 5\n point_of_interest 0 0 0\n zoom 2\n angle 30\n}}\n"
    );
    error_at(&text, 11, &["zoom"]);
    // A bad number inside the block.
    let text = format!(
        "{body}PerspectiveCamera {{\n camera_position 0 zero 5\n point_of_interest 0 0 0\n angle 30\n}}\n"
    );
    error_at(&text, 9, &["zero"]);
    // A missing key names the block.
    let text = format!("{body}PerspectiveCamera {{\n camera_position 0 0 5\n angle 30\n}}\n");
    error_at(&text, 8, &["point_of_interest"]);
    // Infinite position.
    let text = format!(
        "{body}PerspectiveCamera {{\n camera_position 0 0 inf\n point_of_interest 0 0 0\n angle 30\n}}\n"
    );
    error_at(&text, 9, &["inf"]);
}

#[test]
fn numbers_too_large_to_square_are_errors() {
    // 1e38 is a finite f32, but its square is not: it used to come out as a "degenerate" face
    // or an infinite light.
    let box_ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nm 0\nf 1 2 3 4\n";
    error_at(
        &format!("{MAT}v 1e38 0 0\n{box_}"),
        6,
        &["1st number of `v`", "at most 1e9", "`1e38`"],
    );
    error_at(
        "material\ndiffuse 1 1 1\nemitted 2e9 2e9 2e9\n",
        3,
        &["`emitted`", "at most 1e9", "`2e9`"],
    );
    // The limit itself is accepted.
    let ok = format!("material\ndiffuse 1 1 1\nemitted 1e9 1e9 1e9\nv -1e9 0 0\n{box_}");
    let scene = parse_scene_str(&ok, "f.obj").unwrap();
    assert!(scene.lights[0].color.is_finite());
}

#[test]
fn numbers_past_f32_get_the_magnitude_message_and_infinities_do_not() {
    // 1e39 is finite, only too large for an f32, which Rust's parser rounds it to infinity:
    // it is past the parser's 1e9 like 1e10, and called that, not "not a finite number".
    let body = format!("{MAT}m 0\ns 0 0 0 1\n");
    let camera = |position: &str| {
        format!(
            "{body}PerspectiveCamera {{\n camera_position 0 {position} 5\n point_of_interest 0 0 0\n angle 30\n}}\n"
        )
    };
    let box_ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nm 0\nf 1 2 3 4\n";
    for big in ["1e39", "-1e39", "1e400", "+3.5e38"] {
        let found = format!("found `{big}`");
        let magnitude = |what: &str| {
            [
                what.to_string(),
                "of magnitude at most 1e9".into(),
                found.clone(),
            ]
        };
        let cases: [(String, usize, [String; 3]); 6] = [
            (
                format!("{MAT}v 0 {big} 0\n{box_}"),
                6,
                magnitude("2nd number of `v`"),
            ),
            (
                format!("material\ndiffuse {big} 1 1\n"),
                2,
                magnitude("1st number of `diffuse`"),
            ),
            (
                format!("material\nemitted 1 1 {big}\n"),
                2,
                magnitude("3rd number of `emitted`"),
            ),
            (camera(big), 9, magnitude("2nd number of `camera_position`")),
            (
                format!("{MAT}m 0\ns 0 0 0 {big}\n"),
                7,
                magnitude("the radius of `s`"),
            ),
            (
                format!("{body}background_color {big} 0 0\n"),
                8,
                magnitude("`background_color`"),
            ),
        ];
        for (text, line, needles) in &cases {
            let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
            let msg = error_at(text, *line, &needles);
            assert!(!msg.contains("finite"), "{msg}");
        }
    }
    // What is spelled infinite or not a number is still called that.
    for bad in ["inf", "-inf", "+Infinity", "NaN", "-nan"] {
        let found = format!("found `{bad}`");
        for (text, line) in [
            (format!("{MAT}v 0 {bad} 0\n"), 6),
            (format!("material\ndiffuse {bad} 1 1\n"), 2),
            (camera(bad), 9),
            (format!("{MAT}m 0\ns 0 0 0 {bad}\n"), 7),
        ] {
            let msg = error_at(&text, line, &["(a finite number)", &found]);
            assert!(!msg.contains("magnitude"), "{msg}");
        }
    }
}

#[test]
fn errors_after_a_continuation_name_a_line_of_the_logical_line() {
    // Lines 7-8 form one logical line; the bad number is on line 8 physically. Accept either
    // line of the logical line, but never a later one.
    let text = format!("{MAT}m 0\nv 0 \\\n  bad 0\n");
    let err = parse_scene_str(&text, "f.obj").unwrap_err();
    assert!(err.line == 7 || err.line == 8, "{err}");
    // The line count continues correctly after a continuation.
    let text = format!("{MAT}m 0\nv 0 \\\n  0 0\nv 1 0 0\nv 0 1 zz\n");
    error_at(&text, 10, &["zz"]);
}

#[test]
fn an_empty_scene_is_an_error() {
    let err = parse_scene_str("# nothing\n", "f.obj").unwrap_err();
    assert!(err.to_string().starts_with("f.obj:"), "{err}");
}

#[test]
fn negative_colours_and_glossiness_name_the_line() {
    error_at("material\ndiffuse 1 -0.5 1\n", 2, &["-0.5"]);
    error_at("material\nemitted -1 0 0\n", 2, &["-1"]);
    error_at("material\nglossiness -0.1\n", 2, &["-0.1"]);
    error_at("material\nroughness -2\n", 2, &["-2"]);
    let text = format!("{MAT}m 0\ns 0 0 0 1\nbackground_color 0 -1 0\n");
    error_at(&text, 8, &["-1"]);
}

#[test]
fn a_non_utf8_byte_is_an_error_naming_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.obj");
    std::fs::write(&path, b"material\ndiffuse 1 1 1\n# caf\xe9\nv 0 0 0\n").unwrap();
    let err = raywave::render::scene::Scene::load(&path)
        .unwrap_err()
        .to_string();
    assert!(err.contains("latin1.obj:3:"), "{err}");
    assert!(err.contains("expected UTF-8"), "{err}");
}
