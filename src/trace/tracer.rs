//! Traces one pixel as its render does and records every ray: the reference's recursion
//! (`crate::reference`), step for step, with the same camera rays, the same hashed random
//! numbers, the same spawn offsets and occlusion tests, so the tree is the rays both engines
//! trace for that pixel.
//!
//! ```text
//! for each aa sample s:  camera ray -> segment(path, throughput 1)
//! segment(path, β):  closest hit
//!     miss  -> contribution β ⊙ background / n_aa
//!     hit   -> contribution β ⊙ ambient ⊙ kd / n_aa
//!              for light l, point j:  shadow segment, contribution β ⊙ Shade / N / n_aa if visible
//!              mirror with bounces left -> segment(reflection, β ⊙ kr)
//! ```
//!
//! The reference nests the same terms (kr ⊙ (a + b + ...)) in f32; the contributions here are
//! distributed over the path, so their sum differs from the rendered pixel only by rounding
//! (`super::check`).

use super::tree::{
    BlockerInfo, PixelRef, PrimitiveRef, PrimitiveShape, RayTree, SCHEMA_ID, Segment, SegmentKind,
    ShadowInfo, SurfaceInfo, TraceSettings,
};
use crate::camera::CameraRays;
use crate::geometry::{Accel, Ray};
use crate::sampling::{SampleKey, square_sample};
use crate::scene::Scene;
use crate::settings::{LightModel, RenderSettings, ShadowMode};
use crate::shading::shade;
use crate::spawn::{falloff, light_end, light_offset, mirror_ray, shadow_ray, surface_hit};
use glam::Vec3;

/// Why a pixel cannot be traced.
#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    /// The pixel lies outside the image.
    #[error(
        "pixel ({x}, {y}) is outside the {width}×{height} image: expected x < {width} and y < {height}"
    )]
    OutsideImage {
        /// Column asked for.
        x: u32,
        /// Row asked for.
        y: u32,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// The tree could hold more segments than [`MAX_SEGMENTS`].
    #[error("the tree could hold up to {bound} segments ({aa} camera rays × {paths} path segments × (1 + {lights} light(s) × {points} points)): expected at most {max}; use fewer --aa, --shadow-samples or --bounces", max = MAX_SEGMENTS)]
    TooLarge {
        /// The bound on the segment count.
        bound: u64,
        /// Camera rays per pixel.
        aa: u32,
        /// Path segments per camera ray at most (bounces + 1).
        paths: u64,
        /// Lights in the scene.
        lights: usize,
        /// Points per light.
        points: u32,
    },
}

/// The most segments a tree may hold (about 400 MB of JSON): a bound on the count, from the
/// settings, is checked before tracing, so a huge request is refused instead of filling memory.
pub const MAX_SEGMENTS: u64 = 1_000_000;

/// Traces pixel (x, y) (from the top-left) of `scene` rendered with `settings` and records its
/// ray tree; errors when the pixel is outside the image.
pub fn trace_pixel(
    scene: &Scene,
    settings: &RenderSettings,
    x: u32,
    y: u32,
) -> Result<RayTree, TraceError> {
    if x >= settings.width || y >= settings.height {
        return Err(TraceError::OutsideImage {
            x,
            y,
            width: settings.width,
            height: settings.height,
        });
    }
    let aa = settings.aa_samples.max(1);
    let paths = u64::from(settings.bounces) + 1;
    let points = settings.points_per_light();
    let bound = u64::from(aa)
        .saturating_mul(paths)
        .saturating_mul(1 + scene.lights.len() as u64 * u64::from(points));
    if bound > MAX_SEGMENTS {
        return Err(TraceError::TooLarge {
            bound,
            aa,
            paths,
            lights: scene.lights.len(),
            points,
        });
    }
    let pixel = y * settings.width + x;
    let (lo, hi) = super::scene_view::scene_bounds(scene);
    let diagonal = (hi - lo).length();
    let miss_length = if diagonal.is_finite() && diagonal > 0.0 {
        diagonal
    } else {
        1.0
    };
    let mut tracer = Tracer {
        scene,
        settings,
        accel: Accel::new(scene),
        light_offsets: scene.lights.iter().map(light_offset).collect(),
        samples: settings.aa_samples.max(1),
        miss_length,
        segments: Vec::new(),
    };
    let camera = CameraRays::new(&scene.camera, settings.width, settings.height);
    for sample in 0..tracer.samples {
        let key = SampleKey {
            pixel,
            sample,
            bounce: 0,
            light: 0,
            seed: settings.seed,
        };
        let ray = camera.sample_ray(pixel, sample, tracer.samples, settings.seed);
        tracer.path(&ray, key, None, Vec3::ONE);
    }
    let mut sum = [0.0f64; 3];
    for s in &tracer.segments {
        for (acc, c) in sum.iter_mut().zip(s.contribution) {
            *acc += f64::from(c);
        }
    }
    Ok(RayTree {
        schema: SCHEMA_ID.to_string(),
        scene: scene.source.clone(),
        pixel: PixelRef { x, y, index: pixel },
        settings: trace_settings(settings),
        camera: super::tree::CameraInfo::of(&scene.camera),
        miss_length,
        segments: tracer.segments,
        sum,
        check: None,
    })
}

/// The settings as the tree reports them.
pub fn trace_settings(s: &RenderSettings) -> TraceSettings {
    TraceSettings {
        width: s.width,
        height: s.height,
        bounces: s.bounces,
        shadows: match s.shadows {
            ShadowMode::Off => "off",
            ShadowMode::Hard => "hard",
            ShadowMode::Soft => "soft",
        }
        .to_string(),
        points_per_light: s.points_per_light(),
        sampler: s.sampler.name().to_string(),
        aa_samples: s.aa_samples.max(1),
        seed: s.seed,
        two_sided: s.two_sided,
        light_model: match s.light_model {
            LightModel::Lab => "lab",
            LightModel::Rpi => "rpi",
        }
        .to_string(),
        background: s.background,
        ambient: s.ambient,
    }
}

/// The primitive behind a global id.
pub fn primitive_ref(scene: &Scene, prim: u32) -> PrimitiveRef {
    let triangles = scene.triangles.len() as u32;
    let material = scene
        .triangles
        .get(prim as usize)
        .map(|t| t.material)
        .unwrap_or_else(|| scene.spheres[(prim - triangles) as usize].material);
    match scene.triangles.get(prim as usize) {
        Some(t) => PrimitiveRef {
            id: prim,
            shape: PrimitiveShape::Triangle,
            index: prim,
            face: Some(t.face),
            material,
        },
        None => PrimitiveRef {
            id: prim,
            shape: PrimitiveShape::Sphere,
            index: prim - triangles,
            face: None,
            material,
        },
    }
}

struct Tracer<'a> {
    scene: &'a Scene,
    settings: &'a RenderSettings,
    accel: Accel,
    light_offsets: Vec<f32>,
    samples: u32,
    miss_length: f32,
    segments: Vec<Segment>,
}

impl Tracer<'_> {
    /// A camera or reflection ray with path throughput `beta`: its segment, then its hit's
    /// shadow rays, then its reflection.
    fn path(&mut self, ray: &Ray, key: SampleKey, parent: Option<u32>, beta: Vec3) {
        let (scene, settings) = (self.scene, self.settings);
        let per_sample = 1.0 / self.samples as f32;
        let hit = self
            .accel
            .closest(scene, ray, f32::INFINITY, settings.two_sided);
        let id = self.segments.len() as u32;
        let kind = if key.bounce == 0 {
            SegmentKind::Camera
        } else {
            SegmentKind::Reflection
        };
        let mut segment = Segment {
            id,
            parent,
            sample: key.sample,
            kind,
            depth: key.bounce,
            origin: ray.origin.to_array(),
            direction: ray.direction.to_array(),
            end: (ray.origin + self.miss_length * ray.direction).to_array(),
            hit: None,
            shadow: None,
            throughput: beta.to_array(),
            contribution: (beta * settings.background() * per_sample).to_array(),
        };
        if !hit.is_hit() {
            self.segments.push(segment);
            return;
        }
        let surface = surface_hit(scene, hit.prim, ray, hit.t, settings.two_sided);
        let material = *scene.material_of(hit.prim);
        segment.end = surface.point.to_array();
        segment.contribution =
            (beta * Vec3::from_array(settings.ambient) * material.diffuse * per_sample).to_array();
        segment.hit = Some(SurfaceInfo {
            primitive: primitive_ref(scene, hit.prim),
            t: hit.t,
            point: surface.point.to_array(),
            normal: surface.normal.to_array(),
            shadow_points_not_cast: 0,
        });
        self.segments.push(segment);

        // Direct light, as `Reference::direct`.
        let e = -ray.direction;
        let count = settings.points_per_light();
        let weight = 1.0 / count as f32;
        let mut not_cast = 0;
        for (li, light) in scene.lights.iter().enumerate() {
            let light_key = SampleKey {
                light: li as u32,
                ..key
            };
            let end = light_end(light, self.light_offsets[li], &surface);
            for j in 0..count {
                let (uv, target) = match settings.shadows {
                    ShadowMode::Soft => {
                        let (u, v) = square_sample(settings.sampler, &light_key, j, count);
                        (Some([u, v]), light.point(u, v))
                    }
                    _ => (None, light.centroid),
                };
                let Some(shadow) = shadow_ray(&surface, target, &end) else {
                    not_cast += 1;
                    continue;
                };
                let blocked = match settings.shadows {
                    ShadowMode::Off => None,
                    _ => Some(self.accel.occluded(
                        scene,
                        &shadow.ray,
                        shadow.tmax,
                        settings.two_sided,
                    )),
                };
                // Which primitive blocks it: the nearest hit in (0, tmax). The flag above is
                // the render's own test; this only names the blocker.
                let blocker = (blocked == Some(true))
                    .then(|| {
                        let h =
                            self.accel
                                .closest(scene, &shadow.ray, shadow.tmax, settings.two_sided);
                        h.is_hit().then(|| BlockerInfo {
                            primitive: primitive_ref(scene, h.prim),
                            t: h.t,
                            point: (shadow.ray.origin + h.t * shadow.ray.direction).to_array(),
                        })
                    })
                    .flatten();
                let contribution = if blocked == Some(true) {
                    Vec3::ZERO
                } else {
                    let light_color = light.color * falloff(settings.light_model, shadow.dist);
                    let l = shadow.ray.direction;
                    beta * (shade(&material, surface.normal, e, l, shadow.n_dot_l, light_color)
                        * weight)
                        * per_sample
                };
                let shadow_id = self.segments.len() as u32;
                self.segments.push(Segment {
                    id: shadow_id,
                    parent: Some(id),
                    sample: key.sample,
                    kind: SegmentKind::Shadow,
                    depth: key.bounce,
                    origin: shadow.ray.origin.to_array(),
                    direction: shadow.ray.direction.to_array(),
                    end: target.to_array(),
                    hit: None,
                    shadow: Some(ShadowInfo {
                        light: li as u32,
                        sample_index: j,
                        uv,
                        light_point: target.to_array(),
                        tmax: shadow.tmax,
                        blocked,
                        blocker,
                    }),
                    throughput: beta.to_array(),
                    contribution: contribution.to_array(),
                });
            }
        }
        if let Some(info) = self.segments[id as usize].hit.as_mut() {
            info.shadow_points_not_cast = not_cast;
        }

        if material.is_reflective() && key.bounce < settings.bounces {
            let next = mirror_ray(&surface, ray.direction);
            let bounced = SampleKey {
                bounce: key.bounce + 1,
                ..key
            };
            self.path(&next, bounced, Some(id), beta * material.reflective);
        }
    }
}
