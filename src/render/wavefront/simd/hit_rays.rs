//! One shadow ray per hit, N hits at a time (8 or 16): hard shadows, whose single ray per
//! (hit, light) would leave N − 1 lanes of a per-hit block idle, spawned across the hits of a
//! batch instead. Lane k is the scalar spawn of hit k: `spawn::light_end` then
//! `spawn::shadow_ray`, the same operations in the same order.

use crate::render::scene::Light;
use crate::render::wavefront::batch::{HitBatch, HitRays};
use crate::render::wavefront::lanes::Lanes;
use glam::Vec3;

/// N hits of a batch, lane k = hit `i0 + k`: what spawning a shadow ray reads of each.
#[derive(Clone, Copy)]
pub struct HitLanes<V> {
    /// The hit points, on their surfaces.
    pub point: [V; 3],
    /// The unit shading normals.
    pub normal: [V; 3],
    /// How far off the surface secondary rays start.
    pub offset: V,
}

impl<V: Lanes> HitLanes<V> {
    /// Hits `i0..i0 + N` of `hits`, the lanes past its end padded with zeros (the caller masks
    /// them, and the hits that missed, out of what the rays' `live` says).
    #[inline(always)]
    pub fn load(hits: &HitBatch, i0: usize) -> HitLanes<V> {
        let col = |c: &[f32]| V::load(c, i0, 0.0);
        HitLanes {
            point: [col(&hits.point.x), col(&hits.point.y), col(&hits.point.z)],
            normal: [
                col(&hits.normal.x),
                col(&hits.normal.y),
                col(&hits.normal.z),
            ],
            offset: col(&hits.offset),
        }
    }
}

/// Shadow rays from N hits to `target` on `light` (whose `spawn::light_offset` is
/// `end_offset`): lane k equals `spawn::shadow_ray(hit_k, target, &spawn::light_end(light,
/// end_offset, hit_k))`, bit for bit, where that is `Some`; `live` is clear where it is `None`.
#[inline(always)]
pub fn hit_shadow_rays<V: Lanes>(
    hits: &HitLanes<V>,
    light: &Light,
    end_offset: f32,
    target: Vec3,
) -> HitRays<V::Array> {
    let [px, py, pz] = hits.point;
    let [nx, ny, nz] = hits.normal;
    let splat = V::splat;
    let (c, ln) = (light.centroid, light.normal);
    // light_end: the hit's height h above the light's plane, with the plane's normal turned to
    // face the hit. (−n)·v is −(n·v) exactly, so turning the normal is a select of signs.
    let side = splat(ln.x) * (px - splat(c.x))
        + splat(ln.y) * (py - splat(c.y))
        + splat(ln.z) * (pz - splat(c.z));
    let facing = side.simd_ge(V::ZERO);
    let h = facing.select(side, -side);
    let margin = splat(end_offset) + hits.offset;
    let leaving = [
        px + hits.offset * nx,
        py + hits.offset * ny,
        pz + hits.offset * nz,
    ];
    let d = splat(ln.x) * (leaving[0] - splat(c.x))
        + splat(ln.y) * (leaving[1] - splat(c.y))
        + splat(ln.z) * (leaving[2] - splat(c.z));
    let height = facing.select(d, -d) - margin;
    let ratio = h.simd_gt(V::ZERO).select(height / h, V::ZERO);
    // shadow_ray: above the tangent plane by the margin, and a positive tmax.
    let (tx, ty, tz) = (
        splat(target.x) - px,
        splat(target.y) - py,
        splat(target.z) - pz,
    );
    let above = nx * tx + ny * ty + nz * tz;
    let dist = (tx * tx + ty * ty + tz * tz).sqrt();
    let (lx, ly, lz) = (tx / dist, ty / dist, tz / dist);
    let tmax = dist * ratio;
    let live = above.simd_gt(margin) & tmax.simd_gt(V::ZERO);
    HitRays {
        origin: leaving.map(V::to_array),
        l: [lx.to_array(), ly.to_array(), lz.to_array()],
        tmax: tmax.to_array(),
        n_dot_l: (nx * lx + ny * ly + nz * lz).to_array(),
        dist: dist.to_array(),
        live: live.to_bitmask(),
    }
}
