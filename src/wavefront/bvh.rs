//! The wavefront engine's own BVH for meshes: an 8-wide tree with uncompressed child boxes stored
//! as columns, and triangles copied into 8-lane blocks in traversal order. With `simd.rs`, the
//! only module that names `wide` types.
//!
//! ```text
//! build:    obvhs PLOC BVH2 + reinsertion (the CWBVH's own first steps, medium_build preset)
//!           → collapse: each wide node takes up to 8 BVH2 descendants, opening the largest
//!             one first; a subtree of ≤ LEAF_MAX triangles becomes a leaf (one block), and
//!             two leaves share a block when they fit and their union box adds no surface
//!             area (the two triangles of a wall), freeing a slot to open another child
//! closest:  one ray, all 8 child boxes in one f32x8 slab test (one FMA per plane:
//!           bound · (1/d) − origin · (1/d)), hit children near to far on a
//!           fixed stack (entries carry their entry distance, skipped once a closer hit is
//!           known); a leaf tests its 8 triangles in one f32x8 Möller–Trumbore
//! packets: camera rays, 8 neighbouring pixels at a time: each child box and each leaf
//!           triangle tested against the 8 rays in one f32x8 test, one node fetch and one
//!           child order for the packet; lanes that part (fewer than 4 enter a subtree, or a
//!           leaf holds more triangles than lanes enter it) go on one ray at a time
//! occluded: the same walk, no sorting, stops at the first blocker
//! ```
//!
//! Node (`Node`, 224 bytes, 32-aligned; 64-aligned 256-byte nodes measured no clear win, see
//! docs/PERFORMANCE.md): `bounds[axis][0]` = min, `bounds[axis][1]` = max of
//! the 8 children, one f32x8 each; `child[k]` = a node index, or `LEAF | block`, or `EMPTY`
//! (empty slots have min = +∞, max = −∞, which no ray enters). Block (`Block`, 320 bytes):
//! v0, e1, e2 x/y/z columns of 8 triangles and their `Scene::triangles` ids; unused lanes are
//! NaN (they never hit: every comparison with NaN is false) with id `NO_HIT`.
//!
//! Every lane of the triangle test is `geometry::intersect_triangle` with the same operations
//! in the same order, so each t is bit-equal to the scalar kernel's: the BVH only decides which
//! triangles are tested. Boxes are padded outward (`pad`) so that the kernel's edge slack
//! (u, v ≥ −EDGE_EPSILON) and the slab test's rounding never cull a triangle the kernel would
//! hit, for ray origins within about 100 box sizes of a box; from farther away the origin's
//! own rounding (about 2⁻²⁴·|origin|) can exceed the padding, in the fused slab test as in
//! the unfused one before it. Ties (two triangles at the same t: a shared edge, a corner of
//! two walls) go to the lowest triangle id, as in a brute-force loop in index order, so the
//! closest hit is brute force's. The exception is a triangle the ray grazes: its computed t is
//! off by about ε / sin θ and can lie before the entry of the box that holds it, which is then
//! pruned by a hit found first. In `tests/mesh_bvh.rs`, 1 of 8,000 grazing queries differs
//! (one ray at a time and in packets alike; 3 in an earlier tree), for a triangle with
//! |n·d| ≈ 2e-6; the tree then returns another real hit of the kernel. Which hit is found
//! first depends on the visiting order, so packets (the first entering lane's order) and one
//! ray may differ from each other on such a triangle.

use super::simd::{self, RayColumns, TriangleLanes};
use crate::geometry::{Hit, Ray, T_MIN, intersect_sphere};
use crate::scene::{NO_HIT, Scene, Triangle};
use glam::Vec3A;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::{BvhBuildParams, aabb::Aabb};
use std::time::{Duration, Instant};
use wide::f32x8;

/// Children per node and triangles per block.
pub const WIDTH: usize = 8;
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

/// `v` moved into memory advised for 2 MiB transparent huge pages (Linux, arrays of at least
/// 4 MiB), else `v` itself. A deep ray through a 1M-triangle tree touches
/// nodes and blocks spread over 65 MB: in 4 KiB pages that is a TLB miss at almost every
/// level, in 2 MiB pages 33 entries cover it all. Embree's BVH gets huge pages too: before
/// this, the `mesh_rays` process held 62 MB of `AnonHugePages` with Embree and none without.
/// With the kernel's THP mode at `madvise`, as on this machine, nothing else in raywave gets
/// them. The advice is only a hint: where the kernel declines, the copy behaves as before.
/// Measured in one process against a second tree without the advice: +2–4% on 1M-triangle
/// rays (docs/PERFORMANCE.md, "What was tried").
fn huge_pages<T: Copy>(v: Vec<T>) -> Vec<T> {
    #[cfg(target_os = "linux")]
    {
        /// Arrays at least this large go to memory advised for transparent huge pages.
        const HUGE_PAGE_MIN_BYTES: usize = 4 << 20;
        const HUGE: usize = 2 << 20;
        let bytes = std::mem::size_of_val(v.as_slice());
        if bytes >= HUGE_PAGE_MIN_BYTES {
            // glibc maps an allocation this large afresh (mmap), untouched, so advising it
            // before the copy lets its first page faults take huge pages; from an allocator
            // that reuses touched memory, the advice only lets khugepaged collapse it later.
            let mut out = Vec::with_capacity(v.len());
            let base = out.as_mut_ptr() as usize;
            let (start, end) = (base.next_multiple_of(HUGE), (base + bytes) & !(HUGE - 1));
            if end > start {
                // SAFETY: [start, end) lies inside `out`'s allocation, and MADV_HUGEPAGE only
                // changes how the kernel backs those pages, never their contents.
                unsafe {
                    libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
                }
            }
            out.extend_from_slice(&v);
            return out;
        }
    }
    v
}

/// A child slot of a wide node during the collapse: one BVH2 node, or, for a leaf, several
/// whose triangles share one block.
struct Kid {
    nodes: Vec<usize>,
    aabb: Aabb,
    count: u32,
}

/// The two leaf children whose merged box has the least surface area beyond their own two,
/// if one pair fits one block and the merge adds no area (ties: the first pair found).
fn best_merge(kids: &[Kid]) -> Option<(usize, usize)> {
    let mut best: Option<(f32, usize, usize)> = None;
    for i in 0..kids.len() {
        for j in i + 1..kids.len() {
            let (a, b) = (&kids[i], &kids[j]);
            if a.count + b.count > LEAF_MAX {
                continue;
            }
            let added = a.aabb.union(&b.aabb).half_area() - a.aabb.half_area() - b.aabb.half_area();
            if added <= 0.0 && best.is_none_or(|(least, _, _)| added < least) {
                best = Some((added, i, j));
            }
        }
    }
    best.map(|(_, i, j)| (i, j))
}

/// Outward padding of a box: covers the kernel's edge slack (a hit may lie EDGE_EPSILON · |e|
/// outside its triangle) and a few ulps of the slab test, with a wide margin.
fn pad(b: &Aabb) -> f32 {
    let extent = (b.max - b.min).max_element();
    let magnitude = b.min.abs().max(b.max.abs()).max_element();
    1e-5 * (extent + magnitude)
}

impl MeshBvh {
    /// Builds the tree over `scene.triangles` with obvhs's `medium_build` settings.
    pub fn new(scene: &Scene) -> MeshBvh {
        let start = Instant::now();
        let tris = &scene.triangles;
        let aabbs: Vec<Aabb> = tris
            .iter()
            .map(|t| {
                let mut b = Aabb::from_point(t.v0.into());
                b.extend((t.v0 + t.e1).into());
                b.extend((t.v0 + t.e2).into());
                b
            })
            .collect();
        let mut bvh = MeshBvh {
            nodes: Vec::new(),
            blocks: Vec::new(),
            root: EMPTY,
            depth: 0,
            build_time: Duration::ZERO,
        };
        if !tris.is_empty() {
            let p = BvhBuildParams::medium_build();
            let mut bvh2 = obvhs::ploc::PlocBuilder::with_capacity(aabbs.len()).build(
                p.ploc_search_distance,
                &aabbs,
                (0..aabbs.len() as u32).collect(),
                p.sort_precision,
                p.search_depth_threshold,
            );
            ReinsertionOptimizer::default().run(&mut bvh2, p.reinsertion_batch_ratio, None);
            bvh.collapse(&bvh2, tris);
            bvh.nodes = huge_pages(std::mem::take(&mut bvh.nodes));
            bvh.blocks = huge_pages(std::mem::take(&mut bvh.blocks));
        }
        bvh.build_time = start.elapsed();
        bvh
    }

    /// Turns obvhs's BVH2 into the 8-wide tree; triangles are copied leaf by leaf.
    fn collapse(&mut self, bvh2: &Bvh2, tris: &[Triangle]) {
        let n2 = &bvh2.nodes;
        // Triangles under every BVH2 node (children have higher indices than their parent in
        // a PLOC build, but reinsertion may move them, so count with an explicit post-order).
        let mut count = vec![0u32; n2.len()];
        let mut order = Vec::with_capacity(n2.len());
        let mut todo = vec![0usize];
        while let Some(i) = todo.pop() {
            order.push(i);
            if !n2[i].is_leaf() {
                let c = n2[i].first_index as usize;
                todo.extend([c, c + 1]);
            }
        }
        for &i in order.iter().rev() {
            count[i] = if n2[i].is_leaf() {
                n2[i].prim_count
            } else {
                let c = n2[i].first_index as usize;
                count[c] + count[c + 1]
            };
        }
        if count[0] <= LEAF_MAX {
            self.root = self.leaf(bvh2, &[0], tris);
            self.depth = 0;
            return;
        }
        let kid = |k: usize| Kid {
            nodes: vec![k],
            aabb: *n2[k].aabb(),
            count: count[k],
        };
        self.root = 0;
        self.nodes.push(empty_node());
        // (BVH2 node, wide node index, depth)
        let mut work = vec![(0usize, 0usize, 1usize)];
        while let Some((i, w, depth)) = work.pop() {
            self.depth = self.depth.max(depth);
            let c = n2[i].first_index as usize;
            let mut kids = vec![kid(c), kid(c + 1)];
            loop {
                // Open the largest child that is too big for a leaf while a slot is free.
                if kids.len() < WIDTH {
                    let open = kids
                        .iter()
                        .enumerate()
                        .filter(|(_, k)| k.count > LEAF_MAX && !n2[k.nodes[0]].is_leaf())
                        .max_by(|a, b| a.1.aabb.half_area().total_cmp(&b.1.aabb.half_area()))
                        .map(|(slot, _)| slot);
                    if let Some(slot) = open {
                        let k = kids.swap_remove(slot).nodes[0];
                        let c = n2[k].first_index as usize;
                        kids.extend([kid(c), kid(c + 1)]);
                        continue;
                    }
                }
                // Then merge two leaves into one block where that costs no more than both
                // apart (surface area heuristic: a ray enters a box with probability ∝ its
                // area, and a block test costs the same for 2 or 8 triangles); a freed slot
                // goes back to opening.
                let Some((i, j)) = best_merge(&kids) else {
                    break;
                };
                let b = kids.swap_remove(j);
                let a = &mut kids[i];
                a.nodes.extend(b.nodes);
                a.aabb = a.aabb.union(&b.aabb);
                a.count += b.count;
            }
            let mut node = empty_node();
            for (slot, k) in kids.iter().enumerate() {
                let b = &k.aabb;
                let p = pad(b);
                for axis in 0..3 {
                    let mut lo = node.bounds[axis][0].to_array();
                    let mut hi = node.bounds[axis][1].to_array();
                    lo[slot] = b.min[axis] - p;
                    hi[slot] = b.max[axis] + p;
                    node.bounds[axis][0] = f32x8::new(lo);
                    node.bounds[axis][1] = f32x8::new(hi);
                }
                node.child[slot] = if k.count <= LEAF_MAX {
                    self.leaf(bvh2, &k.nodes, tris)
                } else {
                    let index = self.nodes.len();
                    self.nodes.push(empty_node());
                    work.push((k.nodes[0], index, depth + 1));
                    index as u32
                };
            }
            self.nodes[w] = node;
        }
    }

    /// One block with the (≤ 8) triangles under BVH2 nodes `roots`; returns its leaf reference.
    fn leaf(&mut self, bvh2: &Bvh2, roots: &[usize], tris: &[Triangle]) -> u32 {
        let mut ids = Vec::with_capacity(WIDTH);
        let mut todo: Vec<usize> = roots.iter().rev().copied().collect();
        while let Some(k) = todo.pop() {
            let n = &bvh2.nodes[k];
            if n.is_leaf() {
                let first = n.first_index as usize;
                ids.extend_from_slice(
                    &bvh2.primitive_indices[first..first + n.prim_count as usize],
                );
            } else {
                let c = n.first_index as usize;
                todo.extend([c + 1, c]);
            }
        }
        self.blocks.push(Block::new(tris, &ids));
        LEAF | (self.blocks.len() - 1) as u32
    }

    /// Asks for the first cache lines of a child pushed on the stack, so that they are on
    /// their way by the time it is popped.
    #[inline(always)]
    fn prefetch(&self, child: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let p = if child & LEAF == 0 {
                self.nodes.as_ptr().wrapping_add(child as usize) as *const i8
            } else {
                self.blocks.as_ptr().wrapping_add((child & !LEAF) as usize) as *const i8
            };
            // SAFETY: SSE is part of x86_64's baseline, and a prefetch never faults, whatever
            // the address (EMPTY never reaches here).
            unsafe {
                _mm_prefetch::<_MM_HINT_T0>(p);
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64));
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(128));
            }
        }
    }

    /// Number of 8-wide nodes and of triangle blocks (for reports).
    pub fn size(&self) -> (usize, usize) {
        (self.nodes.len(), self.blocks.len())
    }

    /// Closest triangle hit in (T_MIN, tmax): `Hit::MISS` when none. The same t bits and
    /// triangle as testing every triangle with `intersect_triangle` in index order.
    pub fn closest_triangle(&self, ray: &Ray, tmax: f32, two_sided: bool) -> Hit {
        let r = RayLanes::new(ray);
        hit(self.closest_from(
            self.root,
            &r,
            (tmax, NO_HIT),
            two_sided,
            &mut Stack::new(self),
        ))
    }

    /// The closest hit of one ray in the subtree `start`, given the best (t, triangle) found
    /// so far (`(tmax, NO_HIT)` for none): the better of the two, as a pair. Inlined into its
    /// callers: as a call per ray it ran the primary set at 15 Mrays/s instead of 22, and with
    /// 12% more instructions (callgrind, incoherent rays; docs/PERFORMANCE.md).
    #[inline(always)]
    fn closest_from(
        &self,
        start: u32,
        r: &RayLanes,
        (mut best_t, mut best_prim): (f32, u32),
        two_sided: bool,
        stack: &mut Stack,
    ) -> (f32, u32) {
        let stack = &mut stack.0[..];
        let mut sp = 0;
        let mut cur = start;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let (mask, near) = r.boxes(node, best_t);
                if mask != 0 {
                    if mask.is_power_of_two() {
                        cur = node.child[mask.trailing_zeros() as usize];
                        continue;
                    }
                    let near = near.to_array();
                    if mask.count_ones() == 2 {
                        // The commonest case: push the far one, go on with the near one.
                        let a = mask.trailing_zeros() as usize;
                        let b = 31 - mask.leading_zeros() as usize;
                        let (first, second) = if near[b] < near[a] { (b, a) } else { (a, b) };
                        self.prefetch(node.child[second]);
                        stack[sp] = (node.child[second], near[second]);
                        sp += 1;
                        cur = node.child[first];
                        continue;
                    }
                    // Push far to near; go on with the nearest.
                    let (order, n) = sorted_far_to_near(mask, &near, &node.child);
                    for &(d, c) in &order[..n - 1] {
                        self.prefetch(c);
                        stack[sp] = (c, d);
                        sp += 1;
                    }
                    cur = order[n - 1].1;
                    continue;
                }
            } else if cur != EMPTY {
                let block = &self.blocks[(cur & !LEAF) as usize];
                (best_t, best_prim) = block_closest(block, r, (best_t, best_prim), two_sided);
            }
            // Pop the next entry that may still hold a closer hit.
            loop {
                if sp == 0 {
                    return (best_t, best_prim);
                }
                sp -= 1;
                if stack[sp].1 <= best_t {
                    cur = stack[sp].0;
                    break;
                }
            }
        }
    }

    /// True when a triangle blocks the ray in (T_MIN, tmax); stops at the first blocker.
    pub fn occluded_triangle(&self, ray: &Ray, tmax: f32, two_sided: bool) -> bool {
        self.occluded_in(ray, tmax, two_sided, &mut Stack::new(self))
    }

    /// [`Self::occluded_triangle`] with a stack from the caller.
    #[inline(always)]
    fn occluded_in(&self, ray: &Ray, tmax: f32, two_sided: bool, stack: &mut Stack) -> bool {
        let stack = &mut stack.0[..];
        let r = RayLanes::new(ray);
        let tmax8 = f32x8::splat(tmax);
        let mut sp = 0;
        let mut cur = self.root;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let (mask, _) = r.boxes(node, tmax);
                let mut m = mask;
                while m != 0 {
                    let k = m.trailing_zeros() as usize;
                    m &= m - 1;
                    self.prefetch(node.child[k]);
                    stack[sp] = (node.child[k], 0.0);
                    sp += 1;
                }
            } else if cur != EMPTY
                && triangles8_block(&self.blocks[(cur & !LEAF) as usize], &r, tmax8, two_sided)
            {
                return true;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            cur = stack[sp].0;
        }
    }

    /// Closest hit (triangles through the tree, then spheres, as `Accel::closest`) of every
    /// ray: writes t (`f32::INFINITY` on a miss) and the global primitive id (`NO_HIT`).
    pub fn closest_hits(
        &self,
        scene: &Scene,
        rays: &RayColumns,
        two_sided: bool,
        t_out: &mut [f32],
        prim_out: &mut [u32],
    ) {
        let mut stack = Stack::new(self);
        let (o, d, tmax) = cut(rays);
        let (t_out, prim_out) = (&mut t_out[..tmax.len()], &mut prim_out[..tmax.len()]);
        for i in 0..tmax.len() {
            let ray = ray_at(&o, &d, i);
            let r = RayLanes::new(&ray);
            let found = self.closest_from(self.root, &r, (tmax[i], NO_HIT), two_sided, &mut stack);
            let best = with_spheres(scene, &ray, found);
            t_out[i] = best.t;
            prim_out[i] = best.prim;
        }
    }

    /// Whether anything (spheres, then triangles through the tree) blocks every ray in
    /// (T_MIN, tmax), as `Accel::occluded`. Rays with tmax ≤ T_MIN cannot be blocked and are
    /// not traced (the shadow queue's dead lanes have tmax = 0).
    pub fn occluded(&self, scene: &Scene, rays: &RayColumns, two_sided: bool, out: &mut [bool]) {
        let mut stack = Stack::new(self);
        let (o, d, tmax) = cut(rays);
        for (i, blocked) in out[..tmax.len()].iter_mut().enumerate() {
            let tmax = tmax[i];
            #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must not be traced either
            if !(tmax > T_MIN) {
                *blocked = false;
                continue;
            }
            let ray = ray_at(&o, &d, i);
            *blocked = scene
                .spheres
                .iter()
                .any(|s| intersect_sphere(s, &ray, tmax) < tmax)
                || self.occluded_in(&ray, tmax, two_sided, &mut stack);
        }
    }
}

/// Below this many live lanes a packet splits: its lanes finish the subtree one ray at a time.
/// Embree's BVH8 traversal of 8-ray packets splits below 8 (its `switchThreshold`, 7). Here,
/// against one ray at a time on the peer camera rays (interleaved, 30 rounds): splitting below
/// 2 lanes 1.14–1.16× on 12k triangles, 0.96–0.98× on 1M; below 4, 1.12–1.13× and 1.01–1.04×;
/// below 8, 1.02–1.08× and 1.02–1.03× (docs/PERFORMANCE.md, "What was tried").
const PACKET_MIN_LANES: u32 = 4;

/// 8 rays in lanes (a packet of coherent rays: camera rays of neighbouring pixels), with what
/// the slab test needs. Lane k holds exactly `RayLanes::new(ray_k)`'s values, so every box and
/// triangle test of the packet is, lane by lane, the one-ray test bit for bit.
struct Packet {
    o: [f32x8; 3],
    d: [f32x8; 3],
    inv: [f32x8; 3],
    o_inv: [f32x8; 3],
    /// Per axis, all ones in the lanes whose 1/d has its sign bit set (they enter a box at its
    /// max bound): `RayLanes::near` lane by lane.
    negative: [f32x8; 3],
}

impl Packet {
    /// Rays `i..i + live` (live ≤ 8) of the columns; lanes past them get NaN rays (traced by
    /// nobody: they are never live).
    #[inline(always)]
    fn load(o: &[&[f32]; 3], d: &[&[f32]; 3], i: usize, live: usize) -> Packet {
        let col = |c: &[f32]| packet_lanes(c, i, live);
        let (o, d) = (o.map(col), d.map(col));
        // `RayLanes::new`'s operations on 8 lanes: |c| < 1e-18 becomes ±1e-18, then 1 / c.
        let tiny = f32x8::splat(1e-18);
        let sign = f32x8::splat(-0.0);
        let inv = d.map(|c| f32x8::ONE / c.abs().simd_lt(tiny).select(tiny | (c & sign), c));
        let negative = inv.map(|v| {
            let bits: wide::i32x8 = wide::bytemuck::cast(v);
            wide::bytemuck::cast(bits.simd_lt(wide::i32x8::ZERO))
        });
        Packet {
            o,
            d,
            o_inv: std::array::from_fn(|a| o[a] * inv[a]),
            inv,
            negative,
        }
    }

    /// Lane k as one ray, for the lanes that leave the packet: `RayLanes::new(ray_k)`, read
    /// from the packet's lanes instead of computed again.
    #[inline(always)]
    fn lane(&self, k: usize) -> RayLanes {
        let at = |v: &[f32x8; 3]| v.map(|c| f32x8::splat(lanes(&c)[k]));
        RayLanes {
            o: at(&self.o),
            d: at(&self.d),
            inv: at(&self.inv),
            o_inv: at(&self.o_inv),
            near: self.negative.map(|n| ((n.to_bitmask() >> k) & 1) as usize),
        }
    }

    /// Slab test of child box `k` of `node` against the 8 rays over [0, limit] (a lane with
    /// limit −∞ enters nothing): the mask of lanes that enter it, and their entry distances.
    /// Lane by lane `RayLanes::boxes`.
    #[inline(always)]
    fn child_box(&self, node: &Node, k: usize, limit: f32x8) -> (f32x8, f32x8) {
        let slab = |axis: usize| {
            let b = &node.bounds[axis];
            let lo = f32x8::splat(lanes(&b[0])[k]).mul_sub(self.inv[axis], self.o_inv[axis]);
            let hi = f32x8::splat(lanes(&b[1])[k]).mul_sub(self.inv[axis], self.o_inv[axis]);
            let neg = self.negative[axis];
            (neg.select(hi, lo), neg.select(lo, hi))
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        let near = nx.fast_max(ny).fast_max(nz).fast_max(f32x8::ZERO);
        let far = fx.fast_min(fy).fast_min(fz).fast_min(limit);
        (near.simd_le(far), near)
    }
}

/// The 8 lanes of a vector, in place.
#[inline(always)]
fn lanes(v: &f32x8) -> &[f32; WIDTH] {
    wide::bytemuck::cast_ref(v)
}

/// The packet traversal's stack: (child reference, entry distance of every lane, NaN in the
/// lanes that do not enter it, so that no comparison lets them in). Same bound as [`Stack`].
struct PacketStack(Vec<(u32, f32x8)>);

impl PacketStack {
    fn new(bvh: &MeshBvh) -> PacketStack {
        PacketStack(vec![(0, f32x8::ZERO); bvh.depth * (WIDTH - 1) + 1])
    }
}

/// Per-lane best (t, triangle) of a packet, and the limit a new hit must be below: t itself
/// before any hit (tmax), next_up(t) after one (ties then count, resolved by id).
struct PacketBest {
    t: f32x8,
    prim: [u32; WIDTH],
    limit: f32x8,
}

impl PacketBest {
    /// Lane k's (t, triangle), as one ray's traversal carries it.
    fn lane(&self, k: usize) -> (f32, u32) {
        (lanes(&self.t)[k], self.prim[k])
    }

    /// Lane k after one ray's traversal returned (t, prim) for it. Blends in registers: a
    /// lane written through memory and read back as a vector stalls store forwarding.
    #[inline(always)]
    fn set_lane(&mut self, k: usize, (t, prim): (f32, u32)) {
        let lane = MASK_LANES[1 << k];
        let limit = if prim == NO_HIT { t } else { t.next_up() };
        self.t = lane.select(f32x8::splat(t), self.t);
        self.limit = lane.select(f32x8::splat(limit), self.limit);
        self.prim[k] = prim;
    }
}

impl MeshBvh {
    /// Closest triangle hits of a packet of coherent rays (live lanes `live`, a bitmask): per
    /// lane the best (t, triangle), `(tmax, NO_HIT)` for a miss. The packet shares each node
    /// fetch and child order, and tests each child box and leaf triangle against its 8 rays
    /// at once; once fewer than `PACKET_MIN_LANES` lanes enter a subtree, or a leaf holds more
    /// triangles than lanes enter it, those lanes go on one ray at a time. Every test is, lane
    /// by lane, the one-ray test, and (t, id) is minimised as a pair, so each lane gets brute
    /// force's answer, as one ray does; the children are visited in the first entering lane's
    /// order, not each lane's, so where one ray differs from brute force (a grazing hit pruned
    /// by its box's entry distance, module docs) the packet may differ from one ray too.
    fn closest_packet(
        &self,
        p: &Packet,
        tmax: f32x8,
        live: u32,
        two_sided: bool,
        stack: &mut PacketStack,
        one: &mut Stack,
    ) -> PacketBest {
        let mut best = PacketBest {
            t: tmax,
            prim: [NO_HIT; WIDTH],
            limit: tmax,
        };
        let stack = &mut stack.0[..];
        let mut sp = 0;
        let mut cur = self.root;
        // Lanes that enter `cur` (live lanes at the root, as one ray's traversal starts there).
        let mut active = live;
        loop {
            if active.count_ones() < PACKET_MIN_LANES
                || cur & LEAF != 0 && cur != EMPTY && {
                    let block = &self.blocks[(cur & !LEAF) as usize];
                    block_len(block) > active.count_ones()
                }
            {
                // One ray at a time through the rest of this subtree.
                let mut m = active;
                while m != 0 {
                    let k = m.trailing_zeros() as usize;
                    m &= m - 1;
                    let found = self.closest_from(cur, &p.lane(k), best.lane(k), two_sided, one);
                    best.set_lane(k, found);
                }
            } else if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let bits = &MASK_LANES[active as usize];
                let limit = bits.select(best.t, f32x8::splat(f32::NEG_INFINITY));
                let mut order = [(0.0f32, 0u32); WIDTH];
                let mut entries = [f32x8::ZERO; WIDTH];
                let mut n = 0;
                for k in 0..WIDTH {
                    let child = node.child[k];
                    if child == EMPTY {
                        break;
                    }
                    let (enter, near) = p.child_box(node, k, limit);
                    let mask = enter.to_bitmask();
                    if mask != 0 {
                        // Children in order of the first entering lane's entry distance.
                        let key = lanes(&near)[mask.trailing_zeros() as usize];
                        let entry = enter.select(near, f32x8::splat(f32::NAN));
                        let mut j = n;
                        while j > 0 && order[j - 1].0 < key {
                            order[j] = order[j - 1];
                            entries[j] = entries[j - 1];
                            j -= 1;
                        }
                        order[j] = (key, child);
                        entries[j] = entry;
                        n += 1;
                    }
                }
                if n > 0 {
                    for j in 0..n - 1 {
                        stack[sp] = (order[j].1, entries[j]);
                        sp += 1;
                    }
                    cur = order[n - 1].1;
                    active = entries[n - 1].simd_le(best.t).to_bitmask();
                    continue;
                }
            } else if cur != EMPTY {
                let block = &self.blocks[(cur & !LEAF) as usize];
                let bits = &MASK_LANES[active as usize];
                for j in 0..block_len(block) as usize {
                    let prim = block.prim[j];
                    let at = |c: &[f32x8; 3]| c.map(|v| f32x8::splat(lanes(&v)[j]));
                    let tri = simd::TriangleLanes {
                        o: p.o,
                        d: p.d,
                        v0: at(&block.v0),
                        e1: at(&block.e1),
                        e2: at(&block.e2),
                    };
                    let limit = bits.select(best.limit, f32x8::splat(f32::NEG_INFINITY));
                    let t = simd::moller_trumbore8(&tri, limit, two_sided);
                    let hit = t.simd_lt(limit);
                    if hit.any() {
                        // A tie with the best so far goes to the lower id; else t is closer.
                        let tie = hit & t.simd_eq(best.t);
                        let mut take = (hit & !tie).to_bitmask();
                        let mut ties = tie.to_bitmask();
                        while ties != 0 {
                            let k = ties.trailing_zeros() as usize;
                            ties &= ties - 1;
                            if prim < best.prim[k] {
                                take |= 1 << k;
                            }
                        }
                        let take_lanes = MASK_LANES[take as usize];
                        best.t = take_lanes.select(t, best.t);
                        // next_up(t) as bits + 1: t > T_MIN ≥ 0 here (so t is positive, not
                        // −0.0), and finite (t < limit).
                        const _: () = assert!(T_MIN >= 0.0);
                        let up: f32x8 = wide::bytemuck::cast(
                            wide::bytemuck::cast::<f32x8, wide::u32x8>(t) + wide::u32x8::ONE,
                        );
                        best.limit = take_lanes.select(up, best.limit);
                        while take != 0 {
                            let k = take.trailing_zeros() as usize;
                            take &= take - 1;
                            best.prim[k] = prim;
                        }
                    }
                }
            }
            // Pop the next entry that some lane may still find a closer hit in.
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                let (child, entry) = stack[sp];
                active = entry.simd_le(best.t).to_bitmask();
                if active != 0 {
                    cur = child;
                    break;
                }
            }
        }
    }

    /// [`Self::closest_hits`] for coherent rays (camera rays: 8 consecutive rays are
    /// neighbouring pixels, or samples of them), traced in packets of 8 (`closest_packet`).
    /// Brute force's answers, as [`Self::closest_hits`] gives, with the same grazing exception.
    pub fn closest_hits_coherent(
        &self,
        scene: &Scene,
        rays: &RayColumns,
        two_sided: bool,
        t_out: &mut [f32],
        prim_out: &mut [u32],
    ) {
        if self.root & LEAF != 0 {
            // A tree of one leaf (or none) has nothing to share.
            return self.closest_hits(scene, rays, two_sided, t_out, prim_out);
        }
        let (mut stack, mut one) = (PacketStack::new(self), Stack::new(self));
        let (o, d, tmax) = cut(rays);
        let (t_out, prim_out) = (&mut t_out[..tmax.len()], &mut prim_out[..tmax.len()]);
        for i in (0..tmax.len()).step_by(WIDTH) {
            let live = (tmax.len() - i).min(WIDTH);
            let p = Packet::load(&o, &d, i, live);
            let tmax8 = packet_lanes(tmax, i, live);
            let best =
                self.closest_packet(&p, tmax8, (1 << live) - 1, two_sided, &mut stack, &mut one);
            for k in 0..live {
                let best = with_spheres(scene, &ray_at(&o, &d, i + k), best.lane(k));
                t_out[i + k] = best.t;
                prim_out[i + k] = best.prim;
            }
        }
    }
}

/// `c[i..i + live]` in lanes 0..live (live ≤ 8), NaN in the lanes after them.
#[inline(always)]
fn packet_lanes(c: &[f32], i: usize, live: usize) -> f32x8 {
    match c.get(i..i + WIDTH) {
        // A full packet is one vector load.
        Some(lanes) if live == WIDTH => {
            f32x8::from(<[f32; WIDTH]>::try_from(lanes).expect("WIDTH lanes"))
        }
        _ => f32x8::new(std::array::from_fn(|k| {
            if k < live { c[i + k] } else { f32::NAN }
        })),
    }
}

/// Number of triangles in a block: its lanes before the first unused one (id `NO_HIT`). From
/// the ids, not the vertices: a triangle built in code may have a NaN vertex.
#[inline(always)]
fn block_len(block: &Block) -> u32 {
    let ids: wide::i32x8 = wide::bytemuck::cast(block.prim);
    let unused = ids.simd_eq(wide::i32x8::splat(NO_HIT as i32)).to_bitmask();
    (unused | 1 << WIDTH).trailing_zeros()
}

/// Lane masks by bitmask: `MASK_LANES[m]` is all ones in lane k where bit k of m is set.
static MASK_LANES: [f32x8; 256] = {
    let mut table = [f32x8::ZERO; 256];
    let mut m = 0;
    while m < 256 {
        let mut lanes = [0.0f32; WIDTH];
        let mut k = 0;
        while k < WIDTH {
            if m & (1 << k) != 0 {
                lanes[k] = f32::from_bits(u32::MAX);
            }
            k += 1;
        }
        table[m] = f32x8::new(lanes);
        m += 1;
    }
    table
};

/// The closer of the tree's best (t, triangle) for a ray (`(tmax, NO_HIT)` when it found none)
/// and the scene's spheres, tested after the tree as `Accel::closest` does (sphere ids follow
/// the triangles'); `Hit::MISS` when neither is hit.
#[inline(always)]
fn with_spheres(scene: &Scene, ray: &Ray, (mut t, mut prim): (f32, u32)) -> Hit {
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

/// The origin, direction and tmax columns, each cut to the number of rays, so that indexing
/// them below that number needs no bounds checks.
#[allow(clippy::type_complexity)]
fn cut<'a>(rays: &RayColumns<'a>) -> ([&'a [f32]; 3], [&'a [f32]; 3], &'a [f32]) {
    let n = rays.len();
    (
        rays.origin.map(|c| &c[..n]),
        rays.direction.map(|c| &c[..n]),
        &rays.tmax[..n],
    )
}

#[inline(always)]
fn ray_at(o: &[&[f32]; 3], d: &[&[f32]; 3], i: usize) -> Ray {
    Ray {
        origin: glam::Vec3::new(o[0][i], o[1][i], o[2][i]),
        direction: glam::Vec3::new(d[0][i], d[1][i], d[2][i]),
    }
}

/// The traversal stack: (child reference, entry distance; 0 for occlusion). Sized by the tree:
/// a node leaves at most 7 children on it (8 pushed, one popped at once, in `occluded_in`), so
/// 7 · depth + 1 entries always suffice, however deep a degenerate mesh makes the tree. One is
/// allocated per batch, not per ray.
struct Stack(Vec<(u32, f32)>);

impl Stack {
    fn new(bvh: &MeshBvh) -> Stack {
        Stack(vec![(0, 0.0); bvh.depth * (WIDTH - 1) + 1])
    }
}

fn empty_node() -> Node {
    Node {
        bounds: [[f32x8::splat(f32::INFINITY), f32x8::splat(f32::NEG_INFINITY)]; 3],
        child: [EMPTY; WIDTH],
    }
}

/// One ray splatted over 8 lanes, with what the slab test needs.
struct RayLanes {
    o: [f32x8; 3],
    d: [f32x8; 3],
    /// 1 / d, with |d| raised to at least 1e-18 (sign kept), so that an axis-parallel ray never
    /// makes 0 · ∞ = NaN in the slab test. A NaN direction stays NaN and, since `fast_max` and
    /// `fast_min` return their right operand on NaN, enters every box: the answer is still right
    /// (every triangle test misses on NaN), only slow; no valid scene makes such a ray.
    inv: [f32x8; 3],
    /// origin · inv, so that a slab distance is one fused (bound · inv − origin · inv).
    o_inv: [f32x8; 3],
    /// Per axis, which bound is entered first: 0 (min) for d ≥ 0, 1 (max) for d < 0.
    near: [usize; 3],
}

impl RayLanes {
    #[inline(always)]
    fn new(ray: &Ray) -> RayLanes {
        // The three axes at once in one SSE register: one division, no branches. Lane by
        // lane the same operations as the scalar `if |c| < 1e-18 { ±1e-18 } else { c }`,
        // then 1 / c (a NaN compares false and stays NaN).
        let (o, d) = (Vec3A::from(ray.origin), Vec3A::from(ray.direction));
        let tiny = Vec3A::splat(1e-18);
        let inv = Vec3A::ONE / Vec3A::select(d.abs().cmplt(tiny), tiny.copysign(d), d);
        let o_inv = (o * inv).to_array();
        let negative = inv.is_negative_bitmask();
        RayLanes {
            o: o.to_array().map(f32x8::splat),
            d: d.to_array().map(f32x8::splat),
            inv: inv.to_array().map(f32x8::splat),
            o_inv: o_inv.map(f32x8::splat),
            near: std::array::from_fn(|a| ((negative >> a) & 1) as usize),
        }
    }

    /// Slab test of the 8 child boxes over [0, tmax]: the mask of boxes entered, and where.
    #[inline(always)]
    fn boxes(&self, node: &Node, tmax: f32) -> (u32, f32x8) {
        let slab = |axis: usize| {
            let b = &node.bounds[axis];
            let n = self.near[axis];
            (
                b[n].mul_sub(self.inv[axis], self.o_inv[axis]),
                b[1 - n].mul_sub(self.inv[axis], self.o_inv[axis]),
            )
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        let near = nx.fast_max(ny).fast_max(nz).fast_max(f32x8::ZERO);
        let far = fx.fast_min(fy).fast_min(fz).fast_min(f32x8::splat(tmax));
        (near.simd_le(far).to_bitmask(), near)
    }
}

/// The hit children of a node (`mask`), far to near by their entry distance `near`: (entry
/// distance, child reference) pairs, and how many.
#[inline(always)]
fn sorted_far_to_near(
    mask: u32,
    near: &[f32; WIDTH],
    child: &[u32; WIDTH],
) -> ([(f32, u32); WIDTH], usize) {
    let mut order = [(0.0f32, 0u32); WIDTH];
    let mut n = 0;
    let mut m = mask;
    while m != 0 {
        let k = m.trailing_zeros() as usize;
        m &= m - 1;
        let mut j = n;
        while j > 0 && order[j - 1].0 < near[k] {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = (near[k], child[k]);
        n += 1;
    }
    (order, n)
}

/// One ray against the 8 triangles of a block, given the best (t, triangle) so far: the better
/// of the two. Once something is hit, ties count too: (t, id) is minimised as a pair, so the
/// answer is brute force's (the lowest id among the closest), whatever the order the tree
/// visits the triangles in.
#[inline(always)]
fn block_closest(
    block: &Block,
    r: &RayLanes,
    (mut best_t, mut best_prim): (f32, u32),
    two_sided: bool,
) -> (f32, u32) {
    let limit = if best_prim == NO_HIT {
        best_t
    } else {
        best_t.next_up()
    };
    let limit8 = f32x8::splat(limit);
    let t = triangles8(block, r, limit8, two_sided);
    let mut m = t.simd_lt(limit8).to_bitmask();
    if m != 0 {
        let ts = t.to_array();
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            let prim = block.prim[k];
            if ts[k] < best_t || (ts[k] == best_t && prim < best_prim) {
                best_t = ts[k];
                best_prim = prim;
            }
        }
    }
    (best_t, best_prim)
}

/// Möller–Trumbore for one ray against the 8 triangles of a block; lane k equals
/// `intersect_triangle(tri_k, ray, tmax_k, two_sided)`: `simd::moller_trumbore8` with the ray
/// splatted and the triangles in columns.
#[inline(always)]
fn triangles8(b: &Block, r: &RayLanes, tmax: f32x8, two_sided: bool) -> f32x8 {
    simd::moller_trumbore8(&b.lanes(r), tmax, two_sided)
}

/// True when a triangle of the block blocks the ray: `triangles8(..) < tmax` in some lane, with
/// `simd::moller_trumbore8_blocks`'s early exits.
#[inline(always)]
fn triangles8_block(b: &Block, r: &RayLanes, tmax: f32x8, two_sided: bool) -> bool {
    simd::moller_trumbore8_blocks(&b.lanes(r), tmax, two_sided) != 0
}

/// Lane-level entry points for tests: one ray against up to 8 triangles, as in a leaf.
pub mod lanes {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn kid(min: [f32; 3], max: [f32; 3], count: u32) -> Kid {
        Kid {
            nodes: vec![0],
            aabb: Aabb::new(glam::Vec3A::from(min), glam::Vec3A::from(max)),
            count,
        }
    }

    /// Leaves merge only when they fit one block and their union adds no surface area, and
    /// the pair that adds least goes first.
    #[test]
    fn leaves_merge_only_when_the_union_adds_no_area() {
        // Two halves of one wall (same box): merge. A box inside another: merge.
        let wall = [0.0, 0.0, 0.0];
        let (a, b) = (kid(wall, [1.0, 1.0, 0.0], 1), kid(wall, [1.0, 1.0, 0.0], 1));
        assert_eq!(best_merge(&[a, b]), Some((0, 1)));
        let (outer, inner) = (kid([0.0; 3], [2.0; 3], 3), kid([0.5; 3], [1.0; 3], 5));
        assert_eq!(best_merge(&[outer, inner]), Some((0, 1)));
        // Too many triangles for one block: no merge, however the boxes lie.
        let (outer, inner) = (kid([0.0; 3], [2.0; 3], 4), kid([0.5; 3], [1.0; 3], 5));
        assert_eq!(best_merge(&[outer, inner]), None);
        // Two boxes apart: the union is larger than both; no merge.
        let (left, right) = (kid([0.0; 3], [1.0; 3], 1), kid([3.0; 3], [4.0; 3], 1));
        assert_eq!(best_merge(&[left, right]), None);
        // Of two candidate pairs, the one that adds least (here: most negative) goes first.
        let kids = [
            kid([0.0; 3], [4.0; 3], 2),
            kid([3.0; 3], [4.0; 3], 2),
            kid([0.0; 3], [4.0; 3], 2),
        ];
        assert_eq!(best_merge(&kids), Some((0, 2)));
    }
}
