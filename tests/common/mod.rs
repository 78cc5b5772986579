//! Helpers shared by the integration tests (each test file that needs them declares
//! `mod common;`).
#![allow(dead_code)]

use glam::Vec3;
use raywave::geometry::Ray;
use raywave::scene::{Scene, Triangle};

/// The triangle v0 v1 v2 (front side counter-clockwise), material 0; a degenerate one gets a
/// zero normal (the kernels never read it).
pub fn triangle(v0: Vec3, v1: Vec3, v2: Vec3) -> Triangle {
    let (e1, e2) = (v1 - v0, v2 - v0);
    Triangle {
        v0,
        e1,
        e2,
        normal: e1.cross(e2).normalize_or_zero(),
        material: 0,
        face: 0,
    }
}

/// A ray from arrays.
pub fn ray(origin: [f32; 3], direction: [f32; 3]) -> Ray {
    Ray {
        origin: Vec3::from_array(origin),
        direction: Vec3::from_array(direction),
    }
}

/// A small deterministic generator (xorshift64*), so the traversal tests need no seed plumbing.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32) / (1u64 << 24) as f32
    }
    pub fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        Vec3::new(
            lo.x + (hi.x - lo.x) * self.next(),
            lo.y + (hi.y - lo.y) * self.next(),
            lo.z + (hi.z - lo.z) * self.next(),
        )
    }
    pub fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.in_box(Vec3::splat(-1.0), Vec3::ONE);
            if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

impl Rng {
    /// A point in the cube [−half, half]³.
    pub fn point(&mut self, half: f32) -> Vec3 {
        self.in_box(Vec3::splat(-half), Vec3::splat(half))
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
