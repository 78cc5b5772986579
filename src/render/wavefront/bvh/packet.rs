//! Camera rays in packets of 8: each node fetched once for 8 neighbouring rays, each child box
//! and each leaf triangle tested against the 8 rays in one f32x8 test.
//!
//! ```text
//! active = live lanes; cur = root
//! loop:
//!     if fewer than PACKET_MIN_LANES lanes are active, or cur is a leaf with more triangles
//!        than active lanes:  each active lane goes on alone through cur's subtree (traverse.rs)
//!     else if cur is a node: the children some active lane enters, far to near by the first
//!        entering lane's entry distance, each lane's entry distance kept; push all but the
//!        nearest, go on with it (active = the lanes that enter it before their best t)
//!     else (a leaf): each triangle against the active lanes, keep each lane's least (t, id)
//!     pop the next entry that some lane may still find a closer hit in
//! ```
//!
//! Every test is, lane by lane, the one-ray test bit for bit, and (t, id) is minimised as a
//! pair, so each lane gets brute force's answer, as one ray does, but for the grazing exception
//! (module docs), which here also depends on the packet's visiting order.

use super::traverse::{RayLanes, Stack};
use super::{Block, EMPTY, LEAF, MeshBvh, Node, WIDTH};
use crate::render::geometry::{T_MIN, closer};
use crate::render::scene::NO_HIT;
use crate::render::wavefront::cost::Counter;
use crate::render::wavefront::lanes::{
    MASK_LANES, cast, f32x8, i32x8, load_live, set_bits, u32x8, view,
};
use crate::render::wavefront::simd::{self, RayColumns, TriangleLanes};

/// Below this many live lanes a packet splits: its lanes finish the subtree one ray at a time.
/// Embree's BVH8 traversal of 8-ray packets splits below 8 (its `switchThreshold`, 7). Here,
/// against one ray at a time on the peer camera rays (interleaved, 30 rounds): splitting below
/// 2 lanes 1.14–1.16× on 12k triangles, 0.96–0.98× on 1M; below 4, 1.12–1.13× and 1.01–1.04×;
/// below 8, 1.02–1.08× and 1.02–1.03× (docs/TRIED.md, "The mesh BVH").
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
    fn load(rays: &RayColumns, i: usize, live: usize) -> Packet {
        let col = |c: &[f32]| load_live(c, i, live);
        let (o, d) = (rays.origin.map(col), rays.direction.map(col));
        // `RayLanes::new`'s operations on 8 lanes: |c| < 1e-18 becomes ±1e-18, then 1 / c.
        let tiny = f32x8::splat(1e-18);
        let sign = f32x8::splat(-0.0);
        let inv = d.map(|c| f32x8::ONE / c.abs().simd_lt(tiny).select(tiny | (c & sign), c));
        let negative = inv.map(|v| cast(cast::<_, i32x8>(v).simd_lt(i32x8::ZERO)));
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
        let at = |v: &[f32x8; 3]| v.map(|c| f32x8::splat(view(&c)[k]));
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
            let lo = f32x8::splat(view(&b[0])[k]).mul_sub(self.inv[axis], self.o_inv[axis]);
            let hi = f32x8::splat(view(&b[1])[k]).mul_sub(self.inv[axis], self.o_inv[axis]);
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

    /// Triangle `j` of `block` splatted against the 8 rays, as Möller–Trumbore's operands.
    #[inline(always)]
    fn against(&self, block: &Block, j: usize) -> TriangleLanes {
        let at = |c: &[f32x8; 3]| c.map(|v| f32x8::splat(view(&v)[j]));
        TriangleLanes {
            o: self.o,
            d: self.d,
            v0: at(&block.v0),
            e1: at(&block.e1),
            e2: at(&block.e2),
        }
    }
}

/// Per-lane best (t, triangle) of a packet, and the limit a new hit must be below: t itself
/// before any hit (tmax), next_up(t) after one (ties then count, resolved by id).
pub(super) struct PacketBest {
    t: f32x8,
    prim: [u32; WIDTH],
    limit: f32x8,
}

impl PacketBest {
    /// Lane k's (t, triangle), as one ray's traversal carries it.
    #[inline(always)]
    pub(super) fn lane(&self, k: usize) -> (f32, u32) {
        (view(&self.t)[k], self.prim[k])
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

    /// Triangle `prim`, hit at `t` in the lanes of `hit` (t below their limit), taken where it
    /// is closer by `geometry::closer`: lanes strictly closer in one compare, lanes at the same
    /// t through `closer` itself.
    #[inline(always)]
    fn take(&mut self, hit: f32x8, t: f32x8, prim: u32) {
        let tie = hit & t.simd_eq(self.t);
        let mut take = (hit & !tie).to_bitmask();
        let (ts, best_ts) = (view(&t), view(&self.t));
        for k in set_bits(tie.to_bitmask()) {
            if closer(ts[k], prim, best_ts[k], self.prim[k]) {
                take |= 1 << k;
            }
        }
        let take_lanes = MASK_LANES[take as usize];
        self.t = take_lanes.select(t, self.t);
        // next_up(t) as bits + 1: t > T_MIN ≥ 0 here (so t is positive, not −0.0), and finite
        // (t < limit).
        const _: () = assert!(T_MIN >= 0.0);
        let up: f32x8 = cast(cast::<_, u32x8>(t) + u32x8::ONE);
        self.limit = take_lanes.select(up, self.limit);
        for k in set_bits(take) {
            self.prim[k] = prim;
        }
    }
}

/// The children of a node that some active lane enters, far to near by the first entering
/// lane's entry distance: (that distance, child reference), and every lane's entry distance
/// (NaN in the lanes that do not enter it, so that no comparison lets them in).
struct Entered {
    order: [(f32, u32); WIDTH],
    entries: [f32x8; WIDTH],
    n: usize,
}

/// A packet traversal's state across packets: its stack, and what the lanes that leave the
/// packet need.
pub(super) struct Walk<'b> {
    /// (child reference, entry distance of every lane). Same bound as [`Stack`].
    stack: Vec<(u32, f32x8)>,
    alone: Alone<'b>,
}

/// What lanes that leave a packet need to go on one ray at a time.
struct Alone<'b> {
    bvh: &'b MeshBvh,
    stack: Stack,
    two_sided: bool,
}

impl<'b> Walk<'b> {
    /// Stacks deep enough for any walk of `bvh`, allocated once per batch.
    pub(super) fn new(bvh: &'b MeshBvh, two_sided: bool) -> Walk<'b> {
        Walk {
            stack: vec![(0, f32x8::ZERO); bvh.depth * (WIDTH - 1) + 1],
            alone: Alone {
                bvh,
                stack: Stack::new(bvh),
                two_sided,
            },
        }
    }

    /// Closest triangle hits of rays `i..i + live` (live ≤ 8) as one packet: per lane the best
    /// (t, triangle), `(tmax, NO_HIT)` for a miss; lane k's nodes and leaves counted in
    /// `counts[k]`.
    #[inline(always)]
    pub(super) fn closest<C: Counter>(
        &mut self,
        rays: &RayColumns,
        i: usize,
        live: usize,
        counts: &mut [C; WIDTH],
    ) -> PacketBest {
        let p = Packet::load(rays, i, live);
        let tmax = load_live(rays.tmax, i, live);
        self.closest_packet(&p, tmax, (1 << live) - 1, counts)
    }

    /// The walk of the module docs for live lanes `live` (a bitmask). A lane visits the nodes
    /// and leaves it is active in.
    fn closest_packet<C: Counter>(
        &mut self,
        p: &Packet,
        tmax: f32x8,
        live: u32,
        counts: &mut [C; WIDTH],
    ) -> PacketBest {
        let Walk { stack, alone } = self;
        let bvh = alone.bvh;
        let mut best = PacketBest {
            t: tmax,
            prim: [NO_HIT; WIDTH],
            limit: tmax,
        };
        let stack = &mut stack[..];
        let mut sp = 0;
        let mut cur = bvh.root;
        // Lanes that enter `cur` (live lanes at the root, as one ray's traversal starts there).
        let mut active = live;
        loop {
            if splits(bvh, cur, active) {
                alone.finish(cur, active, p, &mut best, counts);
            } else if cur & LEAF == 0 {
                C::node_lanes(counts, active);
                let e = entered_children(&bvh.nodes[cur as usize], active, p, &best);
                if e.n > 0 {
                    for j in 0..e.n - 1 {
                        stack[sp] = (e.order[j].1, e.entries[j]);
                        sp += 1;
                    }
                    cur = e.order[e.n - 1].1;
                    active = e.entries[e.n - 1].simd_le(best.t).to_bitmask();
                    continue;
                }
            } else if cur != EMPTY {
                let block = &bvh.blocks[(cur & !LEAF) as usize];
                C::leaf_lanes(counts, active, block.len());
                leaf_against_packet(block, active, p, &mut best, alone.two_sided);
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
}

impl Alone<'_> {
    /// Each active lane alone through the rest of subtree `cur`, from its best so far.
    #[inline(always)]
    fn finish<C: Counter>(
        &mut self,
        cur: u32,
        active: u32,
        p: &Packet,
        best: &mut PacketBest,
        counts: &mut [C; WIDTH],
    ) {
        for k in set_bits(active) {
            let found = self.bvh.closest_from(
                cur,
                &p.lane(k),
                best.lane(k),
                self.two_sided,
                &mut self.stack,
                &mut counts[k],
            );
            best.set_lane(k, found);
        }
    }
}

/// True where the packet parts: fewer than `PACKET_MIN_LANES` active lanes, or a leaf with
/// more triangles than active lanes (then one ray against 8 triangles is cheaper).
#[inline(always)]
fn splits(bvh: &MeshBvh, cur: u32, active: u32) -> bool {
    active.count_ones() < PACKET_MIN_LANES
        || cur & LEAF != 0 && cur != EMPTY && {
            let block = &bvh.blocks[(cur & !LEAF) as usize];
            block.len() > active.count_ones()
        }
}

/// The children of `node` that some active lane enters before its best t (see [`Entered`]).
#[inline(always)]
fn entered_children(node: &Node, active: u32, p: &Packet, best: &PacketBest) -> Entered {
    let bits = &MASK_LANES[active as usize];
    let limit = bits.select(best.t, f32x8::splat(f32::NEG_INFINITY));
    let mut e = Entered {
        order: [(0.0f32, 0u32); WIDTH],
        entries: [f32x8::ZERO; WIDTH],
        n: 0,
    };
    for k in 0..WIDTH {
        let child = node.child[k];
        if child == EMPTY {
            break;
        }
        let (enter, near) = p.child_box(node, k, limit);
        let mask = enter.to_bitmask();
        if mask != 0 {
            // Children in order of the first entering lane's entry distance.
            let key = view(&near)[mask.trailing_zeros() as usize];
            let entry = enter.select(near, f32x8::splat(f32::NAN));
            let mut j = e.n;
            while j > 0 && e.order[j - 1].0 < key {
                e.order[j] = e.order[j - 1];
                e.entries[j] = e.entries[j - 1];
                j -= 1;
            }
            e.order[j] = (key, child);
            e.entries[j] = entry;
            e.n += 1;
        }
    }
    e
}

/// Each triangle of a leaf against the packet's active lanes, keeping each lane's best.
#[inline(always)]
fn leaf_against_packet(
    block: &Block,
    active: u32,
    p: &Packet,
    best: &mut PacketBest,
    two_sided: bool,
) {
    let bits = &MASK_LANES[active as usize];
    for j in 0..block.len() as usize {
        let limit = bits.select(best.limit, f32x8::splat(f32::NEG_INFINITY));
        let t = simd::moller_trumbore8(&p.against(block, j), limit, two_sided);
        let hit = t.simd_lt(limit);
        if hit.any() {
            best.take(hit, t, block.prim[j]);
        }
    }
}
