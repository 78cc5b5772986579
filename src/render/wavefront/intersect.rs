//! Stage 2, intersect: the closest hit of every ray, then what shading needs at it (point put
//! back on its surface, normal flipped for two-sided faces, offset, material).
//!
//! Small scenes (below `BVH_MIN_TRIANGLES` triangles) go through the brute-force kernel over
//! every primitive, 8 or 16 rays at a time (the engine's lane width); meshes go through the
//! engine's 8-wide BVH (`bvh::MeshBvh`) at either width: camera rays in packets of 8
//! neighbouring pixels, all other rays one at a time ([`mesh_hits`]). Its hits are
//! brute force's (same t bits, ties to the lowest triangle id), as are the reference's
//! (`Accel::closest` over obvhs's CWBVH), except for the few axis-parallel rays obvhs's box
//! test misses (docs/ARCHITECTURE.md, "The mesh path").

use super::batch::{HitBatch, RayBatch};
use super::bvh::MeshBvh;
use super::context::Context;
use super::cost::{Costs, Counter};
use super::lanes::at_width;
use super::simd::{self, RayColumns};
use super::texels;
use crate::render::scene::{NO_HIT, Scene};
use crate::render::spawn::face_the_ray;
use glam::Vec3;

/// The ray columns of a batch.
pub fn columns(rays: &RayBatch) -> RayColumns<'_> {
    RayColumns {
        origin: [&rays.origin.x, &rays.origin.y, &rays.origin.z],
        direction: [&rays.direction.x, &rays.direction.y, &rays.direction.z],
        tmax: &rays.tmax,
    }
}

/// t and primitive id of every ray's closest hit through the mesh BVH, each ray's traversal
/// work added to `costs`: camera rays (depth 0: 8 consecutive rays are neighbouring pixels) 8
/// at a time, mirror rays, which fan out, one at a time (docs/TRIED.md, "The mesh BVH").
pub fn mesh_hits<S: Costs>(
    bvh: &MeshBvh,
    scene: &Scene,
    rays: &RayBatch,
    two_sided: bool,
    t: &mut [f32],
    prim: &mut [u32],
    costs: &mut S,
) {
    if rays.bounce == 0 {
        bvh.closest_hits_coherent(scene, &columns(rays), two_sided, t, prim, costs);
    } else {
        bvh.closest_hits(scene, &columns(rays), two_sided, t, prim, costs);
    }
}

/// Fills `hits` (same indices as `rays`), each ray's traversal work added to `costs` (by ray
/// index; `cost::NoCount` counts nothing). Without a BVH every ray is charged every primitive:
/// the brute-force kernel tests them all, so it is not instrumented.
pub fn closest<S: Costs>(ctx: &Context, rays: &RayBatch, hits: &mut HitBatch, costs: &mut S) {
    let n = rays.len();
    hits.resize(n);
    let scene = ctx.scene;
    let two_sided = ctx.settings.two_sided;
    match &ctx.accel {
        None => {
            at_width!(ctx.lane_width, V => simd::closest_hits::<V>(
                &scene.triangles,
                &scene.spheres,
                &columns(rays),
                two_sided,
                &mut hits.t,
                &mut hits.prim,
            ));
            let mut every = S::Counter::default();
            every.tests((scene.triangles.len() + scene.spheres.len()) as u32);
            for i in 0..n {
                costs.add(i, every);
            }
        }
        Some(bvh) => mesh_hits(
            bvh,
            scene,
            rays,
            two_sided,
            &mut hits.t[..n],
            &mut hits.prim[..n],
            costs,
        ),
    }
    // Every column cut to n first, so that the loop's indexing needs no bounds checks.
    let [ox, oy, oz] = rays.origin.slices(0..n);
    let [dx, dy, dz] = rays.direction.slices(0..n);
    let (t, prims) = (&hits.t[..n], &hits.prim[..n]);
    let [px, py, pz] = hits.point.slices_mut(0..n);
    let [nx, ny, nz] = hits.normal.slices_mut(0..n);
    let offset = &mut hits.offset[..n];
    let material = &mut hits.material[..n];
    for i in 0..n {
        let prim = prims[i];
        if prim == NO_HIT {
            continue;
        }
        let d = Vec3::new(dx[i], dy[i], dz[i]);
        let (hit, m) = ctx.surface(prim, Vec3::new(ox[i], oy[i], oz[i]) + t[i] * d);
        let triangle = (prim as usize) < scene.triangles.len();
        let hit = face_the_ray(hit, d, two_sided && triangle);
        (px[i], py[i], pz[i]) = (hit.point.x, hit.point.y, hit.point.z);
        (nx[i], ny[i], nz[i]) = (hit.normal.x, hit.normal.y, hit.normal.z);
        offset[i] = hit.offset;
        material[i] = m;
    }
    hits.terms.clear();
    hits.terms.extend_from_slice(&ctx.materials);
    if ctx.textured {
        texels::fill(ctx, hits, n);
    }
}
