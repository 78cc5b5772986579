//! Traversal counters: how much work each ray's hit search did (BVH nodes visited, leaves
//! visited, primitives tested), for `render --stats` and the cost map.
//!
//! ```text
//! kernel<S: Costs>(.., costs: &mut S)        one source, two instantiations:
//!     S = NoCount   every counter call is an empty inline function on a zero-sized value:
//!                   the kernel the renderer always runs, compiled as before
//!     S = PerRay    each ray's Cost, added by ray index (the counted pass)
//! per ray:  Counter::node()          an 8-wide node whose child boxes the ray was tested against
//!           Counter::leaf(n)         a block of n triangles tested against the ray
//!           Counter::tests(n)        n primitives tested outside a leaf (spheres; brute force)
//! ```
//!
//! A ray in a packet (camera rays through the mesh BVH) visits the nodes and leaves it is
//! active in; a ray of an 8- or 16-lane brute-force block is charged every primitive its block
//! tested. The counts are integers and each pixel's are summed inside its tile, so they are
//! the same for any thread count.

use super::lanes::set_bits;
use crate::render::per_kind::{PerKind, RayKind};
use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign};

/// What a kernel counts for one ray (or one block of rays tested together).
pub trait Counter: Copy + Default {
    /// An interior node: the ray tested against its child boxes.
    fn node(&mut self);
    /// A leaf: the ray tested against its `triangles` triangles.
    fn leaf(&mut self, triangles: u32);
    /// `n` primitives tested outside a leaf (spheres, brute force).
    fn tests(&mut self, n: u32);
    /// `n` rays' worth of this count (a block of `n` rays that did the same tests).
    fn times(self, n: u32) -> Self;
    /// [`Counter::node`] for every lane of `lanes` set in `active` (a packet at a node).
    #[inline(always)]
    fn node_lanes(lanes: &mut [Self], active: u32) {
        set_bits(active).for_each(|k| lanes[k].node());
    }
    /// [`Counter::leaf`] for every lane of `lanes` set in `active` (a packet at a leaf).
    #[inline(always)]
    fn leaf_lanes(lanes: &mut [Self], active: u32, triangles: u32) {
        set_bits(active).for_each(|k| lanes[k].leaf(triangles));
    }
}

/// Where a batch kernel puts each ray's count, by the ray's index in the batch.
pub trait Costs {
    /// The per-ray counter the kernel fills.
    type Counter: Counter;
    /// Adds ray `i`'s count.
    fn add(&mut self, i: usize, c: Self::Counter);
    /// Adds `c` to rays `i0 + k` for every bit k set in `lanes` (a block's live lanes).
    #[inline(always)]
    fn add_lanes(&mut self, i0: usize, lanes: u32, c: Self::Counter) {
        set_bits(lanes).for_each(|k| self.add(i0 + k, c));
    }
}

/// A sink that can be seen through an index map: the shadow stage counts each queued ray
/// against the hit that cast it.
pub trait Remap: Costs {
    /// This sink through a map: ray `q`'s count goes to index `map[q]`.
    type Mapped<'m>: Costs<Counter = Self::Counter>
    where
        Self: 'm;
    /// [`Remap::Mapped`] over `map` (the shadow queue's hit index of every entry).
    fn mapped<'m>(&'m mut self, map: &'m [u32]) -> Self::Mapped<'m>;
}

/// Counts nothing: the instantiation every render runs. Zero-sized, every call empty.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoCount;

impl Counter for NoCount {
    #[inline(always)]
    fn node(&mut self) {}
    #[inline(always)]
    fn leaf(&mut self, _: u32) {}
    #[inline(always)]
    fn tests(&mut self, _: u32) {}
    #[inline(always)]
    fn times(self, _: u32) -> NoCount {
        NoCount
    }
    #[inline(always)]
    fn node_lanes(_: &mut [NoCount], _: u32) {}
    #[inline(always)]
    fn leaf_lanes(_: &mut [NoCount], _: u32, _: u32) {}
}

impl Costs for NoCount {
    type Counter = NoCount;
    #[inline(always)]
    fn add(&mut self, _: usize, _: NoCount) {}
    #[inline(always)]
    fn add_lanes(&mut self, _: usize, _: u32, _: NoCount) {}
}

impl Remap for NoCount {
    type Mapped<'m> = NoCount;
    #[inline(always)]
    fn mapped<'m>(&'m mut self, _: &'m [u32]) -> NoCount {
        NoCount
    }
}

/// One ray's (or one pixel's) traversal work.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Cost {
    /// Interior nodes visited (each an 8-wide test of child boxes).
    pub nodes: u32,
    /// Leaves visited (each a block of up to 8 triangles).
    pub leaves: u32,
    /// Primitives tested: the triangles of the leaves visited, spheres, and every primitive a
    /// brute-force block tested.
    pub tests: u32,
}

impl Counter for Cost {
    #[inline(always)]
    fn node(&mut self) {
        self.nodes += 1;
    }
    #[inline(always)]
    fn leaf(&mut self, triangles: u32) {
        self.leaves += 1;
        self.tests += triangles;
    }
    #[inline(always)]
    fn tests(&mut self, n: u32) {
        self.tests += n;
    }
    #[inline(always)]
    fn times(self, n: u32) -> Cost {
        Cost {
            nodes: self.nodes.saturating_mul(n),
            leaves: self.leaves.saturating_mul(n),
            tests: self.tests.saturating_mul(n),
        }
    }
}

impl Add for Cost {
    type Output = Cost;
    #[inline]
    fn add(self, o: Cost) -> Cost {
        // Saturating: a pixel's sum past 4e9 stays at the top of the scale.
        Cost {
            nodes: self.nodes.saturating_add(o.nodes),
            leaves: self.leaves.saturating_add(o.leaves),
            tests: self.tests.saturating_add(o.tests),
        }
    }
}

impl AddAssign for Cost {
    #[inline]
    fn add_assign(&mut self, o: Cost) {
        *self = *self + o;
    }
}

/// Each ray's [`Cost`], summed into a column by ray index.
pub struct PerRay<'a>(pub &'a mut [Cost]);

impl Costs for PerRay<'_> {
    type Counter = Cost;
    #[inline]
    fn add(&mut self, i: usize, c: Cost) {
        self.0[i] += c;
    }
}

impl Remap for PerRay<'_> {
    type Mapped<'m>
        = Mapped<'m>
    where
        Self: 'm;
    fn mapped<'m>(&'m mut self, map: &'m [u32]) -> Mapped<'m> {
        Mapped {
            map,
            costs: &mut *self.0,
        }
    }
}

/// [`PerRay`] through an index map (`Costs::mapped`).
pub struct Mapped<'m> {
    map: &'m [u32],
    costs: &'m mut [Cost],
}

impl Costs for Mapped<'_> {
    type Counter = Cost;
    #[inline]
    fn add(&mut self, q: usize, c: Cost) {
        self.costs[self.map[q] as usize] += c;
    }
}

/// A sum of many rays' [`Cost`]s, in 64 bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CostSum {
    /// Interior nodes visited.
    pub nodes: u64,
    /// Leaves visited.
    pub leaves: u64,
    /// Primitives tested.
    pub tests: u64,
}

impl AddAssign<Cost> for CostSum {
    #[inline]
    fn add_assign(&mut self, c: Cost) {
        self.nodes += c.nodes as u64;
        self.leaves += c.leaves as u64;
        self.tests += c.tests as u64;
    }
}

impl Add for CostSum {
    type Output = CostSum;
    fn add(self, o: CostSum) -> CostSum {
        CostSum {
            nodes: self.nodes + o.nodes,
            leaves: self.leaves + o.leaves,
            tests: self.tests + o.tests,
        }
    }
}

/// What a counted render measured: the frame's sums by kind, and each pixel's when asked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CostReport {
    /// Every ray's work, summed by kind.
    pub totals: PerKind<CostSum>,
    /// Each pixel's work by kind (all its samples' rays), row-major; `None` unless asked for.
    pub pixels: Option<Vec<PerKind<Cost>>>,
}

/// What a tile's render counts: nothing ([`NoCount`], the renderer as it always runs) or each
/// pixel's work ([`TileCosts`], the counted pass).
pub(crate) trait Tally {
    /// The sink of one batch's per-ray (or per-hit) counts.
    type Sink<'a>: Remap
    where
        Self: 'a;
    /// A zeroed sink for a batch of `n` rays (or hits).
    fn batch(&mut self, n: usize) -> Self::Sink<'_>;
    /// Adds the batch's counts to the pixels of `pixel` (ray i's pixel), as `kind`'s work.
    fn settle(&mut self, pixel: &[u32], kind: RayKind);
}

impl Tally for NoCount {
    type Sink<'a> = NoCount;
    #[inline(always)]
    fn batch(&mut self, _: usize) -> NoCount {
        NoCount
    }
    #[inline(always)]
    fn settle(&mut self, _: &[u32], _: RayKind) {}
}

/// One tile's counts while it renders: the current batch's per-ray column, and each of the
/// tile's pixels by kind.
pub(crate) struct TileCosts {
    first: u32,
    column: Vec<Cost>,
    pub(crate) pixels: Vec<PerKind<Cost>>,
}

impl TileCosts {
    /// Zero counts for pixels `first..first + count`.
    pub(crate) fn new(first: u32, count: usize) -> TileCosts {
        TileCosts {
            first,
            column: Vec::new(),
            pixels: vec![PerKind::default(); count],
        }
    }

    /// The tile's sums by kind.
    pub(crate) fn totals(&self) -> PerKind<CostSum> {
        let mut sum = PerKind::<CostSum>::default();
        for p in &self.pixels {
            for (kind, c) in p.iter() {
                sum[kind] += *c;
            }
        }
        sum
    }
}

impl Tally for TileCosts {
    type Sink<'a> = PerRay<'a>;
    fn batch(&mut self, n: usize) -> PerRay<'_> {
        self.column.clear();
        self.column.resize(n, Cost::default());
        PerRay(&mut self.column)
    }
    fn settle(&mut self, pixel: &[u32], kind: RayKind) {
        for (&p, &c) in pixel.iter().zip(&self.column) {
            self.pixels[(p - self.first) as usize][kind] += c;
        }
    }
}
