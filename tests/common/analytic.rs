//! The closed-form penumbra scene shared by the sampling study and the oracle's bias test.
//!
//! A floor at y = 0 (facing up), a light at y = 2 over x, z ∈ [−0.5, 0.5] (facing down; a
//! square, or any convex polygon inside it) and a blocker at y = 1 covering the half-plane
//! x + z < 0 (facing down, so shadow rays meet its front). A shadow ray from floor point (x, z)
//! to light point (lx, lz) crosses y = 1 at ((x + lx)/2, (z + lz)/2), so it is blocked exactly
//! when lx + lz < −(x + z). With s = x + z and the square light, the floor is fully lit for
//! s > 1, in umbra for s < −1 and in penumbra between. The edge runs diagonally so that both
//! light coordinates matter: a sampler biased in either one moves the mean. A camera 10 above
//! the origin looks straight down (screen up = −z) with a 1.5 half-width at the floor, so
//! pixels map to floor points in closed form (`floor_point`).

use glam::DVec3;
use raywave::render::sampling::LightSampler;
use raywave::render::scene::{Scene, parse_scene_str};
use raywave::render::settings::RenderSettings;

/// Image size.
pub const SIZE: u32 = 64;
/// The light's ke: Lc = 0.2 · 10 · area.
pub const KE: f64 = 10.0;
/// The floor's kd.
pub const KD: f64 = 0.5;

/// The scene with a light whose corners (x, z) are `light`, counter-clockwise seen from below
/// (`super::SQUARE`, `super::PENTAGON`).
pub fn scene(light: &[(f64, f64)]) -> Scene {
    let mut text = format!(
        "PerspectiveCamera {{
           camera_position 0 10 0
           point_of_interest 0 0 0
           up 0 0 -1
           angle {}
         }}
         material
         emitted {KE} {KE} {KE}
         material
         diffuse {KD} {KD} {KD}
         material
         diffuse 0.5 0.5 0.5
         v -3 0 -3
         v -3 0 3
         v 3 0 3
         v 3 0 -3
         m 1
         f 1 2 3 4
         v -10 1 -10
         v 10 1 -10
         v -10 1 10
         m 2
         f 5 6 7
         m 0
        ",
        2.0 * 0.15f64.atan()
    );
    for (x, z) in light {
        text += &format!("v {x} 2 {z}\n");
    }
    text += "f";
    for k in 0..light.len() {
        text += &format!(" {}", 8 + k);
    }
    parse_scene_str(&text, "analytic.obj").expect("analytic scene parses")
}

/// The floor point seen through the centre of pixel (column, row from the top).
pub fn floor_point(column: u32, row: u32) -> DVec3 {
    let x = (2.0 * (column as f64 + 0.5) / SIZE as f64 - 1.0) * 1.5;
    let j = SIZE - 1 - row; // counted from the bottom
    let z = -(2.0 * (j as f64 + 0.5) / SIZE as f64 - 1.0) * 1.5;
    DVec3::new(x, 0.0, z)
}

/// Soft shadows with `n` points of `sampler`, no bounces, at `SIZE`².
pub fn settings(sampler: LightSampler, n: u32, seed: u32) -> RenderSettings {
    super::soft_settings(SIZE, sampler, n, seed)
}
