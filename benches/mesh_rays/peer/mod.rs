//! Peer comparison on mesh scenes: the same rays traced by obvhs's CWBVH one ray at a time, by
//! raywave's wavefront stages, and by Embree 4 (feature `embree4`) and tinybvh (feature
//! `tinybvh`), with the hits compared.
//!
//! ```text
//! RaySets::new(scene, seed):                      built once, from a fixed seed
//!     primary     camera ray through the centre of every pixel of W×H
//!     shadow      from every primary hit to a uniform point on a light,
//!                 a segment with tmax = distance − 1e-4
//!     incoherent  from every primary hit in a uniformly random direction
//!     fan16/64    from every n-th primary hit, n segments to n random light points, for
//!                 n = 16 and 64: the renderer's soft-shadow pattern (one origin per n
//!                 consecutive rays, so every 8-ray packet has one origin)
//! each engine fills Hits { t, prim } (closest) or a Vec<bool> (occluded) per ray;
//! agreement: same prim, or both hit with |Δt| ≤ 1e-4·max(1, t) (shared edges), or both miss.
//! ```
//!
//! Every comparison is **two-sided**: Embree (as Intel's release builds it, without
//! `EMBREE_BACKFACE_CULLING`) and tinybvh report hits on both sides of a triangle, so raywave's
//! kernels are called with `two_sided = true` here, whatever the lab's one-sided convention
//! says; and the scene is `without_emitters`, since a two-sided light wall would hide the lab's
//! box. The peers trace triangles only, so a scene with spheres is compared `without_spheres`.
//!
//! Rays are stored as wavefront `RayBatch`es of `BATCH` rays, so every engine reads the same
//! structure-of-arrays columns and the wavefront stage gets its own input type without a copy
//! inside the timed loop.

#[cfg(feature = "embree4")]
pub mod embree4;
#[cfg(feature = "embree4")]
pub mod embree4_tree;
pub mod stage;
#[cfg(feature = "tinybvh")]
pub mod tinybvh;

use glam::Vec3;
use obvhs::{cwbvh::CwBvh, ray::RayHit};
use raywave::render::camera::CameraRays;
use raywave::render::geometry::{Ray, casters, intersect_triangle, obvhs_ray};
use raywave::render::sampling::SplitMix64;
use raywave::render::scene::{NO_HIT, Scene};
use raywave::render::spawn::surface_hit;
use raywave::render::wavefront::batch::{HitBatch, PathId, RayBatch};
use raywave::render::wavefront::bvh::MeshBvh;
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::cost::NoCount;
use raywave::render::wavefront::lanes::{LaneWidth, at_width};
use raywave::render::wavefront::{DEFAULT_BATCH_SIZE, intersect, simd};
use std::time::{Duration, Instant};

/// The scene as the peers see it: every triangle except the emissive ones (the lights).
///
/// The lab's light is the box's whole front wall, facing inwards; one-sided, the camera looks
/// through its back, but two-sided (as Embree traces) it would hide the whole box. The lights
/// stay in `Scene::lights`, so shadow rays still aim at them; the segments end 1e-4 short of
/// the light, so they never needed its triangles.
pub fn without_emitters(scene: &Scene) -> Scene {
    let mut peer = scene.clone();
    peer.triangles
        .retain(|t| scene.materials[t.material as usize].emitted == Vec3::ZERO);
    peer
}

/// The scene without its spheres: what the peers, which trace triangles only, can compare
/// on a scene such as the lab's box (whose three mirror spheres would be missing from their
/// answers). Its materials, lights and camera are unchanged.
pub fn without_spheres(scene: &Scene) -> Scene {
    Scene {
        spheres: Vec::new(),
        ..scene.clone()
    }
}

/// Rays per `RayBatch` of a ray set: the wavefront engine's default batch size.
pub const BATCH: usize = DEFAULT_BATCH_SIZE;

/// Which ray set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RaySetKind {
    /// Camera rays through pixel centres: coherent, closest hit.
    Primary,
    /// Segments from primary hits to light points: coherent, any hit (occlusion).
    Shadow,
    /// From primary hits in uniformly random directions: incoherent, closest hit.
    Incoherent,
    /// n segments from one primary hit to n light points, for every n-th hit: occlusion, one
    /// origin per aligned block of n (how the renderer casts soft shadows with n points per
    /// light: its shadow queue holds them in (hit, light, j) order, 8 to a packet).
    ShadowFan(u32),
}

/// The soft-shadow fan sizes of every `RaySets`: raywave's default 16 points per light and the
/// lab benchmark's 64.
pub const FAN_SIZES: [u32; 2] = [16, 64];

impl RaySetKind {
    /// Lower-case name, for benchmark ids: `primary`, `shadow`, `incoherent`, `shadow_fan16`.
    pub fn name(self) -> String {
        match self {
            RaySetKind::Primary => "primary".into(),
            RaySetKind::Shadow => "shadow".into(),
            RaySetKind::Incoherent => "incoherent".into(),
            RaySetKind::ShadowFan(n) => format!("shadow_fan{n}"),
        }
    }

    /// What the rays are, for table rows: `camera`, `hard shadow`, `soft shadow ×16`, ...
    pub fn title(self) -> String {
        match self {
            RaySetKind::Primary => "camera".into(),
            RaySetKind::Shadow => "hard shadow".into(),
            RaySetKind::Incoherent => "incoherent".into(),
            RaySetKind::ShadowFan(n) => format!("soft shadow ×{n}"),
        }
    }

    /// True for occlusion (any-hit) sets, false for closest-hit sets.
    pub fn is_occlusion(self) -> bool {
        matches!(self, RaySetKind::Shadow | RaySetKind::ShadowFan(_))
    }

    /// Whether the rays are coherent (Embree's context hint): every set but the incoherent one.
    pub fn is_coherent(self) -> bool {
        self != RaySetKind::Incoherent
    }
}

/// One ray set, in wavefront batches of `BATCH` rays (the last one shorter).
#[derive(Clone, Debug)]
pub struct RaySet {
    /// What the rays are.
    pub kind: RaySetKind,
    /// The rays; `tmax` is infinity except for shadow segments.
    pub batches: Vec<RayBatch>,
}

impl RaySet {
    fn new(kind: RaySetKind) -> Self {
        RaySet {
            kind,
            batches: Vec::new(),
        }
    }

    /// Number of rays.
    pub fn len(&self) -> usize {
        self.batches.iter().map(RayBatch::len).sum()
    }

    fn push(&mut self, origin: Vec3, direction: Vec3, tmax: f32) {
        if self.batches.last().is_none_or(|b| b.len() == BATCH) {
            // Camera rays are depth 0, the rest as if from a first bounce: the intersect
            // stage traces depth-0 batches as coherent packets.
            self.batches.push(RayBatch {
                bounce: u32::from(self.kind != RaySetKind::Primary),
                ..RayBatch::default()
            });
        }
        let first = (self.batches.len() - 1) * BATCH;
        let batch = self.batches.last_mut().expect("a batch was just pushed");
        let n = batch.len() as u32;
        // Ray i of a camera set is pixel i's, as in a frame of one sample per pixel, so the
        // shadow stage draws a frame's light points from its hits (`stage::ShadowStage`).
        let path = PathId {
            pixel: (first + batch.len()) as u32,
            sample: 0,
            slot: n,
        };
        batch.push(origin, direction, Vec3::ONE, path);
        *batch.tmax.last_mut().expect("a ray was just pushed") = tmax;
    }

    /// Ray `i` of batch `b` as the scalar kernels want it, with its tmax.
    #[inline]
    pub fn ray(batch: &RayBatch, i: usize) -> (Ray, f32) {
        (
            Ray {
                origin: batch.origin.get(i),
                direction: batch.direction.get(i),
            },
            batch.tmax[i],
        )
    }
}

/// The ray sets of one scene.
#[derive(Clone, Debug)]
pub struct RaySets {
    /// Camera rays, one per pixel.
    pub primary: RaySet,
    /// One shadow segment per primary hit.
    pub shadow: RaySet,
    /// One random-direction ray per primary hit.
    pub incoherent: RaySet,
    /// For each n of `FAN_SIZES`, in that order: n shadow segments from every n-th primary
    /// hit, in aligned blocks of n (about one ray per primary hit, as the other sets).
    pub fans: Vec<RaySet>,
}

impl RaySets {
    /// Builds the sets for a `width` × `height` image of the scene's camera; the primary hits
    /// come from `bvh`, the random numbers from `seed` alone.
    pub fn new(scene: &Scene, bvh: &ObvhsMesh, width: u32, height: u32, seed: u64) -> Self {
        let camera = CameraRays::new(&scene.camera, width, height);
        let mut primary = RaySet::new(RaySetKind::Primary);
        for pixel in 0..width * height {
            let (x, y) = camera.screen(pixel, 0.5, 0.5);
            let ray = camera.ray(x, y);
            primary.push(ray.origin, ray.direction, f32::INFINITY);
        }
        let mut hits = Hits::default();
        bvh.closest(scene, &primary, &mut hits);

        let mut rng = SplitMix64(seed);
        let mut shadow = RaySet::new(RaySetKind::Shadow);
        let mut incoherent = RaySet::new(RaySetKind::Incoherent);
        let mut fans: Vec<RaySet> = FAN_SIZES
            .iter()
            .map(|&n| RaySet::new(RaySetKind::ShadowFan(n)))
            .collect();
        // Their own streams, so adding the fan sets left the other sets unchanged.
        let mut fan_rngs: Vec<SplitMix64> = FAN_SIZES
            .iter()
            .map(|&n| SplitMix64(seed ^ 0xfa4_fa4_fa4 ^ u64::from(n)))
            .collect();
        let mut hit_index = 0usize;
        let rays = primary
            .batches
            .iter()
            .flat_map(|b| (0..b.len()).map(move |i| (b, i)));
        for ((batch, i), (&t, &prim)) in rays.zip(hits.t.iter().zip(&hits.prim)) {
            if prim == NO_HIT {
                continue;
            }
            let ray = Ray {
                origin: batch.origin.get(i),
                direction: batch.direction.get(i),
            };
            let hit = surface_hit(scene, prim, &ray, t, false);
            // Every ray leaves the surface on the side it goes to, as the renderers' do, but
            // `LEAVE` off it: these are benchmark inputs, and a random direction grazing a
            // curved mesh meets the next triangle at t ≈ 1e-6, where the engines' box tests
            // legitimately differ.
            let leave = |direction: Vec3| {
                let side = if direction.dot(hit.normal) >= 0.0 {
                    LEAVE
                } else {
                    -LEAVE
                };
                hit.point + side * hit.normal
            };
            if !scene.lights.is_empty() {
                let light = &scene.lights[rng.below(scene.lights.len())];
                let target = light.point(rng.unit(), rng.unit());
                let to_light = target - hit.point;
                let dist = to_light.length();
                if dist > 2.0 * LEAVE {
                    let l = to_light / dist;
                    let origin = leave(l);
                    shadow.push(origin, l, (target - origin).length() - LEAVE);
                }
            }
            // Uniform on the sphere: z uniform in [-1, 1], azimuth uniform.
            let z = 1.0 - 2.0 * rng.unit();
            let phi = std::f32::consts::TAU * rng.unit();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let direction = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            incoherent.push(leave(direction), direction, f32::INFINITY);
            for (fan, fan_rng) in fans.iter_mut().zip(&mut fan_rngs) {
                let RaySetKind::ShadowFan(n) = fan.kind else {
                    unreachable!("fans are fan sets")
                };
                if !hit_index.is_multiple_of(n as usize) || scene.lights.is_empty() {
                    continue;
                }
                let light = &scene.lights[fan_rng.below(scene.lights.len())];
                // One origin for the block: on the side of the light's centre.
                let origin = leave(light.centroid - hit.point);
                for _ in 0..n {
                    let target = light.point(fan_rng.unit(), fan_rng.unit());
                    let to_light = target - hit.point;
                    let dist = to_light.length();
                    // A dead lane (tmax 0) keeps the block aligned; no engine reports a hit
                    // in (0, 0).
                    let (l, tmax) = if dist > 2.0 * LEAVE {
                        (to_light / dist, (target - origin).length() - LEAVE)
                    } else {
                        (Vec3::Z, 0.0)
                    };
                    fan.push(origin, l, tmax);
                }
            }
            hit_index += 1;
        }
        RaySets {
            primary,
            shadow,
            incoherent,
            fans,
        }
    }

    /// The fan set of `n` rays per origin (n from `FAN_SIZES`).
    pub fn fan(&self, n: u32) -> &RaySet {
        self.fans
            .iter()
            .find(|s| s.kind == RaySetKind::ShadowFan(n))
            .unwrap_or_else(|| panic!("no fan of {n}: the sizes are {FAN_SIZES:?}"))
    }

    /// Every set, in table order: primary, shadow, the fans by size, incoherent.
    pub fn all(&self) -> Vec<&RaySet> {
        let mut sets = vec![&self.primary, &self.shadow];
        sets.extend(&self.fans);
        sets.push(&self.incoherent);
        sets
    }
}

/// How far off its surface a ray of the benchmark sets starts, and short of the light a
/// shadow segment ends: the lab's 1e-4, the scale of the generated mesh scenes.
const LEAVE: f32 = 1e-4;

/// Closest hits of a ray set, in ray order: `t = INFINITY`, `prim = NO_HIT` for a miss.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Hits {
    /// Hit distance.
    pub t: Vec<f32>,
    /// Triangle index in `Scene::triangles`.
    pub prim: Vec<u32>,
}

impl Hits {
    /// Empties both columns, keeping their capacity.
    pub fn clear(&mut self) {
        self.t.clear();
        self.prim.clear();
    }

    /// Appends one result.
    #[inline]
    pub fn push(&mut self, t: f32, prim: u32) {
        self.t.push(t);
        self.prim.push(prim);
    }
}

/// obvhs's CWBVH over a scene's triangles, traced one ray at a time: the baseline the mesh targets
/// are measured against.
pub struct ObvhsMesh {
    /// The BVH (primitive indices map back to `Scene::triangles`).
    pub bvh: CwBvh,
    /// Wall time of the build, triangle conversion included.
    pub build_time: Duration,
}

impl ObvhsMesh {
    /// Builds the CWBVH with the same preset as raywave's `Accel` (`medium_build`).
    pub fn new(scene: &Scene) -> Self {
        let start = Instant::now();
        let bvh = raywave::render::geometry::build_cwbvh(scene);
        ObvhsMesh {
            bvh,
            build_time: start.elapsed(),
        }
    }

    /// Closest two-sided hit of every ray (`ray_traverse`), into `out`.
    pub fn closest(&self, scene: &Scene, set: &RaySet, out: &mut Hits) {
        out.clear();
        let bvh = &self.bvh;
        for batch in &set.batches {
            for i in 0..batch.len() {
                let (ray, tmax) = RaySet::ray(batch, i);
                let mut hit = RayHit::none();
                let found = bvh.ray_traverse(obvhs_ray(&ray, tmax), &mut hit, |r, id| {
                    let tri = &scene.triangles[bvh.primitive_indices[id] as usize];
                    intersect_triangle(tri, &ray, r.tmax, true)
                });
                if found {
                    out.push(hit.t, bvh.primitive_indices[hit.primitive_id as usize]);
                } else {
                    out.push(f32::INFINITY, NO_HIT);
                }
            }
        }
    }

    /// Whether anything blocks each segment (`ray_traverse_miss`, first blocker), into `out`.
    pub fn occluded(&self, scene: &Scene, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        let bvh = &self.bvh;
        for batch in &set.batches {
            for i in 0..batch.len() {
                let (ray, tmax) = RaySet::ray(batch, i);
                let miss = bvh.ray_traverse_miss(obvhs_ray(&ray, tmax), |_, id| {
                    let tri = &scene.triangles[bvh.primitive_indices[id] as usize];
                    intersect_triangle(tri, &ray, tmax, true)
                });
                out.push(!miss);
            }
        }
    }
}

/// raywave's wavefront intersect stage over the set's batches (`intersect::closest`, which also
/// fills the shading columns of `scratch`), with t and prim copied into `out`. The context must
/// be built with `two_sided = true` for peer comparisons.
pub fn wavefront_closest(ctx: &Context, set: &RaySet, scratch: &mut HitBatch, out: &mut Hits) {
    out.clear();
    for batch in &set.batches {
        intersect::closest(ctx, batch, scratch, &mut NoCount);
        out.t.extend_from_slice(&scratch.t[..batch.len()]);
        out.prim.extend_from_slice(&scratch.prim[..batch.len()]);
    }
}

/// Bytes of raywave's mesh BVH: its 8-wide nodes at 224 bytes and triangle blocks at 320, the
/// sizes `wavefront::bvh` documents. The blocks hold copies of the triangles, so these are all
/// the bytes its traversal reads, as Embree's BVH holds its Triangle4 leaves.
pub fn mesh_bvh_bytes(bvh: &MeshBvh) -> usize {
    /// `size_of::<Node>()` and `size_of::<Block>()` of `wavefront::bvh` (private there).
    const NODE_BYTES: usize = 224;
    const BLOCK_BYTES: usize = 320;
    let (nodes, blocks) = bvh.size();
    nodes * NODE_BYTES + blocks * BLOCK_BYTES
}

/// The context's mesh BVH. Scenes below `BVH_MIN_TRIANGLES` have none and are not mesh
/// scenes: they panic here.
fn mesh_bvh<'c>(ctx: &'c Context) -> &'c MeshBvh {
    ctx.accel
        .as_ref()
        .expect("peer comparisons run on mesh scenes, which have a BVH")
}

/// The wavefront engine's mesh traversal alone (`intersect::mesh_hits`, the call inside
/// `intersect::closest`), over the set's batches: t and prim into `out`, nothing else, as
/// obvhs's and Embree's calls here produce. `wavefront_closest` adds the intersect stage's
/// shading columns (point, normal, material) on top.
pub fn wavefront_bvh_closest(ctx: &Context, set: &RaySet, out: &mut Hits) {
    traverse(ctx, set, out, |bvh, scene, batch, two_sided, t, prim| {
        intersect::mesh_hits(bvh, scene, batch, two_sided, t, prim, &mut NoCount)
    });
}

/// [`wavefront_bvh_closest`] with every ray traced on its own (`MeshBvh::closest_hits`), as
/// the stage traces all but camera rays: on camera rays, what the packets buy.
pub fn wavefront_bvh_closest_one_ray(ctx: &Context, set: &RaySet, out: &mut Hits) {
    traverse(ctx, set, out, |bvh, scene, batch, two_sided, t, prim| {
        bvh.closest_hits(
            scene,
            &intersect::columns(batch),
            two_sided,
            t,
            prim,
            &mut NoCount,
        )
    });
}

/// `trace(bvh, scene, batch, two_sided, t, prim)` over the set's batches, into `out`.
fn traverse(
    ctx: &Context,
    set: &RaySet,
    out: &mut Hits,
    trace: impl Fn(&MeshBvh, &Scene, &RayBatch, bool, &mut [f32], &mut [u32]),
) {
    out.clear();
    let bvh = mesh_bvh(ctx);
    let two_sided = ctx.settings.two_sided;
    for batch in &set.batches {
        let start = out.t.len();
        out.t.resize(start + batch.len(), f32::INFINITY);
        out.prim.resize(start + batch.len(), NO_HIT);
        trace(
            bvh,
            ctx.scene,
            batch,
            two_sided,
            &mut out.t[start..],
            &mut out.prim[start..],
        );
    }
}

/// raywave's hit search as the intersect stage runs it (`intersect::closest` without the
/// shading columns), over the set's batches: for meshes the BVH traversal
/// (`intersect::mesh_hits`: camera rays in packets, others one at a time), for scenes below
/// `BVH_MIN_TRIANGLES` the brute-force kernel over every primitive at the build's native lane
/// width, as the stage runs it (`simd::closest_hits`, 16 lanes with AVX-512). t and prim into `out`, what the peers' calls produce.
pub fn raywave_closest(ctx: &Context, set: &RaySet, out: &mut Hits) {
    if ctx.accel.is_some() {
        return wavefront_bvh_closest(ctx, set, out);
    }
    out.clear();
    let scene = ctx.scene;
    for batch in &set.batches {
        let start = out.t.len();
        out.t.resize(start + batch.len(), f32::INFINITY);
        out.prim.resize(start + batch.len(), NO_HIT);
        at_width!(LaneWidth::Auto, V => simd::closest_hits::<V>(
            &scene.triangles,
            &scene.spheres,
            &intersect::columns(batch),
            ctx.settings.two_sided,
            &mut out.t[start..],
            &mut out.prim[start..],
        ));
    }
}

/// The wavefront engine's occlusion path, over the set's batches.
///
/// `wavefront::shadow`'s occlusion pass hands the shadow queue's columns to
/// `MeshBvh::occluded` for meshes (the fused hard-shadow path walks the same per-ray code from
/// registers, `MeshBvh::hit_rays_occluded`), and to the brute-force `simd::occluded` (the build's
/// native lane width, as the stage runs it) over the shadow
/// casters (`geometry::casters`: every triangle when two-sided) and spheres for smaller scenes;
/// this hands the same function each batch's columns.
pub fn wavefront_occluded(ctx: &Context, set: &RaySet, out: &mut Vec<bool>) {
    out.clear();
    let scene = ctx.scene;
    let two_sided = ctx.settings.two_sided;
    for batch in &set.batches {
        let start = out.len();
        out.resize(start + batch.len(), false);
        let (rays, blocked) = (intersect::columns(batch), &mut out[start..]);
        match &ctx.accel {
            Some(bvh) => bvh.occluded(scene, &rays, two_sided, blocked, &mut NoCount),
            None => at_width!(LaneWidth::Auto, V => simd::occluded::<V, _>(
                casters(scene, &ctx.shadow_casters, two_sided),
                &scene.spheres,
                &rays,
                two_sided,
                blocked,
                &mut NoCount,
            )),
        }
    }
}

/// Every triangle against every ray, two-sided: the independent answer for small tests.
pub fn brute_force_closest(scene: &Scene, set: &RaySet, out: &mut Hits) {
    out.clear();
    for batch in &set.batches {
        for i in 0..batch.len() {
            let (ray, mut best) = RaySet::ray(batch, i);
            let mut prim = NO_HIT;
            for (k, tri) in scene.triangles.iter().enumerate() {
                let t = intersect_triangle(tri, &ray, best, true);
                if t < best {
                    best = t;
                    prim = k as u32;
                }
            }
            out.push(if prim == NO_HIT { f32::INFINITY } else { best }, prim);
        }
    }
}

/// How many rays two engines agree on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Agreement {
    /// Rays compared.
    pub rays: usize,
    /// Rays with the same answer.
    pub agree: usize,
    /// Of those, rays that hit different triangles at the same distance (a shared edge).
    pub same_t_other_prim: usize,
    /// Of those, rays that one side saw hit within `NEAR_ORIGIN_T` and the other miss or hit
    /// farther away.
    pub near_origin: usize,
}

impl Agreement {
    /// agree / rays (1 for no rays).
    pub fn fraction(&self) -> f64 {
        if self.rays == 0 {
            1.0
        } else {
            self.agree as f64 / self.rays as f64
        }
    }

    /// Rays with different answers.
    pub fn disagree(&self) -> usize {
        self.rays - self.agree
    }
}

/// Relative distance tolerance under which two hits on different triangles count as one hit
/// on their shared edge.
const EDGE_T_TOLERANCE: f32 = 1e-4;

/// Under this distance a hit that one engine reports counts as agreeing with whatever the other
/// reports (a miss, or a hit farther on): a ray that starts on the edge where two faces meet (a
/// camera ray hit the box's corner) lies on the other face's plane up to rounding and meets it
/// at t ≈ 1e-7, at t = 0, or not at all. obvhs's slab test and an exact triangle test
/// legitimately differ there (7 of 6,084 incoherent rays of the mesh test scene), and so do
/// intervals: tinybvh's plain BVH accepts t = 0 (it rejects only t < 0, and −0 passes), where
/// raywave and Embree need t > 0 and go on to the next surface (15 of 43,264 incoherent rays
/// of the mesh test scene at 256×256).
const NEAR_ORIGIN_T: f32 = 1e-5;

/// Closest hits agree when both miss, both name the same triangle, both hit at distances
/// within `EDGE_T_TOLERANCE · max(1, t)` (two triangles sharing the edge the ray crosses), or
/// one hits within `NEAR_ORIGIN_T` of the origin.
pub fn hit_agreement(a: &Hits, b: &Hits) -> Agreement {
    assert_eq!(a.t.len(), b.t.len(), "hit lists of different lengths");
    let mut agreement = Agreement {
        rays: a.t.len(),
        agree: 0,
        same_t_other_prim: 0,
        near_origin: 0,
    };
    for i in 0..a.t.len() {
        let (pa, pb) = (a.prim[i], b.prim[i]);
        if pa == pb {
            agreement.agree += 1;
        } else if pa != NO_HIT
            && pb != NO_HIT
            && (a.t[i] - b.t[i]).abs() <= EDGE_T_TOLERANCE * a.t[i].max(1.0)
        {
            agreement.agree += 1;
            agreement.same_t_other_prim += 1;
        } else if a.t[i].min(b.t[i]) < NEAR_ORIGIN_T {
            agreement.agree += 1;
            agreement.near_origin += 1;
        }
    }
    agreement
}

/// Occlusion answers against the blockers of a peer whose shadow query is a closest hit
/// limited to tmax (tinybvh: `Hits` with `NO_HIT` for a free segment): they agree when both say
/// the same, or, as for closest hits, when the peer's blocker lies within `NEAR_ORIGIN_T` of
/// the origin (a segment that starts on another surface's plane).
pub fn blocker_agreement(a: &[bool], blockers: &Hits) -> Agreement {
    assert_eq!(
        a.len(),
        blockers.t.len(),
        "answer lists of different lengths"
    );
    let mut agreement = Agreement {
        rays: a.len(),
        agree: 0,
        same_t_other_prim: 0,
        near_origin: 0,
    };
    for (&blocked, (&t, &prim)) in a.iter().zip(blockers.t.iter().zip(&blockers.prim)) {
        if blocked == (prim != NO_HIT) {
            agreement.agree += 1;
        } else if t < NEAR_ORIGIN_T {
            agreement.agree += 1;
            agreement.near_origin += 1;
        }
    }
    agreement
}

/// Occlusion answers agree when they are equal.
pub fn occlusion_agreement(a: &[bool], b: &[bool]) -> Agreement {
    assert_eq!(a.len(), b.len(), "occlusion lists of different lengths");
    Agreement {
        rays: a.len(),
        agree: a.iter().zip(b).filter(|(x, y)| x == y).count(),
        same_t_other_prim: 0,
        near_origin: 0,
    }
}
