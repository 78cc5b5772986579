//! One ray at a time through the tree: the closest hit and occlusion, and the leaf tests
//! (one ray against the 8 triangles of a block).
//!
//! ```text
//! closest:  node → slab test of its 8 child boxes over [0, best t]
//!           one child hit: go on with it; two: push the far one; more: push far to near
//!           leaf  → Möller–Trumbore against its 8 triangles, keep the least (t, id)
//!           pop entries until one starts before the best t
//! occluded: node → go on with the last child hit, push the others; leaf → stop at the first
//!           blocker
//! ```

use super::{Block, EMPTY, LEAF, MeshBvh, Node, WIDTH, hit};
use crate::render::geometry::{Hit, Ray, closer};
use crate::render::scene::NO_HIT;
use crate::render::wavefront::cost::{Counter, NoCount};
use crate::render::wavefront::lanes::{f32x8, set_bits, view};
use crate::render::wavefront::simd;
use glam::Vec3A;

/// One ray splatted over 8 lanes, with what the slab test needs.
pub(super) struct RayLanes {
    pub(super) o: [f32x8; 3],
    pub(super) d: [f32x8; 3],
    /// 1 / d, with |d| raised to at least 1e-18 (sign kept), so that an axis-parallel ray never
    /// makes 0 · ∞ = NaN in the slab test. A NaN direction stays NaN and, since `fast_max` and
    /// `fast_min` return their right operand on NaN, enters every box: the answer is still right
    /// (every triangle test misses on NaN), only slow; no valid scene makes such a ray.
    pub(super) inv: [f32x8; 3],
    /// origin · inv, so that a slab distance is one fused (bound · inv − origin · inv).
    pub(super) o_inv: [f32x8; 3],
    /// Per axis, which bound is entered first: 0 (min) for d ≥ 0, 1 (max) for d < 0.
    pub(super) near: [usize; 3],
}

impl RayLanes {
    /// `ray` splatted, with its guarded 1/d, origin · (1/d) and near bounds.
    #[inline(always)]
    pub(super) fn new(ray: &Ray) -> RayLanes {
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

/// The traversal stack: (child reference, entry distance; 0 for occlusion). A node leaves at
/// most 7 children on it, so 7 · depth + 1 entries always suffice, however deep a degenerate
/// mesh makes the tree. One per batch, not per ray ([`MeshBvh::stack`] outside the tree).
#[derive(Default)]
pub struct Stack(Vec<(u32, f32)>);

impl Stack {
    /// A stack deep enough for any walk of `bvh`.
    pub(super) fn new(bvh: &MeshBvh) -> Stack {
        Stack(vec![(0, 0.0); bvh.depth * (WIDTH - 1) + 1])
    }
}

impl MeshBvh {
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

    /// Closest triangle hit in (T_MIN, tmax): `Hit::MISS` when none. The same t bits and
    /// triangle as testing every triangle with `intersect_triangle` in index order, but for the
    /// grazing exception (module docs).
    pub fn closest_triangle(&self, ray: &Ray, tmax: f32, two_sided: bool) -> Hit {
        let r = RayLanes::new(ray);
        hit(self.closest_from(
            self.root,
            &r,
            (tmax, NO_HIT),
            two_sided,
            &mut Stack::new(self),
            &mut NoCount,
        ))
    }

    /// The closest hit of one ray in the subtree `start`, given the best (t, triangle) found
    /// so far (`(tmax, NO_HIT)` for none): the better of the two, as a pair. Inlined into its
    /// callers: as a call per ray it ran the primary set at 15 Mrays/s instead of 22, and with
    /// 12% more instructions (callgrind, incoherent rays; docs/TRIED.md). `c` counts the
    /// nodes and leaves visited (`NoCount`: nothing, and no code).
    #[inline(always)]
    pub(super) fn closest_from<C: Counter>(
        &self,
        start: u32,
        r: &RayLanes,
        (mut best_t, mut best_prim): (f32, u32),
        two_sided: bool,
        stack: &mut Stack,
        c: &mut C,
    ) -> (f32, u32) {
        let stack = &mut stack.0[..];
        let mut sp = 0;
        let mut cur = start;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                c.node();
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
                c.leaf(block.len());
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
        let r = RayLanes::new(ray);
        self.blocker(&r, tmax, two_sided, &mut Stack::new(self), &mut NoCount) != EMPTY
    }

    /// The first leaf found that blocks the ray in (T_MIN, tmax), as a child reference
    /// (`LEAF | block`), or `EMPTY` when none does; stops at that leaf. `c` counts the nodes
    /// and leaves visited.
    #[inline(always)]
    pub(super) fn blocker<C: Counter>(
        &self,
        r: &RayLanes,
        tmax: f32,
        two_sided: bool,
        stack: &mut Stack,
        c: &mut C,
    ) -> u32 {
        let stack = &mut stack.0[..];
        let tmax8 = f32x8::splat(tmax);
        let mut sp = 0;
        let mut cur = self.root;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                c.node();
                let (mask, _) = r.boxes(node, tmax);
                if mask != 0 {
                    // Go on with the last child entered and push the others, lowest first: the
                    // order that pushing all of them and popping the last visits them in, so the
                    // same leaves are tested in the same order, without the push, pop and
                    // prefetch of the child taken at once (the only one, when one is entered).
                    let last = 31 - mask.leading_zeros() as usize;
                    for k in set_bits(mask & !(1 << last)) {
                        self.prefetch(node.child[k]);
                        stack[sp] = (node.child[k], 0.0);
                        sp += 1;
                    }
                    cur = node.child[last];
                    continue;
                }
            } else if cur != EMPTY {
                let block = &self.blocks[(cur & !LEAF) as usize];
                c.leaf(block.len());
                if triangles8_block(block, r, tmax8, two_sided) {
                    return cur;
                }
            }
            if sp == 0 {
                return EMPTY;
            }
            sp -= 1;
            cur = stack[sp].0;
        }
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
    for k in set_bits(mask) {
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
/// of the two by `geometry::closer`. Once something is hit, ties count too (the limit is
/// next_up(t)), so the answer is brute force's whatever the order the tree visits the
/// triangles in.
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
    let hits = t.simd_lt(limit8).to_bitmask();
    if hits != 0 {
        let ts = view(&t);
        for k in set_bits(hits) {
            let prim = block.prim[k];
            if closer(ts[k], prim, best_t, best_prim) {
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
pub(super) fn triangles8(b: &Block, r: &RayLanes, tmax: f32x8, two_sided: bool) -> f32x8 {
    simd::moller_trumbore8(&b.lanes(r), tmax, two_sided)
}

/// True when a triangle of the block blocks the ray: `triangles8(..) < tmax` in some lane, with
/// `simd::moller_trumbore8_blocks`'s early exits.
#[inline(always)]
pub(super) fn triangles8_block(b: &Block, r: &RayLanes, tmax: f32x8, two_sided: bool) -> bool {
    simd::moller_trumbore8_blocks(&b.lanes(r), tmax, two_sided) != 0
}
