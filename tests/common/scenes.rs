//! Scenes and settings shared by the tests: bare scenes from primitives, the bundled scenes,
//! the bias tests' light shapes and soft-shadow settings.

use raywave::render::scene::{Material, Scene, Sphere, Triangle, parse_scene_str};

/// A white diffuse material block, every key spelled out, for scene texts built in tests.
pub const WHITE_MATERIAL: &str =
    "material\ndiffuse 1 1 1\nreflective 0 0 0\nemitted 0 0 0\nglossiness 0\n";

/// Parses `text` as `f.obj`, which must fail at `line` with an error whose text starts with
/// `f.obj:LINE:`, says what was expected and mentions every needle; returns that text.
pub fn error_at(text: &str, line: usize, needles: &[&str]) -> String {
    let err = match parse_scene_str(text, "f.obj") {
        Ok(_) => panic!("expected an error at line {line}, parsed fine:\n{text}"),
        Err(e) => e,
    };
    assert_eq!(err.file, "f.obj");
    assert_eq!(err.line, line, "wrong line in `{err}` for:\n{text}");
    let msg = err.to_string();
    assert!(
        msg.starts_with(&format!("f.obj:{line}: ")),
        "`{msg}` does not start with f.obj:{line}:"
    );
    assert!(
        msg.contains("expected"),
        "`{msg}` does not say what was expected"
    );
    for needle in needles {
        assert!(msg.contains(needle), "`{msg}` does not mention `{needle}`");
    }
    msg
}

/// A scene of just these primitives, with one default material.
pub fn scene_of(triangles: Vec<Triangle>, spheres: Vec<Sphere>) -> Scene {
    Scene {
        triangles,
        spheres,
        materials: vec![Material::default()],
        ..Scene::default()
    }
}

/// Every bundled `scenes/*.obj`, by file name, in name order (a scene added there is covered).
pub fn bundled_scenes() -> Vec<(String, Scene)> {
    let scenes = scenes_in("scenes");
    assert!(
        scenes.len() >= 5,
        "expected the lab's scenes, found {:?}",
        scenes.iter().map(|(n, _)| n).collect::<Vec<_>>()
    );
    scenes
}

/// RPI's own scenes, `scenes/rpi/*.obj` (its textured ones), by file name, in name order.
pub fn rpi_scenes() -> Vec<(String, Scene)> {
    let scenes = scenes_in("scenes/rpi");
    assert!(!scenes.is_empty(), "expected RPI's scenes in scenes/rpi");
    scenes
}

/// The `.obj` files of the repository's folder `dir`, parsed, by file name in name order.
fn scenes_in(dir: &str) -> Vec<(String, Scene)> {
    let dir = std::path::Path::new(env!("RAYWAVE_REPO")).join(dir);
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, Scene::load(p).expect("bundled scene parses"))
        })
        .collect()
}

/// A square light's corners (x, z), counter-clockwise seen from below.
pub const SQUARE: &[(f64, f64)] = &[(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)];
/// The square with its (0.5, 0.5) corner cut along x + z = 0.7: a convex pentagon, sampled by
/// the fan.
pub const PENTAGON: &[(f64, f64)] = &[
    (-0.5, -0.5),
    (0.5, -0.5),
    (0.5, 0.2),
    (0.2, 0.5),
    (-0.5, 0.5),
];

/// A `size`² image with soft shadows from `n` points of `sampler`, no bounces, seed `seed`.
pub fn soft_settings(
    size: u32,
    sampler: raywave::render::sampling::LightSampler,
    n: u32,
    seed: u32,
) -> raywave::render::settings::RenderSettings {
    raywave::render::settings::RenderSettings {
        width: size,
        height: size,
        bounces: 0,
        shadows: raywave::render::settings::ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        seed,
        ..raywave::render::settings::RenderSettings::default()
    }
}
