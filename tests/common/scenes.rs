//! Scenes and settings shared by the tests: bare scenes from primitives, the bundled scenes,
//! the bias tests' light shapes and soft-shadow settings.

use raywave::scene::{Material, Scene, Sphere, Triangle};

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
    let mut paths: Vec<_> = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes"))
        .expect("scenes/ exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    assert!(
        paths.len() >= 5,
        "expected the lab's scenes, found {paths:?}"
    );
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
    sampler: raywave::sampling::LightSampler,
    n: u32,
    seed: u32,
) -> raywave::settings::RenderSettings {
    raywave::settings::RenderSettings {
        width: size,
        height: size,
        bounces: 0,
        shadows: raywave::settings::ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        seed,
        ..raywave::settings::RenderSettings::default()
    }
}
