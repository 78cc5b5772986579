//! Records one pixel's ray tree while the reference renderer traces it: `trace_pixel` runs
//! `Reference::pixel` with a recorder as its `TraceLog`, so the tree's rays, hits, light points,
//! occlusion outcomes and colour terms are the render's own. The recorder adds what the
//! recursion does not keep: each segment's throughput and contribution, the tree's order, and
//! which primitive blocks a blocked shadow ray.
//!
//! ```text
//! the recursion reports, for each aa sample (one camera ray):
//!     P0, P1, ..., Pk (hits, the last maybe a miss), shadow rays of Pk, ..., of P1, of P0
//! the recorder keeps that chain (one path segment per depth, with its shadow segments) and
//! writes it in tree order when the sample ends:  P0, its shadow rays, P1, its shadow rays, ...
//! throughput β: 1 for the camera ray, β ⊙ kr of the hit before for a mirror ray
//! contribution, divided by the aa samples n_aa:
//!     miss       β ⊙ background                   (what the ray returns)
//!     hit        β ⊙ (ambient ⊙ kd)               (the hit's own term)
//!     shadow     β ⊙ Shade / N, 0 if blocked      (what it adds to the hit)
//! blocker of a blocked shadow ray: the nearest hit in (0, tmax), looked up here, not in the
//! render; whether it is blocked is the render's own occlusion test
//! ```
//!
//! The reference nests the same terms (kr ⊙ (a + b + ...)) in f32; the contributions here are
//! distributed over the path, so their sum differs from the rendered pixel only by rounding
//! (`super::check`).

use super::tree::{
    BlockerInfo, PixelRef, PrimitiveRef, PrimitiveShape, RayTree, SCHEMA_ID, Segment, SegmentKind,
    ShadowInfo, SurfaceInfo, TextureLookup, TraceSettings,
};
use crate::render::geometry::{Accel, Hit, Ray};
use crate::render::per_kind::RayCounts;
use crate::render::reference::{LightPoint, Reference, TraceLog};
use crate::render::sampling::SampleKey;
use crate::render::scene::{Material, Scene};
use crate::render::settings::RenderSettings;
use crate::render::spawn::{ShadowRay, SurfaceHit};
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
    /// The tree could hold more segments than `MAX_SEGMENTS`.
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
const MAX_SEGMENTS: u64 = 1_000_000;

/// The most segments one pixel's tree can have: per camera sample, a camera or mirror ray at
/// each depth, each followed by its shadow rays.
pub(crate) fn max_segments(scene: &Scene, settings: &RenderSettings) -> u64 {
    u64::from(settings.aa_samples.max(1))
        .saturating_mul(u64::from(settings.bounces) + 1)
        .saturating_mul(1 + scene.lights.len() as u64 * u64::from(settings.points_per_light()))
}

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
    let bound = max_segments(scene, settings);
    if bound > MAX_SEGMENTS {
        return Err(TraceError::TooLarge {
            bound,
            aa,
            paths: u64::from(settings.bounces) + 1,
            lights: scene.lights.len(),
            points: settings.points_per_light(),
        });
    }
    let pixel = y * settings.width + x;
    let (lo, hi) = super::mesh::scene_bounds(scene);
    let diagonal = (hi - lo).length();
    let miss_length = Some(diagonal)
        .filter(|d| d.is_finite() && *d > 0.0)
        .unwrap_or(1.0);
    let reference = Reference::new(scene, settings);
    let mut recorder = Recorder {
        scene,
        accel: reference.accel(),
        two_sided: settings.two_sided,
        per_sample: 1.0 / aa as f32,
        miss_length,
        chain: Vec::new(),
        segments: Vec::new(),
    };
    reference.pixel(pixel, &mut RayCounts::default(), &mut recorder);
    let segments = recorder.finish();
    let sum = super::check::contribution_sum(&segments);
    Ok(RayTree {
        schema: SCHEMA_ID.to_string(),
        scene: scene.source.clone(),
        pixel: PixelRef { x, y, index: pixel },
        settings: TraceSettings {
            width: settings.width,
            height: settings.height,
            bounces: settings.bounces,
            shadows: settings.shadows.name().to_string(),
            points_per_light: settings.points_per_light(),
            sampler: settings.sampler.name().to_string(),
            aa_samples: aa,
            seed: settings.seed,
            two_sided: settings.two_sided,
            light_model: settings.light_model.name().to_string(),
            background: settings.background,
            ambient: settings.ambient,
        },
        camera: super::tree::CameraInfo::of(&scene.camera),
        miss_length,
        segments,
        sum,
        check: None,
    })
}

/// The primitive behind a global id.
pub fn primitive_ref(scene: &Scene, prim: u32) -> PrimitiveRef {
    let (shape, index, face, material) = match scene.triangles.get(prim as usize) {
        Some(t) => (PrimitiveShape::Triangle, prim, Some(t.face), t.material),
        None => {
            let index = prim - scene.triangles.len() as u32;
            let material = scene.spheres[index as usize].material;
            (PrimitiveShape::Sphere, index, None, material)
        }
    };
    PrimitiveRef {
        id: prim,
        shape,
        index,
        face,
        material,
    }
}

/// Builds the tree from the reference's `TraceLog` calls for one pixel.
struct Recorder<'a> {
    scene: &'a Scene,
    /// The reference's own acceleration structure: names blockers.
    accel: &'a Accel,
    two_sided: bool,
    /// 1 / the aa samples.
    per_sample: f32,
    miss_length: f32,
    /// The current aa sample's path segments so far, by depth.
    chain: Vec<PathRecord>,
    /// The finished samples' segments, in tree order.
    segments: Vec<Segment>,
}

/// A camera or reflection segment of the current sample, and the shadow rays of its hit.
struct PathRecord {
    /// Its `id` and `parent` are set when the sample is written.
    segment: Segment,
    shadows: Vec<Segment>,
    /// kr of its hit (zero for a miss): a mirror ray from it has throughput β ⊙ kr.
    reflective: Vec3,
}

impl Recorder<'_> {
    /// Starts the path segment for `ray` at `key.bounce`: the previous sample is written when
    /// a camera ray starts a new one. Its end and contribution are those of a miss.
    fn path(&mut self, key: &SampleKey, ray: &Ray, background: Vec3) -> &mut PathRecord {
        let kind = if key.bounce == 0 {
            self.write_sample();
            SegmentKind::Camera
        } else {
            SegmentKind::Reflection
        };
        debug_assert_eq!(
            self.chain.len(),
            key.bounce as usize,
            "one path segment per depth"
        );
        let beta = match self.chain.last() {
            Some(before) => Vec3::from_array(before.segment.throughput) * before.reflective,
            None => Vec3::ONE,
        };
        self.chain.push(PathRecord {
            segment: Segment {
                id: 0,
                parent: None,
                sample: key.sample,
                kind,
                depth: key.bounce,
                origin: ray.origin.to_array(),
                direction: ray.direction.to_array(),
                end: (ray.origin + self.miss_length * ray.direction).to_array(),
                hit: None,
                shadow: None,
                throughput: beta.to_array(),
                contribution: (beta * background * self.per_sample).to_array(),
            },
            shadows: Vec::new(),
            reflective: Vec3::ZERO,
        });
        self.chain.last_mut().expect("just pushed")
    }

    /// Writes the current sample's chain in tree order: each path segment, then its shadow
    /// segments; each path segment's parent is the one before it.
    fn write_sample(&mut self) {
        let mut parent = None;
        for record in self.chain.drain(..) {
            let id = self.segments.len() as u32;
            self.segments.push(Segment {
                id,
                parent,
                ..record.segment
            });
            for shadow in record.shadows {
                let shadow_id = self.segments.len() as u32;
                self.segments.push(Segment {
                    id: shadow_id,
                    parent: Some(id),
                    ..shadow
                });
            }
            parent = Some(id);
        }
    }

    /// Every segment, in tree order.
    fn finish(mut self) -> Vec<Segment> {
        self.write_sample();
        self.segments
    }

    /// The path segment of the hit whose light loop runs at `key.bounce`.
    fn at(&mut self, key: &SampleKey) -> &mut PathRecord {
        &mut self.chain[key.bounce as usize]
    }
}

impl TraceLog for Recorder<'_> {
    fn path_miss(&mut self, key: &SampleKey, ray: &Ray, background: Vec3) {
        self.path(key, ray, background);
    }

    fn path_hit(
        &mut self,
        key: &SampleKey,
        ray: &Ray,
        hit: &Hit,
        surface: &SurfaceHit,
        material: &Material,
        ambient: Vec3,
    ) {
        let primitive = primitive_ref(self.scene, hit.prim);
        let texture = material.texture.map(|k| TextureLookup {
            name: self.scene.textures[k as usize].name.clone(),
            st: self.scene.texture_coords(hit.prim, surface.point),
        });
        let per_sample = self.per_sample;
        let record = self.path(key, ray, Vec3::ZERO);
        let beta = Vec3::from_array(record.segment.throughput);
        record.reflective = material.reflective;
        record.segment.end = surface.point.to_array();
        record.segment.contribution = (beta * ambient * per_sample).to_array();
        record.segment.hit = Some(SurfaceInfo {
            primitive,
            t: hit.t,
            point: surface.point.to_array(),
            normal: surface.normal.to_array(),
            shadow_points_not_cast: 0,
            diffuse: material.diffuse.to_array(),
            texture,
        });
    }

    fn no_shadow_ray(&mut self, key: &SampleKey, _target: &LightPoint) {
        if let Some(info) = self.at(key).segment.hit.as_mut() {
            info.shadow_points_not_cast += 1;
        }
    }

    fn shadow_ray(
        &mut self,
        key: &SampleKey,
        target: &LightPoint,
        shadow: &ShadowRay,
        blocked: Option<bool>,
        term: Vec3,
    ) {
        let beta = Vec3::from_array(self.at(key).segment.throughput);
        // Which primitive blocks it: the nearest hit in (0, tmax). `blocked` is the render's
        // own test; this only names the blocker.
        let (blocker, contribution) = if blocked == Some(true) {
            let h = self
                .accel
                .closest(self.scene, &shadow.ray, shadow.tmax, self.two_sided);
            let blocker = h.is_hit().then(|| BlockerInfo {
                primitive: primitive_ref(self.scene, h.prim),
                t: h.t,
                point: (shadow.ray.origin + h.t * shadow.ray.direction).to_array(),
            });
            (blocker, Vec3::ZERO)
        } else {
            (None, beta * term * self.per_sample)
        };
        self.at(key).shadows.push(Segment {
            id: 0,
            parent: None,
            sample: key.sample,
            kind: SegmentKind::Shadow,
            depth: key.bounce,
            origin: shadow.ray.origin.to_array(),
            direction: shadow.ray.direction.to_array(),
            end: target.point.to_array(),
            hit: None,
            shadow: Some(ShadowInfo {
                light: target.light,
                sample_index: target.index,
                uv: target.uv,
                light_point: target.point.to_array(),
                tmax: shadow.tmax,
                blocked,
                blocker,
            }),
            throughput: beta.to_array(),
            contribution: contribution.to_array(),
        });
    }
}
