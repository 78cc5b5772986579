//! Stage 3, shadow: direct light at every hit.
//!
//! ```text
//! for each group of hits whose shadow rays fit the queue:
//!     spawn:   for hit, for light, for point j < N:  the shadow ray of `spawn::shadow_ray`
//!              (origin, l, tmax), queued when it has one (the point far enough above the
//!              tangent plane, the hit above the light's moved plane)
//!     occlude: N queued rays at a time (8 or 16), stop at the first blocker; small scenes
//!              test only the triangles that can shadow a light (`geometry::shadow_casters`),
//!              meshes go one ray at a time through `bvh::MeshBvh`, 8 boxes or 8 triangles per
//!              test
//!     shade:   in queue order, direct[hit] += Shade(l) / N for the rays not blocked
//! ```
//!
//! Which of three paths a render takes is [`ShadowPath`], chosen once when the context is
//! built; its table below says when each is taken and what it costs. Every path gives the
//! queue's sums bit for bit: the same kernels, and the (hit, light, point) order, which is the
//! reference's loop order, so each hit's sum comes out bit-identical. Soft shadows on a
//! parallelogram light (every lab light) go N points at a time (`simd::light_points`); hard
//! shadows and other light shapes call the scalar sampling code one point at a time.
//!
//! N is the engine's lane width (`lanes::LaneWidth`, 8 or 16): the stage is generic over the
//! lane type, and with 16 lanes the queue holds aligned blocks of 16 points per (hit, light).
//! Dead lanes add −0.0 and each hit's sum is still added in point order, so both widths give
//! the same bits.

use super::batch::{HitBatch, RayBatch, ShadowQueue};
use super::bvh::{MeshBvh, Stack};
use super::context::Context;
use super::cost::{Costs, Counter, Remap};
use super::lanes::{Lanes, at_width, set_bits};
use super::shade::{
    HitLight, ShadowLanes, ShadowRegisters, shade_lanes, shade_registers, shade_terms,
};
use super::simd::{self, LightBlock, RayColumns};
use crate::render::geometry::casters;
use crate::render::sampling::{SampleKey, mix32};
use crate::render::scene::NO_HIT;
use crate::render::settings::LightModel;
use crate::render::spawn::{falloff, light_end, shadow_ray};
use glam::Vec3;

/// How the shadow stage runs, chosen once per render ([`ShadowPath::choose`], when the context
/// is built); tests force each path the context admits and hold its image to `QueuedPerHit`'s.
///
/// | path | taken when | spawn | occlusion | shade | what it costs and saves |
/// | --- | --- | --- | --- | --- | --- |
/// | `FusedSoft` | soft shadows, every light a parallelogram, a sampler with a lane formula (all but the lab's at N = 1), no BVH | N points of one (hit, light) at a time (`simd::light_points`, `simd::shadow_rays`) | `simd::block_occluded` against the shadow casters | in registers, added in point order | no queue: each block is spawned, tested and shaded while it is in registers (the lab benchmark's path). Not for meshes: walking each block's rays from registers took 4.7% fewer instructions than the queue on the 12k-triangle box, and 2–4% more time (docs/TRIED.md) |
/// | `FusedHard` | hard shadows (or none) | N hits at a time, one ray per light (`simd::hit_shadow_rays`) | `simd::hit_rays_occluded` against the casters, or each live lane through `MeshBvh::hit_rays_occluded` | each lit ray, in light order | no queue; spawning across hits is what a hard-shadow ray costs most (56 instructions a ray against 161 hit by hit); on meshes the queue's push and reread were a third of the stage's instructions outside the walk (the 12k-triangle box: 20% fewer instructions, 1.19–1.26× the stage's rate) |
/// | `QueuedPerHit` | everything else: soft shadows with a BVH, fan lights, the lab's sampler at N = 1 | hit by hit, in (light, point) order, N points at a time where a lane formula exists, else the scalar `PointSet::point` | the queue, N rays at a time against the casters, or through the BVH one at a time | in queue order, aligned blocks N lanes at a time | the general path, and the one every other is held to |
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowPath {
    /// Soft shadows spawned, tested and shaded block by block in registers.
    FusedSoft,
    /// One ray per (hit, light), N hits at a time, in registers.
    FusedHard,
    /// Every ray spawned hit by hit into the queue.
    QueuedPerHit,
}

impl ShadowPath {
    /// Every path, fastest first: [`ShadowPath::choose`] takes the first the context admits.
    pub const ALL: [ShadowPath; 3] = [
        ShadowPath::FusedSoft,
        ShadowPath::FusedHard,
        ShadowPath::QueuedPerHit,
    ];

    /// True when this path gives `ctx`'s shadow stage its image (the table's "taken when";
    /// `QueuedPerHit` everywhere).
    pub fn admits(self, ctx: &Context) -> bool {
        match self {
            ShadowPath::FusedSoft => {
                ctx.accel.is_none()
                    && ctx.samples_lights()
                    && ctx.simd_light_sampling()
                    && ctx.lights.iter().all(|l| l.parallelogram.is_some())
            }
            ShadowPath::FusedHard => !ctx.samples_lights(),
            ShadowPath::QueuedPerHit => true,
        }
    }

    /// The path's name, as `render --stats` and `--stats-json` give it.
    pub fn name(self) -> &'static str {
        match self {
            ShadowPath::FusedSoft => "FusedSoft",
            ShadowPath::FusedHard => "FusedHard",
            ShadowPath::QueuedPerHit => "QueuedPerHit",
        }
    }

    /// What the path does, in a few words, for `render --stats`.
    pub fn describe(self) -> &'static str {
        match self {
            ShadowPath::FusedSoft => {
                "each block of N light points spawned, tested against the shadow casters and shaded in registers"
            }
            ShadowPath::FusedHard => {
                "one ray per light for N hits at a time, tested (against the casters, or each through the BVH) and shaded in registers"
            }
            ShadowPath::QueuedPerHit => {
                "every hit's rays queued in (light, point) order, then tested and shaded from the queue"
            }
        }
    }

    /// The fastest path `ctx` admits.
    pub fn choose(ctx: &Context) -> ShadowPath {
        ShadowPath::ALL
            .into_iter()
            .find(|p| p.admits(ctx))
            .unwrap_or(ShadowPath::QueuedPerHit)
    }
}

/// The hash state of a SampleKey before its dimension is mixed in: `sampling::hash(key, dim)`
/// is `mix32(key_prefix(key) ^ dim)`, so a (hit, light) stream is hashed once, not once per
/// point. Tested against `sampling::uniform`.
#[inline]
pub fn key_prefix(key: &SampleKey) -> u32 {
    let mut h = mix32(key.seed ^ 0x9e37_79b9);
    h = mix32(h ^ key.pixel);
    h = mix32(h ^ key.sample);
    h = mix32(h ^ key.bounce);
    mix32(h ^ key.light)
}

/// Fills every hit's `direct` column; returns the number of shadow rays cast (a point behind
/// the surface casts none, nor does anything with shadows off). Each ray's traversal work is
/// added to `costs` at the index of the hit that cast it (`cost::NoCount` counts nothing).
pub fn direct_light<S: Remap>(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    queue: &mut ShadowQueue,
    capacity: usize,
    costs: &mut S,
) -> u64 {
    at_width!(ctx.lane_width, V => direct_light_lanes::<V, S>(ctx, rays, hits, queue, capacity, costs))
}

/// [`direct_light`] at the lane width of `V`. Never inlined: inlined into the dispatcher, its
/// instruction count (tests/gates/icount.rs) moved by 0.5–2.2% with the codegen unit.
#[inline(never)]
fn direct_light_lanes<V: Lanes, S: Remap>(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    queue: &mut ShadowQueue,
    capacity: usize,
    costs: &mut S,
) -> u64 {
    let n = rays.len();
    hits.direct.fill(0..n, glam::Vec3::ZERO);
    match ctx.shadow_path {
        // Meshes get an instance of the hard path of their own, so that the lab's (no BVH) is
        // compiled as if the tree did not exist: the same choice made inside the fused soft
        // stage's loop cost the lab's stage 2.7% more instructions (tests/gates/icount.rs).
        ShadowPath::FusedSoft => return fused::<V, S>(ctx, rays, hits, costs),
        ShadowPath::FusedHard if ctx.accel.is_some() => {
            return fused_hard::<V, S, true>(ctx, rays, hits, costs);
        }
        ShadowPath::FusedHard => return fused_hard::<V, S, false>(ctx, rays, hits, costs),
        ShadowPath::QueuedPerHit => {}
    }
    // Room for one hit's rays at least, each light's points padded to whole N-lane blocks.
    let per_hit = ctx.lights.len() * (ctx.points_per_light as usize).div_ceil(V::N) * V::N;
    queue.reset(
        capacity.max(per_hit),
        ctx.settings.light_model != LightModel::Lab,
    );
    let mut cast = 0;
    let mut next = 0;
    while next < n {
        queue.len = 0;
        while next < n && queue.room() >= per_hit {
            cast += spawn::<V>(ctx, rays, hits, next, queue);
            next += 1;
        }
        if ctx.casts_shadow_rays() {
            occlude::<V, S>(ctx, queue, costs); // writes every entry
        } else {
            queue.blocked[..queue.len].fill(false);
        }
        shade::<V>(ctx, rays, hits, queue);
    }
    if ctx.casts_shadow_rays() { cast } else { 0 }
}

/// The sample stream of ray `i`'s hit towards light `li`: the key both engines draw its
/// points from.
fn sample_key(ctx: &Context, rays: &RayBatch, i: usize, li: usize) -> SampleKey {
    SampleKey {
        pixel: rays.pixel[i],
        sample: rays.sample[i],
        bounce: rays.bounce,
        light: li as u32,
        seed: ctx.settings.seed,
    }
}

/// The first block of points of `key`'s stream on a parallelogram light (corner, edge u, edge
/// v); the next blocks differ only in `j0`.
fn first_block<'c>(
    ctx: &'c Context,
    key: &SampleKey,
    (origin, edge_u, edge_v): (Vec3, Vec3, Vec3),
) -> LightBlock<'c> {
    LightBlock {
        prefix: key_prefix(key),
        j0: 0,
        sampler: ctx.block_sampler(key),
        origin,
        edge_u,
        edge_v,
    }
}

/// [`direct_light`] without the queue (`ShadowPath::FusedSoft`): each block of N points is
/// spawned, tested and shaded in registers, and added to its hit in point order as [`shade`]
/// adds a queued block. Returns the rays cast. Never inlined, so that profiles name it apart.
#[inline(never)]
fn fused<V: Lanes, S: Costs>(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    costs: &mut S,
) -> u64 {
    let scene = ctx.scene;
    let two_sided = ctx.settings.two_sided;
    let triangles = casters(scene, &ctx.shadow_casters, two_sided);
    let model = ctx.settings.light_model;
    let weight = 1.0 / ctx.points_per_light as f32;
    let count = ctx.points_per_light;
    let mut cast = 0;
    for i in 0..rays.len() {
        if hits.prim[i] == NO_HIT {
            continue;
        }
        let hit = hits.surface(i);
        let m = &hits.terms[hits.material[i] as usize];
        let (normal, to_eye) = (hits.normal.get(i), -rays.direction.get(i));
        let mut sum = (hits.direct.x[i], hits.direct.y[i], hits.direct.z[i]);
        for (li, light) in ctx.lights.iter().enumerate() {
            let Some(parallelogram) = light.parallelogram else {
                unreachable!("`ShadowPath::FusedSoft` admits parallelogram lights only")
            };
            let key = sample_key(ctx, rays, i, li);
            let end = light_end(&scene.lights[li], light.end_offset, &hit);
            let points = first_block(ctx, &key, parallelogram);
            let at = HitLight {
                material: m,
                normal,
                to_eye,
                light_color: light.color,
                weight,
            };
            // A while loop: `step_by` here was 5% of the stage's instructions.
            let mut j0 = 0;
            while j0 < count {
                let target = simd::light_points::<V>(&LightBlock { j0, ..points });
                let lanes = ((count - j0) as usize).min(V::N);
                let block = simd::shadow_rays::<V>(&hit, &target, &end, lanes);
                j0 += V::N as u32;
                if block.live == 0 {
                    continue;
                }
                cast += block.live.count_ones() as u64;
                let mut c = S::Counter::default();
                let blockers = simd::block_occluded::<V, S::Counter>(
                    triangles,
                    &scene.spheres,
                    &block,
                    two_sided,
                    &mut c,
                );
                costs.add(i, c.times(block.live.count_ones()));
                let lanes = ShadowRegisters {
                    l: block.l.map(V::from_array),
                    n_dot_l: V::from_array(block.n_dot_l),
                    open: V::from_fn(|k| if blockers >> k & 1 == 1 { 0.0 } else { 1.0 }),
                    falloff: (model != LightModel::Lab)
                        .then(|| V::from_fn(|k| falloff(model, block.dist.as_ref()[k]))),
                };
                sum = add_in_order::<V>(sum, &shade_registers::<V>(&at, &lanes));
            }
        }
        (hits.direct.x[i], hits.direct.y[i], hits.direct.z[i]) = sum;
    }
    cast
}

/// [`direct_light`] without the queue for one ray per (hit, light) (`ShadowPath::FusedHard`):
/// for each group of N hits, for light, the rays spawned and tested in registers, then each
/// unblocked ray's Shade added as [`shade`] adds a queued one; each hit's rays come in light
/// order, so its sum is the queue's, bit for bit. Returns the rays cast. Never inlined.
#[inline(never)]
fn fused_hard<V: Lanes, S: Costs, const MESH: bool>(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    costs: &mut S,
) -> u64 {
    let scene = ctx.scene;
    let two_sided = ctx.settings.two_sided;
    let triangles = casters(scene, &ctx.shadow_casters, two_sided);
    let model = ctx.settings.light_model;
    let weight = 1.0 / ctx.points_per_light as f32;
    let occludes = ctx.casts_shadow_rays();
    // Meshes: each live lane's ray walks the tree one at a time, from registers.
    let bvh = if MESH { ctx.accel.as_ref() } else { None };
    let mut stack = bvh.map_or_else(Stack::default, MeshBvh::stack);
    let mut cast = 0;
    for i0 in (0..rays.len()).step_by(V::N) {
        let present = present_hits::<V>(hits, i0, rays.len());
        if present == 0 {
            continue;
        }
        let group = simd::HitLanes::<V>::load(hits, i0);
        for (li, light) in ctx.lights.iter().enumerate() {
            let block =
                simd::hit_shadow_rays(&group, &scene.lights[li], light.end_offset, light.centroid);
            let live = block.live & present;
            cast += live.count_ones() as u64;
            let blocked = match (occludes, bvh) {
                (false, _) => 0,
                (true, Some(bvh)) => {
                    bvh.hit_rays_occluded(scene, &block, live, two_sided, &mut stack, i0, costs)
                }
                (true, None) => {
                    let mut c = S::Counter::default();
                    let blocked = simd::hit_rays_occluded::<V, S::Counter>(
                        triangles,
                        &scene.spheres,
                        &block,
                        live,
                        two_sided,
                        &mut c,
                    );
                    costs.add_lanes(i0, live, c);
                    blocked
                }
            };
            // As the queue's Shade: unblocked rays with n·l > 0.
            let lit = set_bits(live & !blocked).filter(|&k| block.n_dot_l.as_ref()[k] > 0.0);
            for k in lit {
                let (i, s) = (i0 + k, block.lane(k));
                // The queue keeps distances only under a light model with fall-off.
                let fall = if model == LightModel::Lab {
                    1.0
                } else {
                    falloff(model, s.dist)
                };
                let light_color = light.color * fall;
                add_ray(
                    rays,
                    hits,
                    i,
                    s.ray.direction,
                    s.n_dot_l,
                    light_color,
                    weight,
                );
            }
        }
    }
    if occludes { cast } else { 0 }
}

/// The hits of `i0..i0 + N` (of `len` rays) that hit something, as a bit mask.
fn present_hits<V: Lanes>(hits: &HitBatch, i0: usize, len: usize) -> u32 {
    (0..(len - i0).min(V::N))
        .filter(|&k| hits.prim[i0 + k] != NO_HIT)
        .fold(0, |m, k| m | 1 << k)
}

/// Queues the shadow rays of hit `i`, in (light, point) order; returns how many are live.
fn spawn<V: Lanes>(
    ctx: &Context,
    rays: &RayBatch,
    hits: &HitBatch,
    i: usize,
    queue: &mut ShadowQueue,
) -> u64 {
    if hits.prim[i] == NO_HIT {
        return 0;
    }
    let mut cast = 0;
    let hit = hits.surface(i);
    let count = ctx.points_per_light;
    for (li, light) in ctx.lights.iter().enumerate() {
        let key = sample_key(ctx, rays, i, li);
        let end = light_end(&ctx.scene.lights[li], light.end_offset, &hit);
        match (
            ctx.samples_lights() && ctx.simd_light_sampling(),
            light.parallelogram,
        ) {
            (true, Some(parallelogram)) => {
                let block = first_block(ctx, &key, parallelogram);
                for j0 in (0..count).step_by(V::N) {
                    let target = simd::light_points::<V>(&LightBlock { j0, ..block });
                    let lanes = ((count - j0) as usize).min(V::N);
                    let block = simd::shadow_rays::<V>(&hit, &target, &end, lanes);
                    if block.live != 0 {
                        queue.push_block(&block, i as u32, li as u32);
                        cast += block.live.count_ones() as u64;
                    }
                }
            }
            _ => {
                for j in 0..count {
                    let target = if ctx.samples_lights() {
                        let (u, v) = ctx.points.point(&key, j);
                        ctx.scene.lights[li].point(u, v)
                    } else {
                        light.centroid
                    };
                    if let Some(s) = shadow_ray(&hit, target, &end) {
                        queue.push(&s, i as u32, li as u32);
                        cast += 1;
                    }
                }
            }
        }
    }
    cast
}

/// Sets `queue.blocked` for every queued ray (both kernels write every entry); each ray's work
/// goes to `costs` at its hit's index.
fn occlude<V: Lanes, S: Remap>(ctx: &Context, queue: &mut ShadowQueue, costs: &mut S) {
    let scene = ctx.scene;
    let two_sided = ctx.settings.two_sided;
    let n = queue.len;
    let cols = RayColumns {
        origin: queue.origin.slices(0..n),
        direction: queue.direction.slices(0..n),
        tmax: &queue.tmax[..n],
    };
    let blocked = &mut queue.blocked[..n];
    let costs = &mut costs.mapped(&queue.path);
    match &ctx.accel {
        None => simd::occluded::<V, _>(
            casters(scene, &ctx.shadow_casters, two_sided),
            &scene.spheres,
            &cols,
            two_sided,
            blocked,
            costs,
        ),
        // Dead entries (no ray: `spawn::shadow_ray` gave none) carry tmax = 0, which
        // `MeshBvh::occluded` skips.
        Some(bvh) => bvh.occluded(scene, &cols, two_sided, blocked, costs),
    }
}

/// `sum` plus each lane of `c` (r, g, b), lane by lane in order, like the reference's loop
/// over points; lanes that add nothing hold −0.0.
#[inline(always)]
fn add_in_order<V: Lanes>(sum: (f32, f32, f32), c: &[V::Array; 3]) -> (f32, f32, f32) {
    let (mut r, mut g, mut b) = sum;
    for ((cr, cg), cb) in c[0].as_ref().iter().zip(c[1].as_ref()).zip(c[2].as_ref()) {
        r += cr;
        g += cg;
        b += cb;
    }
    (r, g, b)
}

/// Adds Shade · `weight` of one unblocked shadow ray with direction `l` to ray `i`'s hit,
/// `light_color` its light's colour with the fall-off.
#[inline(always)]
fn add_ray(
    rays: &RayBatch,
    hits: &mut HitBatch,
    i: usize,
    l: Vec3,
    n_dot_l: f32,
    light_color: Vec3,
    weight: f32,
) {
    let m = &hits.terms[hits.material[i] as usize];
    let (n, e) = (hits.normal.get(i), -rays.direction.get(i));
    let c = shade_terms(m, n, e, l, n_dot_l, light_color);
    hits.direct.add(i, c * weight);
}

/// Adds Shade / N of every unblocked queued ray to its hit, in queue order. Aligned blocks of
/// N rays (the lane width) from one hit to one light (soft shadows) are shaded N lanes at a
/// time, then added lane by lane in order.
fn shade<V: Lanes>(ctx: &Context, rays: &RayBatch, hits: &mut HitBatch, queue: &ShadowQueue) {
    let weight = 1.0 / ctx.points_per_light as f32;
    let model = ctx.settings.light_model;
    let mut q = 0;
    while q < queue.len {
        let end = q + V::N;
        // The queue is sorted by (hit, light): equal ends mean one hit and one light.
        if end <= queue.len
            && queue.path[q] == queue.path[end - 1]
            && queue.light[q] == queue.light[end - 1]
        {
            let i = queue.path[q] as usize;
            let m = &hits.terms[hits.material[i] as usize];
            // Distances are kept only under a light model with fall-off (`ShadowQueue::dist`).
            let falloffs: Option<V::Array> = (!queue.dist.is_empty()).then(|| {
                let mut f = V::Array::default();
                for (f, &d) in f.as_mut().iter_mut().zip(&queue.dist[q..end]) {
                    *f = falloff(model, d);
                }
                f
            });
            // In the order the kernel's operands were always evaluated: the hit, the rays, the
            // light (`shade_lanes`'s instruction count moves with it).
            let (normal, to_eye) = (hits.normal.get(i), -rays.direction.get(i));
            let lanes = ShadowLanes {
                l: queue.direction.slices(q..end),
                n_dot_l: &queue.n_dot_l[q..end],
                blocked: &queue.blocked[q..end],
                falloff: falloffs.as_ref().map(|f| f.as_ref()),
            };
            let at = HitLight {
                material: m,
                normal,
                to_eye,
                light_color: ctx.lights[queue.light[q] as usize].color,
                weight,
            };
            let sum = (hits.direct.x[i], hits.direct.y[i], hits.direct.z[i]);
            let sum = add_in_order::<V>(sum, &shade_lanes::<V>(&at, &lanes));
            (hits.direct.x[i], hits.direct.y[i], hits.direct.z[i]) = sum;
            q = end;
            continue;
        }
        if !queue.blocked[q] && queue.n_dot_l[q] > 0.0 {
            let i = queue.path[q] as usize;
            let fall = queue.dist.get(q).map_or(1.0, |&d| falloff(model, d));
            let light_color = ctx.lights[queue.light[q] as usize].color * fall;
            let (l, n_dot_l) = (queue.direction.get(q), queue.n_dot_l[q]);
            add_ray(rays, hits, i, l, n_dot_l, light_color, weight);
        }
        q += 1;
    }
}
