//! The penumbra mask: where light sampling's noise comes from shadow edges.
//!
//! For every pixel, follow its camera ray and mirror bounces exactly as `trace` does, and at
//! each hit estimate every light's visibility with a dense stratified grid: the fraction of the
//! light's points that face the hit (n·l > 0) and are unoccluded. A pixel is
//! - **penumbra** if any hit on its path sees some light partly (0 < fraction < 1);
//! - **lit** if every hit on its path sees every light fully (fraction = 1);
//! - neither (umbra, lights seen edge-on, the background) otherwise.

use crate::render::camera::CameraRays;
use crate::render::geometry::Accel;
use crate::render::sampling::{LightSampler, PointSet, SampleKey};
use crate::render::scene::Scene;
use crate::render::settings::RenderSettings;
use crate::render::spawn::{light_end, light_offset, mirror_ray, shadow_ray, surface_hit};
use rayon::prelude::*;

/// Per-pixel region membership.
#[derive(Clone, Debug, PartialEq)]
pub struct Regions {
    /// Some light partly visible somewhere on the pixel's path.
    pub penumbra: Vec<bool>,
    /// Every light fully visible everywhere on the pixel's path.
    pub lit: Vec<bool>,
}

impl Regions {
    /// Every pixel.
    pub fn whole(&self) -> Vec<bool> {
        vec![true; self.penumbra.len()]
    }
}

/// Computes the regions with `points` stratified points per light per hit (a square number
/// such as 1024 keeps every stratum a square).
pub fn penumbra_mask(scene: &Scene, settings: &RenderSettings, points: u32) -> Regions {
    let accel = Accel::new(scene);
    // `spawn::light_offset` of every light, once, as the renderers keep them.
    let end_offsets: Vec<f32> = scene.lights.iter().map(light_offset).collect();
    let camera = CameraRays::new(&scene.camera, settings.width, settings.height);
    let pixels = settings.width * settings.height;
    // Per pixel: (penumbra, lit).
    let classify = |pixel: u32| {
        let (x, y) = camera.screen(pixel, 0.5, 0.5);
        let mut ray = camera.ray(x, y);
        let mut penumbra = false;
        let mut lit = true;
        let mut any_hit = false;
        for bounce in 0..=settings.bounces {
            let hit = accel.closest(scene, &ray, f32::INFINITY, settings.two_sided);
            if !hit.is_hit() {
                break;
            }
            any_hit = true;
            let surface = surface_hit(scene, hit.prim, &ray, hit.t, settings.two_sided);
            for (li, light) in scene.lights.iter().enumerate() {
                let key = SampleKey {
                    pixel,
                    sample: 0,
                    bounce,
                    light: li as u32,
                    seed: 0x6d61_736b,
                };
                let end = light_end(light, end_offsets[li], &surface);
                let set = PointSet::of(LightSampler::Stratified, points);
                let visible = (0..points)
                    .filter(|&j| {
                        let (u, v) = set.point(&key, j);
                        // Spawned as the renderers spawn it: no ray below the tangent plane.
                        let shadow = shadow_ray(&surface, light.point(u, v), &end);
                        shadow.is_some_and(|s| {
                            !accel.occluded(scene, &s.ray, s.tmax, settings.two_sided)
                        })
                    })
                    .count() as u32;
                penumbra |= visible > 0 && visible < points;
                lit &= visible == points;
            }
            if !scene.material_of(hit.prim).is_reflective() {
                break;
            }
            ray = mirror_ray(&surface, ray.direction);
        }
        // Without lights nothing is lit (every light fully visible would be vacuously true).
        (penumbra, lit && any_hit && !scene.lights.is_empty())
    };
    let (penumbra, lit) = (0..pixels).into_par_iter().map(classify).unzip();
    Regions { penumbra, lit }
}
