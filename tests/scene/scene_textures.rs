//! RPI's textures in the scene file: `vt` gives the vertex just read its coordinates, a face's
//! triangles carry its corners' coordinates, `texture_file` is read relative to the scene file's
//! folder, and every bad texture is an error naming the scene's line (or, where RPI would go on,
//! a warning).

use glam::Vec3;
use raywave::render::scene::{Scene, SceneError, load_scene};
use std::path::Path;

/// A textured quad (corners with `vt`) and a textured face without, over `texture` (a
/// `texture_file` name) in `dir`, written as `scene.obj`; the path of the file.
fn scene_file(dir: &Path, texture: &str, extra: &str) -> std::path::PathBuf {
    let text = format!(
        "material\ntexture_file {texture}\n{extra}\
v 0 0 0\nvt 0 0\nv 1 0 0\nvt 1 0\nv 1 1 0\nvt 1 1\nv 0 1 0\nvt 0 1\n\
v 0 0 1\nv 1 0 1\nv 1 1 1\n\
m 0\nf 1 2 3 4\nf 5 6 7\n"
    );
    let path = dir.join("scene.obj");
    std::fs::write(&path, text).unwrap();
    path
}

fn write_ppm(path: &Path, bytes: &[u8]) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, bytes).unwrap();
}

/// A 2 × 1 P3: red then blue.
const RED_BLUE: &[u8] = b"P3\n2 1\n255\n255 0 0 0 0 255\n";

fn load(path: &Path) -> Result<Scene, SceneError> {
    load_scene(Some(path), &Default::default()).map(|f| f.scene)
}

#[test]
fn vt_gives_the_last_vertex_its_coordinates_and_faces_their_corners() {
    let dir = tempfile::tempdir().unwrap();
    write_ppm(&dir.path().join("rb.ppm"), RED_BLUE);
    let scene = load(&scene_file(dir.path(), "rb.ppm", "")).unwrap();
    // The quad a b c d splits into (a, b, c) and (a, c, d); the triangle without vt gets zeros.
    assert_eq!(
        scene.texcoords,
        vec![
            [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
            [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            [[0.0, 0.0]; 3],
        ]
    );
    let texture = &scene.textures[0];
    assert_eq!((texture.width, texture.height), (2, 1));
    assert_eq!(
        texture.path,
        dir.path().canonicalize().unwrap().join("rb.ppm")
    );
    // kd: the texture's average stands for it; diffuse_at looks the texel up.
    assert_eq!(scene.materials[0].texture, Some(0));
    assert_eq!(scene.materials[0].diffuse, Vec3::new(0.5, 0.0, 0.5));
    // RPI's bilinear weights: texel 0 at s = 0, texel 1 at s = 1/2, a blend between.
    assert_eq!(scene.diffuse_at(0, Vec3::ZERO), Vec3::X);
    assert_eq!(scene.diffuse_at(0, Vec3::new(0.5, 0.0, 0.0)), Vec3::Z);
    let between = scene.diffuse_at(0, Vec3::new(0.125, 0.0, 0.0));
    assert!(
        between.distance(Vec3::new(0.75, 0.0, 0.25)) < 1e-6,
        "{between}"
    );
    // The face without coordinates is warned about once, naming its line.
    let warnings: Vec<String> = scene.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("scene.obj:16:") && warnings[0].contains("(0, 0)"),
        "{warnings:?}"
    );
}

#[test]
fn textures_are_read_from_the_scene_files_folder() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    write_ppm(&scenes.join("textures/rb.ppm"), RED_BLUE);
    let scene = load(&scene_file(&scenes, "textures/rb.ppm", "")).unwrap();
    assert!(!scene.textures[0].outside_folder);
    // Climbing out through `..` is allowed, and marked so the summary can show where it led.
    write_ppm(&dir.path().join("shared.ppm"), RED_BLUE);
    let scene = load(&scene_file(&scenes, "../shared.ppm", "")).unwrap();
    assert!(scene.textures[0].outside_folder);
    assert_eq!(
        scene.textures[0].path,
        dir.path().canonicalize().unwrap().join("shared.ppm")
    );
}

#[test]
fn a_file_named_twice_is_read_once() {
    let dir = tempfile::tempdir().unwrap();
    write_ppm(&dir.path().join("rb.ppm"), RED_BLUE);
    let scene = load(&scene_file(
        dir.path(),
        "rb.ppm",
        "material\ntexture_file ./rb.ppm\n",
    ))
    .unwrap();
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(scene.materials[1].texture, Some(0));
}

/// The error of loading the scene with texture `name` written as `bytes` (none: missing).
fn texture_error(name: &str, bytes: Option<&[u8]>) -> String {
    let dir = tempfile::tempdir().unwrap();
    if let Some(bytes) = bytes {
        write_ppm(&dir.path().join(name), bytes);
    }
    let e = load(&scene_file(dir.path(), name, ""))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scene.obj:2: "),
        "not at the texture_file line: {e}"
    );
    assert!(
        e.contains(name) && e.contains("expected") || e.contains("cannot read"),
        "{e}"
    );
    e
}

#[test]
fn bad_textures_are_errors_at_their_line() {
    assert!(texture_error("missing.ppm", None).contains("cannot read"));
    assert!(texture_error("grey.ppm", Some(b"P5\n1 1\n255\n\x00")).contains("found a PGM"));
    assert!(texture_error("photo.ppm", Some(b"\xff\xd8\xff\xe0")).contains("P3` or `P6"));
    assert!(texture_error("short.ppm", Some(b"P6\n4 4\n255\n\x00")).contains("truncated"));
    assert!(texture_error("short3.ppm", Some(b"P3\n2 2\n255\n1 2 3\n")).contains("truncated"));
    assert!(texture_error("empty.ppm", Some(b"P6\n0 0\n255\n")).contains("1×1"));
    let huge = texture_error("huge.ppm", Some(b"P6\n65536 65536\n255\n"));
    assert!(huge.contains("refused before reading"), "{huge}");
}

#[test]
fn a_directory_or_fifo_is_refused_without_reading() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("folder.ppm")).unwrap();
    let e = load(&scene_file(dir.path(), "folder.ppm", ""))
        .unwrap_err()
        .to_string();
    assert!(e.contains("found a directory"), "{e}");
    let fifo = dir.path().join("pipe.ppm");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        // Opening a FIFO for reading would block until a writer came: it must not be opened.
        let e = load(&scene_file(dir.path(), "pipe.ppm", ""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("special file"), "{e}");
    }
}

#[test]
fn bad_texture_coordinates_are_errors_at_their_line() {
    use crate::common::scenes::{WHITE_MATERIAL as MAT, error_at};
    error_at("material\nvt 0 0\n", 2, &["before any vertex"]);
    error_at(
        &format!("{MAT}v 0 0 0\nvt nan 0\n"),
        7,
        &["s coordinate", "finite"],
    );
    error_at(
        &format!("{MAT}v 0 0 0\nvt 0 inf\n"),
        7,
        &["t coordinate", "finite"],
    );
    error_at(&format!("{MAT}v 0 0 0\nvt 0 1 2 3\n"), 7, &["extra `3`"]);
    error_at("material\ntexture_file\n", 2, &["file name"]);
    error_at(
        "material\ntexture_file a.ppm b.ppm\n",
        2,
        &["extra `b.ppm`"],
    );
}

#[test]
fn the_bytes_caches_key_on_change_with_the_texture() {
    let dir = tempfile::tempdir().unwrap();
    write_ppm(&dir.path().join("rb.ppm"), RED_BLUE);
    let path = scene_file(dir.path(), "rb.ppm", "");
    let first = load_scene(Some(&path), &Default::default()).unwrap().bytes;
    let text = std::fs::read(&path).unwrap();
    assert!(first.starts_with(&text) && first.len() > text.len());
    // The same scene file over another texture: what the variance cache and bench records
    // key on must change.
    write_ppm(
        &dir.path().join("rb.ppm"),
        b"P3\n2 1\n255\n255 0 0 0 0 254\n",
    );
    let second = load_scene(Some(&path), &Default::default()).unwrap().bytes;
    assert_ne!(first, second);
}
