//! The debug view's test scene, scenes/trace_demo.obj, and its chosen pixel: shared by
//! tests/commands/trace_pixel.rs (the tree) and tests/commands/trace_pixel_exports.rs (OBJ, PLY,
//! PNG). Pixel (26, 32) at 64×64: the camera ray hits the mirror sphere, its reflection the red
//! wall, and the slab under the light blocks some of the wall's shadow rays.
#![allow(dead_code)]

use glam::DVec3;
use raywave::render::scene::Scene;
use raywave::render::settings::{RenderSettings, ShadowMode};
use std::path::Path;

pub const SCENE: &str = "trace_demo.obj";
pub const PIXEL: (u32, u32) = (26, 32);
pub const FLAGS: &[&str] = &[
    "--size",
    "64",
    "64",
    "--bounces",
    "2",
    "--shadow-samples",
    "16",
];

/// The scene file's numbers, written out again here (not read through the code under test).
pub mod demo {
    /// The mirror sphere: centre and radius.
    pub const SPHERE: ([f64; 3], f64) = ([0.0, 0.0, 0.0], 0.6);
    /// The slab's underside (facing down): y and its x and z ranges.
    pub const OCCLUDER_Y: f64 = 1.6;
    pub const OCCLUDER_X: (f64, f64) = (-1.4, -0.7);
    pub const OCCLUDER_Z: (f64, f64) = (0.7, 1.6);
    /// The light: y = 3, x in -0.5..0.5, z in 0..1.
    pub const LIGHT_Y: f64 = 3.0;
    /// The red wall's plane x = -2.
    pub const RED_WALL_X: f64 = -2.0;
    /// The file's camera.
    pub const EYE: [f64; 3] = [0.0, 2.5, 6.0];
    pub const FOV_DEGREES: f64 = 40.0;
}

pub fn scene() -> Scene {
    Scene::load(&crate::common::bin::scenes().join(SCENE)).unwrap()
}

pub fn settings() -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 64,
        bounces: 2,
        shadows: ShadowMode::Soft,
        shadow_samples: 16,
        ..RenderSettings::default()
    }
}

pub fn d(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0].into(), v[1].into(), v[2].into())
}

/// Runs trace-pixel on the demo pixel with `extra` flags in a scratch directory.
pub fn run(dir: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["trace-pixel", "26", "32", SCENE];
    args.extend_from_slice(FLAGS);
    args.extend_from_slice(extra);
    crate::common::bin::raywave(dir, &args)
}
