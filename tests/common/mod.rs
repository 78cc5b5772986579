//! Helpers shared by the integration tests (each test file that needs them declares
//! `mod common;`), one file per idea: `rays` (constructors and the edge-case table),
//! `scenes` (bare and bundled scenes, the bias tests' lights and settings), `strategies`
//! (proptest inputs), `bin` (running the binary in a scratch directory).
#![allow(dead_code, unused_imports)]

pub mod bin;
pub mod rays;
pub mod scenes;
pub mod strategies;

pub use rays::{edge_rays, ray, triangle};
pub use scenes::{PENTAGON, SQUARE, bundled_scenes, scene_of, soft_settings};

use glam::Vec3;

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
