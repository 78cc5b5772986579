//! Where secondary rays start: hit points put back on their surface, and mirror and shadow rays
//! that leave it without meeting it again, at every scale.
//!
//! ```text
//! hit:     p0 = o + t·d                      (off the surface by the error of t)
//!          p  = p0 projected onto the plane, or c + r·normalize(p0 − c) on a sphere
//!          δ  = 2^-18 · (magnitude of the primitive's coordinates)  ≥ 10 × the error of p
//! mirror:  origin p ± δ·n on the side the mirror ray leaves to, t > 0
//! shadow:  l = normalize(q − p) to the light point q; cast when n·(q − p) > δ + δ_q; from
//!          x' = p + δ·n along l, blocked by a hit before the light's plane moved towards p by
//!          δ + δ_q (δ_q: the light's own offset)
//! ```
//!
//! This is pbrt-v4's scheme (`OffsetRayOrigin`, and `SpawnRayTo`'s end off the light) with a
//! simpler bound: the error of a point put back on its surface is a few ulps of the largest
//! coordinate involved, so one offset per primitive, relative to its coordinates, covers it
//! with a tenfold margin. Both ends scale with the scene, so an image does not change when the
//! scene is scaled. Ending the shadow ray at the moved plane is what lets the light's own face
//! be tested (meshes): at a grazing angle the error of where the ray crosses the light's plane
//! grows as 1/|l·n_q|, and so does the distance between that crossing and the ray's end.
//!
//! The shadow ray runs along the Shade formula's own l, so the offsets change which blockers
//! are found within δ of either end, never how a visible point is shaded, and the queue of the
//! wavefront engine keeps one direction per ray. (A first version shot the ray from x' to the
//! moved light point and kept both that segment and l: its extra columns of stores cost the
//! store-bound shadow stage 12%.)
//!
//! Rejected: a larger absolute epsilon on t (the lab's 1e-4: wrong at some scale, whichever
//! value), and carrying the id of the surface a ray leaves (exact for spheres, but a coplanar
//! neighbour, e.g. a quad's other half with two-sided faces, is still met at t ≈ 0).

use crate::render::geometry::{Ray, largest_coordinate};
use crate::render::scene::{Light, Scene, Sphere, Triangle};
use crate::render::settings::LightModel;
use crate::render::shading::reflect;
use glam::Vec3;

/// A secondary ray starts this far off its surface, relative to the magnitude of the surface's
/// coordinates: 2^-18, 64 ulps of that magnitude.
pub const OFFSET_SCALE: f32 = 1.0 / 262_144.0;

/// A hit point on its surface, ready to spawn mirror and shadow rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// The hit point, put back on the surface.
    pub point: Vec3,
    /// Unit shading normal (front side or outward; the caller flips two-sided faces).
    pub normal: Vec3,
    /// How far off the surface secondary rays start (`triangle_offset`, `sphere_offset`).
    pub offset: f32,
}

impl SurfaceHit {
    /// Where a ray leaving on the normal's side starts: `offset` off the surface.
    #[inline]
    pub fn leaving_point(&self) -> Vec3 {
        self.point + self.offset * self.normal
    }
}

/// The plane constant n·v0 of a triangle: its points p have n·p = n·v0.
#[inline]
pub fn triangle_plane(tri: &Triangle) -> f32 {
    tri.normal.dot(tri.v0)
}

/// The offset of rays leaving a triangle: `OFFSET_SCALE` × its largest coordinate.
pub fn triangle_offset(tri: &Triangle) -> f32 {
    let corners = [tri.v0, tri.v0 + tri.e1, tri.v0 + tri.e2];
    OFFSET_SCALE * corners.into_iter().fold(0.0, largest_coordinate)
}

/// The offset of rays leaving a sphere: `OFFSET_SCALE` × (|centre|∞ + radius).
#[inline]
pub fn sphere_offset(s: &Sphere) -> f32 {
    OFFSET_SCALE * (s.center.abs().max_element() + s.radius)
}

/// The hit at `p0` on a triangle with unit normal `normal`, plane constant `plane`
/// (`triangle_plane`) and `offset` (`triangle_offset`): `p0` moved along the normal onto the
/// plane.
#[inline]
pub fn triangle_hit(p0: Vec3, normal: Vec3, plane: f32, offset: f32) -> SurfaceHit {
    SurfaceHit {
        point: p0 - (normal.dot(p0) - plane) * normal,
        normal,
        offset,
    }
}

/// The hit at `p0` on a sphere: `p0` moved radially onto it, with the outward unit normal there.
#[inline]
pub fn sphere_hit(p0: Vec3, s: &Sphere) -> SurfaceHit {
    let u = (p0 - s.center).normalize();
    SurfaceHit {
        point: s.center + s.radius * u,
        normal: u,
        offset: sphere_offset(s),
    }
}

/// The hit of `ray` at distance `t` on primitive `prim`, put back on its surface, with the
/// front (triangles) or outward (spheres) normal and the offset of rays leaving it; with
/// `two_sided`, a triangle's normal is turned to face the ray.
pub fn surface_hit(scene: &Scene, prim: u32, ray: &Ray, t: f32, two_sided: bool) -> SurfaceHit {
    let p0 = ray.origin + t * ray.direction;
    match scene.triangles.get(prim as usize) {
        Some(tri) => face_the_ray(
            triangle_hit(p0, tri.normal, triangle_plane(tri), triangle_offset(tri)),
            ray.direction,
            two_sided,
        ),
        None => sphere_hit(p0, &scene.spheres[prim as usize - scene.triangles.len()]),
    }
}

/// A two-sided face's hit with its normal turned to face a ray of direction `d` (the shading
/// normal, and the side secondary rays leave to); `hit` itself when not `two_sided`.
#[inline]
pub fn face_the_ray(mut hit: SurfaceHit, d: Vec3, two_sided: bool) -> SurfaceHit {
    if two_sided && hit.normal.dot(d) > 0.0 {
        hit.normal = -hit.normal;
    }
    hit
}

/// The mirror ray of a ray with direction `d` at `hit`: d reflected about the normal, starting
/// `hit.offset` off the surface on the side it leaves to (outside a sphere hit from outside,
/// inside one hit from inside).
#[inline]
pub fn mirror_ray(hit: &SurfaceHit, d: Vec3) -> Ray {
    let direction = reflect(d, hit.normal);
    let side = if direction.dot(hit.normal) >= 0.0 {
        hit.offset
    } else {
        -hit.offset
    };
    Ray {
        origin: hit.point + side * hit.normal,
        direction,
    }
}

/// The offset of shadow rays' ends on a light: `OFFSET_SCALE` × its largest corner coordinate.
pub fn light_offset(light: &Light) -> f32 {
    OFFSET_SCALE * light.corners().into_iter().fold(0.0, largest_coordinate)
}

/// Where shadow rays from one hit to one light end: where they meet the light's plane moved
/// towards the hit by the two offsets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightEnd {
    /// tmax / |target − point|: the ray from the offset origin along l meets the moved plane at
    /// height(origin) / cos, and cos = h / |target − point| for every point of the light's
    /// plane (h: the hit point's height above it), so one ratio per (hit, light) serves all
    /// its points. ≤ 0 when the hit is not above the moved plane (no ray is cast).
    pub ratio: f32,
    /// The two offsets added: a point must be this far above the tangent plane.
    pub margin: f32,
}

/// The end of shadow rays from `hit` to `light` (whose `light_offset` is `end_offset`): the
/// light's plane moved towards the hit by `end_offset + hit.offset`. (Moving it by both
/// offsets makes every ray end before its light point, whatever the angle between the
/// surface and the light: `shadow_ray`.)
#[inline]
pub fn light_end(light: &Light, end_offset: f32, hit: &SurfaceHit) -> LightEnd {
    // The hit's height above the light's plane, h, and the light's normal turned to face it
    // (negating the normal negates the product exactly, so h = |that product|).
    let side = light.normal.dot(hit.point - light.centroid);
    let (normal, h) = if side >= 0.0 {
        (light.normal, side)
    } else {
        (-light.normal, -side)
    };
    let margin = end_offset + hit.offset;
    let height = normal.dot(hit.leaving_point() - light.centroid) - margin;
    // A hit on the light's plane (h = ±0) casts no ray to it: ratio 0, never +∞ from −0.0.
    LightEnd {
        ratio: if h > 0.0 { height / h } else { 0.0 },
        margin,
    }
}

/// A shadow ray and what shading needs of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowRay {
    /// From `hit.offset` off the surface, along l.
    pub ray: Ray,
    /// Blocked by a hit with t in (0, tmax): where the ray meets the light's moved plane.
    pub tmax: f32,
    /// |target − point|, for the light model's fall-off.
    pub dist: f32,
    /// n·l.
    pub n_dot_l: f32,
}

/// The shadow ray from `hit` to the light point `target` (`end` from `light_end`), or `None`
/// when the point is not above the tangent plane by more than the two offsets (for a light's
/// own points, and coplanar lights, n·l is 0 up to rounding: a rounding-positive n·l would add
/// a speckle) or the ray's origin is not above the light's moved plane.
///
/// l = normalize(target − point) is the Shade formula's, from the hit point itself; the ray runs
/// along it from `hit.offset` off the surface and ends at the light's moved plane (the module
/// doc says why the light and faces coplanar with it then never block their own points).
/// Written once, for every engine: the lane twin is `wavefront::simd::shadow_rays`.
#[inline]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x > y)` is on purpose: NaN casts no ray
pub fn shadow_ray(hit: &SurfaceHit, target: Vec3, end: &LightEnd) -> Option<ShadowRay> {
    let to_light = target - hit.point;
    if !(hit.normal.dot(to_light) > end.margin) {
        return None;
    }
    let dist = to_light.length();
    let l = to_light / dist;
    let tmax = dist * end.ratio;
    if !(tmax > 0.0) {
        return None;
    }
    Some(ShadowRay {
        ray: Ray {
            origin: hit.leaving_point(),
            direction: l,
        },
        tmax,
        dist,
        n_dot_l: hit.normal.dot(l),
    })
}

/// The factor on a light's colour Lc = 0.2·ke·area for a light point at distance `dist`: 1 in
/// the lab's model; in RPI's, whose light colour is ke·area/(π·d²) (its `raytracer.cpp` has no
/// 0.2), 1/(0.2·π·d²).
#[inline]
pub fn falloff(model: LightModel, dist: f32) -> f32 {
    match model {
        LightModel::Lab => 1.0,
        LightModel::Rpi => 1.0 / (0.2 * std::f32::consts::PI * dist * dist),
    }
}
