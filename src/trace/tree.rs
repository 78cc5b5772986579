//! The ray tree of one pixel as plain serde types: what `raywave trace-pixel --json` writes and
//! what the browser viewer reads. docs/TRACE.md describes every field; the JSON Schema generated
//! from these types is checked in as `docs/schema/ray-tree.schema.json`.
//!
//! Coordinates are world space in the scene file's units (the frame of its `v` and `s` lines);
//! colours are linear RGB, the render's own values before tone mapping. Vectors are `[x, y, z]`.

use crate::render::per_kind::RayCounts;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The `schema` value of every tree this build writes; the suffix changes when a field changes
/// meaning or goes away (new fields may appear without it changing).
pub const SCHEMA_ID: &str = "raywave.ray-tree/1";

/// Every ray the render traces for one pixel, with what each one adds to the pixel's colour.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct RayTree {
    /// Always `raywave.ray-tree/1` in this version: which layout this is.
    pub schema: String,
    /// Where the scene came from (a path, `<stdin>` or `<built-in ...>`).
    pub scene: String,
    /// The traced pixel.
    pub pixel: PixelRef,
    /// The settings the pixel was traced (and rendered) with.
    pub settings: TraceSettings,
    /// The camera of the render.
    pub camera: CameraInfo,
    /// How long a ray that hits nothing is drawn (scene units): the diagonal of the scene's
    /// bounding box. Such segments end this far along their direction.
    pub miss_length: f32,
    /// Every segment, in tree order: each camera ray, then the shadow rays of its hit, then its
    /// reflection with the reflection's shadow rays, and so on; `parent` links them.
    pub segments: Vec<Segment>,
    /// The sum of every segment's `contribution` (summed in f64): the pixel's colour.
    pub sum: [f64; 3],
    /// The sum compared with the pixel as each engine renders it (absent when not checked;
    /// `raywave trace-pixel` always checks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub check: Option<PixelCheck>,
}

/// A pixel of the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct PixelRef {
    /// Column, from the left (0-based).
    pub x: u32,
    /// Row, from the top (0-based).
    pub y: u32,
    /// Row-major index y·width + x: the `pixel` of every random number it draws.
    pub index: u32,
}

/// The render settings that decide the pixel, as plain values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TraceSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Maximum mirror bounces after the camera hit.
    pub bounces: u32,
    /// `off` (no shadow rays, every light point counts as visible), `hard` (one ray to each
    /// light's centroid) or `soft` (`points_per_light` rays to each light).
    pub shadows: String,
    /// Shadow rays per light per hit (1 unless soft).
    pub points_per_light: u32,
    /// How soft-shadow points are placed: `random`, `stratified`, `sobol` or `lab`.
    pub sampler: String,
    /// Camera rays (antialiasing samples) per pixel.
    pub aa_samples: u32,
    /// The seed of every random number.
    pub seed: u32,
    /// Faces hit from behind too.
    pub two_sided: bool,
    /// `lab` (no fall-off) or `rpi` (divided by π·d²).
    pub light_model: String,
    /// Colour of rays that hit nothing.
    pub background: [f32; 3],
    /// Ambient light: every hit adds ambient ⊙ kd.
    pub ambient: [f32; 3],
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CameraInfo {
    /// Eye position.
    pub position: [f32; 3],
    /// The point looked at.
    pub look_at: [f32; 3],
    /// The up hint (the scene's up axis).
    pub up: [f32; 3],
    /// Full field of view of the square image, in degrees.
    pub fov_degrees: f32,
}

impl CameraInfo {
    /// The scene camera as plain values.
    pub fn of(camera: &crate::render::scene::Camera) -> CameraInfo {
        CameraInfo {
            position: camera.position.to_array(),
            look_at: camera.point_of_interest.to_array(),
            up: camera.up.to_array(),
            fov_degrees: camera.fov.to_degrees(),
        }
    }
}

/// What a segment is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum SegmentKind {
    /// From the eye through the pixel (depth 0).
    Camera,
    /// A mirror ray from a reflective hit (depth ≥ 1).
    Reflection,
    /// From a hit towards a point on a light.
    Shadow,
}

/// One ray of the tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Segment {
    /// Its index in `RayTree::segments`.
    pub id: u32,
    /// The segment whose hit spawned it (a reflection's or shadow ray's path segment); none for
    /// camera rays.
    pub parent: Option<u32>,
    /// The antialiasing sample it belongs to.
    pub sample: u32,
    /// Camera, reflection or shadow.
    pub kind: SegmentKind,
    /// Path depth: 0 for the camera ray and the shadow rays of its hit, k after k reflections.
    pub depth: u32,
    /// Where the ray starts (for secondary rays: just off the surface it leaves).
    pub origin: [f32; 3],
    /// Unit direction.
    pub direction: [f32; 3],
    /// Where it is drawn to: the hit point, the light point (shadow rays), or `miss_length`
    /// along the direction for a ray that hits nothing.
    pub end: [f32; 3],
    /// What a camera or reflection ray hit (none for a miss and for shadow rays).
    pub hit: Option<SurfaceInfo>,
    /// The shadow test (shadow rays only).
    pub shadow: Option<ShadowInfo>,
    /// The product of the mirror colours kr along the path before this segment's hit: what its
    /// light is multiplied by on the way to the eye.
    pub throughput: [f32; 3],
    /// The linear colour this segment adds to the pixel, already divided by the antialiasing
    /// samples: for a hit, throughput ⊙ ambient ⊙ kd; for a miss, throughput ⊙ background; for
    /// a visible shadow ray, throughput ⊙ Shade / N; zero for a blocked one.
    pub contribution: [f32; 3],
}

/// A primitive of the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct PrimitiveRef {
    /// Global primitive id: triangles first (`0..triangles`), then spheres.
    pub id: u32,
    /// `triangle` or `sphere`.
    pub shape: PrimitiveShape,
    /// Index among the primitives of its shape (triangle k, sphere k).
    pub index: u32,
    /// The file's face (0-based, in file order) a triangle came from; none for spheres.
    pub face: Option<u32>,
    /// Index of its material in the file's declaration order.
    pub material: u32,
}

/// The two kinds of primitive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum PrimitiveShape {
    /// A triangle (faces are split into triangles).
    Triangle,
    /// An analytic sphere.
    Sphere,
}

/// Where a camera or reflection ray hit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SurfaceInfo {
    /// What was hit.
    pub primitive: PrimitiveRef,
    /// Distance along the ray.
    pub t: f32,
    /// The hit point, put back on the surface.
    pub point: [f32; 3],
    /// Unit shading normal (front side of a face, outward on a sphere; towards the ray with
    /// two-sided faces).
    pub normal: [f32; 3],
    /// Light points that were below this hit's tangent plane (or on the light's own plane): no
    /// shadow ray is cast to them and they add nothing.
    pub shadow_points_not_cast: u32,
    /// The diffuse colour kd used here (linear): the material's, or on a textured material the
    /// texel colour at `texture`'s coordinates.
    pub diffuse: [f32; 3],
    /// Where a textured material was looked up; none for a material without a texture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<TextureLookup>,
}

/// The texture lookup at a hit on a textured material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TextureLookup {
    /// The texture's name as the scene file gives it.
    pub name: String,
    /// The texture coordinates (s, t) at the hit, interpolated from its triangle's corners
    /// ((0, 0) off a triangle with coordinates).
    pub st: [f32; 2],
}

/// A shadow ray's light point and outcome.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ShadowInfo {
    /// Index of the light (emissive faces in file order).
    pub light: u32,
    /// Which of the light's points this is (0..points_per_light).
    pub sample_index: u32,
    /// The point's (u, v) on the light's square; none for hard shadows and shadows off (the
    /// centroid).
    pub uv: Option<[f32; 2]>,
    /// The point on the light the ray aims at.
    pub light_point: [f32; 3],
    /// The ray tests (0, tmax): it ends just before the light's plane.
    pub tmax: f32,
    /// True when something blocks it; none when shadows are off (no test, the point counts as
    /// visible).
    pub blocked: Option<bool>,
    /// The nearest primitive in (0, tmax) when blocked.
    pub blocker: Option<BlockerInfo>,
}

/// What blocks a shadow ray.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BlockerInfo {
    /// The nearest blocking primitive.
    pub primitive: PrimitiveRef,
    /// Distance along the shadow ray.
    pub t: f32,
    /// Where the shadow ray meets it.
    pub point: [f32; 3],
}

/// The tree's sum against the pixel each engine renders.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PixelCheck {
    /// The sum of the contributions.
    pub sum: [f64; 3],
    /// The pixel as the reference renderer computes it.
    pub reference: [f32; 3],
    /// The pixel as the wavefront engine computes it.
    pub wavefront: [f32; 3],
    /// Largest |sum − reference| over the channels.
    pub reference_difference: f64,
    /// Largest |sum − wavefront| over the channels.
    pub wavefront_difference: f64,
    /// The largest difference accepted: rounding of the f32 sums the engines do in another
    /// order: 1e-5 × max(1, the pixel's largest channel).
    pub tolerance: f64,
    /// Both differences within the tolerance, and the tree's rays counted as each engine
    /// counts the rays it traces for the pixel.
    pub agrees: bool,
    /// Rays by kind: the tree's (shadow rays: those tested for occlusion) and each engine's
    /// own count for the pixel.
    #[serde(default)]
    pub rays: RayCountCheck,
}

/// Rays by kind, as the tree holds them and as each engine counts them for the pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct RayCountCheck {
    /// The tree's segments (shadow segments only where the occlusion test ran).
    pub tree: RayCounts,
    /// The reference's counters for the pixel.
    pub reference: RayCounts,
    /// The wavefront engine's counters for the pixel.
    pub wavefront: RayCounts,
}
