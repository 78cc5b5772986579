//! The wavefront engine's own BVH for meshes: an 8-wide tree with uncompressed child boxes stored
//! as columns, and triangles copied into 8-lane blocks in traversal order.
//!
//! ```text
//! build:    obvhs PLOC BVH2 + reinsertion (the CWBVH's own first steps, medium_build preset)
//!           → collapse: each wide node takes up to 8 BVH2 descendants, opening the largest
//!             one first; a subtree of ≤ LEAF_MAX triangles becomes a leaf (one block), and
//!             two leaves share a block when they fit and their union box adds no surface
//!             area (the two triangles of a wall), freeing a slot to open another child
//!                                                                           build.rs, memory.rs
//! closest:  one ray, all 8 child boxes in one f32x8 slab test (one FMA per plane:
//!           bound · (1/d) − origin · (1/d)), hit children near to far on a
//!           fixed stack (entries carry their entry distance, skipped once a closer hit is
//!           known); a leaf tests its 8 triangles in one f32x8 Möller–Trumbore    traverse.rs
//! packets: camera rays, 8 neighbouring pixels at a time: each child box and each leaf
//!           triangle tested against the 8 rays in one f32x8 test, one node fetch and one
//!           child order for the packet; lanes that part (fewer than 4 enter a subtree, or a
//!           leaf holds more triangles than lanes enter it) go on one ray at a time  packet.rs
//! occluded: the same walk, no sorting, stops at the first blocker               traverse.rs
//! ```
//!
//! Node (`Node`, 224 bytes, 32-aligned; 64-aligned 256-byte nodes measured no clear win, see
//! docs/TRIED.md): `bounds[axis][0]` = min, `bounds[axis][1]` = max of
//! the 8 children, one f32x8 each; `child[k]` = a node index, or `LEAF | block`, or `EMPTY`
//! (empty slots have min = +∞, max = −∞, which no ray enters). Block (`Block`, 320 bytes):
//! v0, e1, e2 x/y/z columns of 8 triangles and their `Scene::triangles` ids; unused lanes are
//! NaN (they never hit: every comparison with NaN is false) with id `NO_HIT`.
//!
//! Every lane of the triangle test is `geometry::intersect_triangle` with the same operations
//! in the same order, so each t is bit-equal to the scalar kernel's: the BVH only decides which
//! triangles are tested. Boxes are padded outward (`build::pad`) so that the kernel's edge slack
//! (u, v ≥ −EDGE_EPSILON) and the slab test's rounding never cull a triangle the kernel would
//! hit, for ray origins within about 100 box sizes of a box (from farther away the origin's
//! own rounding, about 2⁻²⁴·|origin|, can exceed the padding). Ties (two triangles at the same
//! t: a shared edge, a corner of two walls) go to the lowest triangle id (`geometry::closer`
//! minimises the pair (t, id)), as in a brute-force loop, so the closest hit is brute force's.
//!
//! # The grazing exception
//!
//! The one case where the tree's answer is not brute force's is a triangle the ray grazes: its
//! computed t is off by about ε / sin θ and can lie before the entry of the box that holds it,
//! which is then pruned by a hit found first. In `tests/kernels/mesh_bvh.rs`, 1 of 8,000 grazing
//! queries differs (one ray at a time and in packets alike; every difference measured was at
//! |n·d| ≤ 1.5e-5), for a triangle with |n·d| ≈ 2e-6. The test
//! holds every difference to that: brute force's hit grazes (|n·d| < 1e-3), and the tree's
//! answer is another real hit of the kernel. Which hit is found first depends on the visiting
//! order, so packets (the first entering lane's order) and one ray may differ from each other
//! on such a triangle. Wherever the rest of the engine and its docs say "the grazing
//! exception", they mean this paragraph.

mod build;
mod memory;
mod packet;
mod traverse;

use super::simd::{RayColumns, TriangleLanes};
use crate::render::geometry::{Hit, Ray, T_MIN, intersect_sphere};
use crate::render::scene::{NO_HIT, Scene, Triangle};
use crate::render::wavefront::batch::HitRays;
use crate::render::wavefront::cost::{Costs, Counter};
use crate::render::wavefront::lanes::{LANES, cast, f32x8, i32x8, set_bits};
use std::time::Duration;
pub use traverse::Stack;
use traverse::{RayLanes, triangles8, triangles8_block};

/// Children per node and triangles per block: the lane count.
pub const WIDTH: usize = LANES;
/// Largest subtree made into a leaf: one block.
const LEAF_MAX: u32 = 8;
/// Child reference bit for a leaf (its block index in the low bits).
const LEAF: u32 = 1 << 31;
/// An unused child slot.
const EMPTY: u32 = u32::MAX;

/// An 8-wide node: the children's boxes as columns, then the children.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Node {
    bounds: [[f32x8; 2]; 3],
    child: [u32; WIDTH],
}

impl Node {
    /// A node with every slot empty: (+∞, −∞) boxes that no ray enters.
    fn empty() -> Node {
        Node {
            bounds: [[f32x8::splat(f32::INFINITY), f32x8::splat(f32::NEG_INFINITY)]; 3],
            child: [EMPTY; WIDTH],
        }
    }
}

/// 8 triangles as columns (v0, e1, e2; x, y, z) and their scene ids.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Block {
    v0: [f32x8; 3],
    e1: [f32x8; 3],
    e2: [f32x8; 3],
    prim: [u32; WIDTH],
}

impl Block {
    /// The block's triangles against one ray, as Möller–Trumbore's operands.
    #[inline(always)]
    fn lanes(&self, r: &RayLanes) -> TriangleLanes {
        TriangleLanes {
            o: r.o,
            d: r.d,
            v0: self.v0,
            e1: self.e1,
            e2: self.e2,
        }
    }

    /// Number of triangles in the block: its lanes before the first unused one (id `NO_HIT`).
    /// From the ids, not the vertices: a triangle built in code may have a NaN vertex.
    #[inline(always)]
    fn len(&self) -> u32 {
        let unused = cast::<_, i32x8>(self.prim)
            .simd_eq(i32x8::splat(NO_HIT as i32))
            .to_bitmask();
        (unused | 1 << WIDTH).trailing_zeros()
    }

    /// Triangles `tris[ids[k]]` in lanes k < ids.len() (at most 8); NaN lanes after them.
    fn new(tris: &[Triangle], ids: &[u32]) -> Block {
        debug_assert!(ids.len() <= WIDTH);
        let col = |f: fn(&Triangle) -> f32| {
            f32x8::new(std::array::from_fn(|k| {
                ids.get(k).map_or(f32::NAN, |&id| f(&tris[id as usize]))
            }))
        };
        Block {
            v0: [col(|t| t.v0.x), col(|t| t.v0.y), col(|t| t.v0.z)],
            e1: [col(|t| t.e1.x), col(|t| t.e1.y), col(|t| t.e1.z)],
            e2: [col(|t| t.e2.x), col(|t| t.e2.y), col(|t| t.e2.z)],
            prim: std::array::from_fn(|k| ids.get(k).copied().unwrap_or(NO_HIT)),
        }
    }
}

/// The wavefront engine's mesh BVH (see the module docs for the layout).
pub struct MeshBvh {
    nodes: Vec<Node>,
    blocks: Vec<Block>,
    /// `EMPTY` without triangles, a leaf reference for ≤ LEAF_MAX of them, else node 0.
    root: u32,
    /// Depth of the wide tree (the root node is depth 1).
    pub depth: usize,
    /// Wall time of the build (BVH2, collapse, triangle copy).
    pub build_time: Duration,
}

impl MeshBvh {
    /// Number of 8-wide nodes and of triangle blocks (for reports).
    pub fn size(&self) -> (usize, usize) {
        (self.nodes.len(), self.blocks.len())
    }

    /// Closest hit (triangles through the tree, then spheres, as `Accel::closest`) of every
    /// ray: writes t (`f32::INFINITY` on a miss) and the global primitive id (`NO_HIT`). Each
    /// ray's nodes, leaves and primitive tests are added to `costs` (`cost::NoCount`: nothing
    /// is counted, and no counting code runs).
    pub fn closest_hits<S: Costs>(
        &self,
        scene: &Scene,
        rays: &RayColumns,
        two_sided: bool,
        t_out: &mut [f32],
        prim_out: &mut [u32],
        costs: &mut S,
    ) {
        let mut stack = Stack::new(self);
        let rays = cut(rays);
        let n = rays.len();
        let (t_out, prim_out) = (&mut t_out[..n], &mut prim_out[..n]);
        for i in 0..n {
            let ray = rays.ray(i);
            let r = RayLanes::new(&ray);
            let best = (rays.tmax[i], NO_HIT);
            let mut c = S::Counter::default();
            let found = self.closest_from(self.root, &r, best, two_sided, &mut stack, &mut c);
            let best = with_spheres(scene, &ray, found, &mut c);
            costs.add(i, c);
            t_out[i] = best.t;
            prim_out[i] = best.prim;
        }
    }

    /// [`Self::closest_hits`] for coherent rays (camera rays: 8 consecutive rays are
    /// neighbouring pixels, or samples of them), traced in packets of 8 (`packet.rs`).
    /// Brute force's answers, as [`Self::closest_hits`] gives, but for the grazing exception
    /// (module docs). A ray of a packet is counted for the nodes and leaves it is active in.
    pub fn closest_hits_coherent<S: Costs>(
        &self,
        scene: &Scene,
        rays: &RayColumns,
        two_sided: bool,
        t_out: &mut [f32],
        prim_out: &mut [u32],
        costs: &mut S,
    ) {
        if self.root & LEAF != 0 {
            // A tree of one leaf (or none) has nothing to share.
            return self.closest_hits(scene, rays, two_sided, t_out, prim_out, costs);
        }
        let mut walk = packet::Walk::new(self, two_sided);
        let rays = cut(rays);
        let n = rays.len();
        let (t_out, prim_out) = (&mut t_out[..n], &mut prim_out[..n]);
        for i in (0..n).step_by(WIDTH) {
            let live = (n - i).min(WIDTH);
            let mut counts = [S::Counter::default(); WIDTH];
            let best = walk.closest(&rays, i, live, &mut counts);
            for k in 0..live {
                let best = with_spheres(scene, &rays.ray(i + k), best.lane(k), &mut counts[k]);
                costs.add(i + k, counts[k]);
                t_out[i + k] = best.t;
                prim_out[i + k] = best.prim;
            }
        }
    }

    /// Whether anything (spheres, then triangles through the tree) blocks every ray in
    /// (T_MIN, tmax), as `Accel::occluded`. Rays with tmax ≤ T_MIN cannot be blocked and are
    /// not traced (the shadow queue's dead lanes have tmax = 0); each traced ray's work is
    /// added to `costs`.
    ///
    /// (An occluder cache, a ray after a blocked one testing the leaf that blocked that one
    /// first, cost 6.6% more instructions on the gate's mesh tile: docs/TRIED.md, "The mesh BVH".)
    pub fn occluded<S: Costs>(
        &self,
        scene: &Scene,
        rays: &RayColumns,
        two_sided: bool,
        out: &mut [bool],
        costs: &mut S,
    ) {
        let mut stack = Stack::new(self);
        let rays = cut(rays);
        for (i, blocked) in out[..rays.len()].iter_mut().enumerate() {
            let tmax = rays.tmax[i];
            #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must not be traced either
            if !(tmax > T_MIN) {
                *blocked = false;
                continue;
            }
            let mut c = S::Counter::default();
            *blocked = self.ray_occluded(scene, &rays.ray(i), tmax, two_sided, &mut stack, &mut c);
            costs.add(i, c);
        }
    }

    /// The `live` lanes of one ray per hit (`simd::hit_shadow_rays`) that something blocks, as
    /// a bit mask: lane k is what [`Self::occluded`] answers for that ray in a queue, its work
    /// added to `costs` at `i0 + k`. The hard-shadow stage walks its rays with this, unqueued.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn hit_rays_occluded<A: AsRef<[f32]>, S: Costs>(
        &self,
        scene: &Scene,
        rays: &HitRays<A>,
        live: u32,
        two_sided: bool,
        stack: &mut Stack,
        i0: usize,
        costs: &mut S,
    ) -> u32 {
        let mut blocked = 0;
        for k in set_bits(live) {
            let s = rays.lane(k);
            #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must not be traced either
            if !(s.tmax > T_MIN) {
                continue;
            }
            let mut c = S::Counter::default();
            if self.ray_occluded(scene, &s.ray, s.tmax, two_sided, stack, &mut c) {
                blocked |= 1 << k;
            }
            costs.add(i0 + k, c);
        }
        blocked
    }

    /// A traversal stack for [`Self::hit_rays_occluded`], deep enough for any walk of this tree.
    pub fn stack(&self) -> Stack {
        Stack::new(self)
    }

    /// Whether anything blocks one ray in (T_MIN, tmax): the spheres first, then the triangles
    /// through the tree; `c` counts the spheres tested and the walk.
    #[inline(always)]
    fn ray_occluded<C: Counter>(
        &self,
        scene: &Scene,
        ray: &Ray,
        tmax: f32,
        two_sided: bool,
        stack: &mut Stack,
        c: &mut C,
    ) -> bool {
        if scene.spheres.iter().any(|s| {
            c.tests(1);
            crate::render::geometry::sphere_blocks(s, ray, tmax)
        }) {
            return true;
        }
        self.blocker(&RayLanes::new(ray), tmax, two_sided, stack, c) != EMPTY
    }
}

/// The closer of the tree's best (t, triangle) for a ray (`(tmax, NO_HIT)` when it found none)
/// and the scene's spheres, tested after the tree as `Accel::closest` does (sphere ids follow
/// the triangles'); `Hit::MISS` when neither is hit.
#[inline(always)]
fn with_spheres<C: Counter>(
    scene: &Scene,
    ray: &Ray,
    (mut t, mut prim): (f32, u32),
    c: &mut C,
) -> Hit {
    c.tests(scene.spheres.len() as u32);
    let base = scene.triangles.len() as u32;
    for (k, s) in scene.spheres.iter().enumerate() {
        let ts = intersect_sphere(s, ray, t);
        if ts < t {
            t = ts;
            prim = base + k as u32;
        }
    }
    hit((t, prim))
}

/// A traversal's best (t, triangle) as a `Hit`: `Hit::MISS` when it found none.
#[inline(always)]
fn hit((t, prim): (f32, u32)) -> Hit {
    if prim == NO_HIT {
        Hit::MISS
    } else {
        Hit { t, prim }
    }
}

/// The columns, each cut to the number of rays, so that indexing them below that number needs
/// no bounds checks.
#[inline(always)]
fn cut<'a>(rays: &RayColumns<'a>) -> RayColumns<'a> {
    let n = rays.len();
    RayColumns {
        origin: rays.origin.map(|c| &c[..n]),
        direction: rays.direction.map(|c| &c[..n]),
        tmax: &rays.tmax[..n],
    }
}

/// Lane-level entry points for tests: one ray against up to 8 triangles, as in a leaf.
pub mod arrays {
    use super::*;

    fn block(tris: &[Triangle]) -> Block {
        assert!(tris.len() <= WIDTH);
        let ids: Vec<u32> = (0..tris.len() as u32).collect();
        Block::new(tris, &ids)
    }

    /// The leaf's closest-hit kernel: lane k is t for `tris[k]` (∞ for a miss or no triangle).
    pub fn triangles(tris: &[Triangle], ray: &Ray, tmax: f32, two_sided: bool) -> [f32; WIDTH] {
        triangles8(
            &block(tris),
            &RayLanes::new(ray),
            f32x8::splat(tmax),
            two_sided,
        )
        .to_array()
    }

    /// The leaf's occlusion kernel: does one of the triangles block the ray?
    pub fn blocks(tris: &[Triangle], ray: &Ray, tmax: f32, two_sided: bool) -> bool {
        triangles8_block(
            &block(tris),
            &RayLanes::new(ray),
            f32x8::splat(tmax),
            two_sided,
        )
    }
}
