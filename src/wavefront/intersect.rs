//! Stage 2, intersect: the closest hit of every ray, then what shading needs at it (point,
//! normal flipped for two-sided faces, material).
//!
//! Small scenes (below `BVH_MIN_TRIANGLES` triangles) go through the 8-wide kernel over every
//! primitive; meshes go through the engine's 8-wide BVH (`bvh::MeshBvh`), one ray at a time
//! with 8 child boxes or 8 triangles per test. Its hits are brute force's (same t bits, ties to
//! the lowest triangle id), as are the reference's (`Accel::closest` over obvhs's CWBVH), except
//! for the few axis-parallel rays obvhs's box test misses (docs/PERFORMANCE.md, "Mesh rays").

use super::batch::{HitBatch, RayBatch};
use super::context::Context;
use super::simd::{self, RayColumns};
use crate::geometry::geometric_normal;
use crate::scene::NO_HIT;

/// The ray columns of a batch.
pub fn columns(rays: &RayBatch) -> RayColumns<'_> {
    RayColumns {
        origin: [&rays.origin_x, &rays.origin_y, &rays.origin_z],
        direction: [&rays.direction_x, &rays.direction_y, &rays.direction_z],
        tmax: &rays.tmax,
    }
}

/// Fills `hits` (same indices as `rays`).
pub fn closest(ctx: &Context, rays: &RayBatch, hits: &mut HitBatch) {
    let n = rays.len();
    hits.resize(n);
    let scene = ctx.scene;
    let two_sided = ctx.settings.two_sided;
    match &ctx.accel {
        None => simd::closest_hits(
            &scene.triangles,
            &scene.spheres,
            &columns(rays),
            two_sided,
            &mut hits.t,
            &mut hits.prim,
        ),
        Some(bvh) => bvh.closest_hits(
            scene,
            &columns(rays),
            two_sided,
            &mut hits.t[..n],
            &mut hits.prim[..n],
        ),
    }
    for i in 0..n {
        let prim = hits.prim[i];
        if prim == NO_HIT {
            continue;
        }
        let d = rays.direction(i);
        let point = rays.origin(i) + hits.t[i] * d;
        let mut normal = geometric_normal(scene, prim, point);
        if two_sided && (prim as usize) < scene.triangles.len() && normal.dot(d) > 0.0 {
            normal = -normal;
        }
        hits.point_x[i] = point.x;
        hits.point_y[i] = point.y;
        hits.point_z[i] = point.z;
        hits.normal_x[i] = normal.x;
        hits.normal_y[i] = normal.y;
        hits.normal_z[i] = normal.z;
        hits.material[i] = ctx.material_index(prim);
    }
}
