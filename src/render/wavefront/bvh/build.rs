//! The build: obvhs's PLOC BVH2 with reinsertion, collapsed into the 8-wide tree.
//!
//! ```text
//! counts   triangles under every BVH2 node (post-order)
//! for each wide node (a BVH2 node whose subtree is too big for a leaf), depth first:
//!     children   its two BVH2 children; while a slot is free, open the largest child that
//!                is too big for a leaf; merge two leaves into one block where that adds no
//!                surface area, and go back to opening with the freed slot
//!     write      each child's padded box into the node's columns; a leaf's triangles into a
//!                new block, a bigger child into a new node, collapsed later
//! ```

use super::memory::huge_pages;
use super::{Block, EMPTY, LEAF, LEAF_MAX, MeshBvh, Node, WIDTH};
use crate::render::scene::{Scene, Triangle};
use crate::render::wavefront::lanes::f32x8;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::{BvhBuildParams, aabb::Aabb};
use std::time::{Duration, Instant};

/// A child slot of a wide node during the collapse: one BVH2 node, or, for a leaf, several
/// whose triangles share one block.
struct Kid {
    nodes: Vec<usize>,
    aabb: Aabb,
    count: u32,
}

impl Kid {
    /// BVH2 node `k` as a child slot.
    fn of(bvh2: &Bvh2, count: &[u32], k: usize) -> Kid {
        Kid {
            nodes: vec![k],
            aabb: *bvh2.nodes[k].aabb(),
            count: count[k],
        }
    }
}

/// A wide node still to fill: its BVH2 node, its index in `MeshBvh::nodes`, its depth.
struct Pending {
    bvh2_node: usize,
    wide: usize,
    depth: usize,
}

impl MeshBvh {
    /// Builds the tree over `scene.triangles` with obvhs's `medium_build` settings.
    pub fn new(scene: &Scene) -> MeshBvh {
        let start = Instant::now();
        let tris = &scene.triangles;
        let mut bvh = if tris.is_empty() {
            MeshBvh::from_bvh2(scene, &Bvh2::default())
        } else {
            let aabbs: Vec<Aabb> = tris
                .iter()
                .map(|t| {
                    let mut b = Aabb::from_point(t.v0.into());
                    b.extend((t.v0 + t.e1).into());
                    b.extend((t.v0 + t.e2).into());
                    b
                })
                .collect();
            let p = BvhBuildParams::medium_build();
            let mut bvh2 = obvhs::ploc::PlocBuilder::with_capacity(aabbs.len()).build(
                p.ploc_search_distance,
                &aabbs,
                (0..aabbs.len() as u32).collect(),
                p.sort_precision,
                p.search_depth_threshold,
            );
            ReinsertionOptimizer::default().run(&mut bvh2, p.reinsertion_batch_ratio, None);
            MeshBvh::from_bvh2(scene, &bvh2)
        };
        bvh.build_time = start.elapsed();
        bvh
    }

    /// The 8-wide tree collapsed from any binary tree over `scene.triangles` whose leaves name
    /// triangles by index (`primitive_indices`; a triangle may sit in several leaves, as
    /// spatial splits leave it). An empty `bvh2` gives the empty tree. `new` collapses obvhs's
    /// build with it; the peer benchmark collapses other builders' trees, to compare trees
    /// under one traversal. `build_time` is the collapse's.
    ///
    /// # Panics
    /// On a leaf of more than 8 triangles (a block's worth), which the collapse cannot hold.
    pub fn from_bvh2(scene: &Scene, bvh2: &Bvh2) -> MeshBvh {
        let start = Instant::now();
        assert!(
            bvh2.nodes.iter().all(|n| n.prim_count <= LEAF_MAX),
            "MeshBvh::from_bvh2: a leaf of more than {LEAF_MAX} triangles"
        );
        let mut bvh = MeshBvh {
            nodes: Vec::new(),
            blocks: Vec::new(),
            root: EMPTY,
            depth: 0,
            build_time: Duration::ZERO,
        };
        if !bvh2.nodes.is_empty() {
            bvh.collapse(bvh2, &scene.triangles);
            bvh.nodes = huge_pages(std::mem::take(&mut bvh.nodes));
            bvh.blocks = huge_pages(std::mem::take(&mut bvh.blocks));
        }
        bvh.build_time = start.elapsed();
        bvh
    }

    /// Turns obvhs's BVH2 into the 8-wide tree; triangles are copied leaf by leaf.
    fn collapse(&mut self, bvh2: &Bvh2, tris: &[Triangle]) {
        let count = subtree_counts(bvh2);
        if count[0] <= LEAF_MAX {
            self.root = self.leaf(bvh2, &[0], tris);
            self.depth = 0;
            return;
        }
        self.root = 0;
        self.nodes.push(Node::empty());
        let mut work = vec![Pending {
            bvh2_node: 0,
            wide: 0,
            depth: 1,
        }];
        while let Some(p) = work.pop() {
            self.depth = self.depth.max(p.depth);
            let kids = children(bvh2, &count, p.bvh2_node);
            self.nodes[p.wide] = self.write_node(&kids, p.depth, bvh2, tris, &mut work);
        }
    }

    /// The wide node holding `kids`: their padded boxes, and for each a leaf reference (its
    /// block written now) or the index of a new node (queued on `work`, to be filled later).
    fn write_node(
        &mut self,
        kids: &[Kid],
        depth: usize,
        bvh2: &Bvh2,
        tris: &[Triangle],
        work: &mut Vec<Pending>,
    ) -> Node {
        let mut node = Node::empty();
        for (slot, k) in kids.iter().enumerate() {
            set_child_box(&mut node, slot, &k.aabb);
            node.child[slot] = if k.count <= LEAF_MAX {
                self.leaf(bvh2, &k.nodes, tris)
            } else {
                let index = self.nodes.len();
                self.nodes.push(Node::empty());
                work.push(Pending {
                    bvh2_node: k.nodes[0],
                    wide: index,
                    depth: depth + 1,
                });
                index as u32
            };
        }
        node
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
}

/// Triangles under every BVH2 node. Children have higher indices than their parent in a PLOC
/// build, but reinsertion may move them, so this counts in an explicit post-order.
fn subtree_counts(bvh2: &Bvh2) -> Vec<u32> {
    let n2 = &bvh2.nodes;
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
    count
}

/// The child slots of the wide node for BVH2 node `i`: its two children, then, while a slot is
/// free, the largest child too big for a leaf opened into its own two; then two leaves merged
/// into one block where that costs no more than both apart (surface area heuristic: a ray
/// enters a box with probability ∝ its area, and a block test costs the same for 2 or 8
/// triangles), a freed slot going back to opening.
fn children(bvh2: &Bvh2, count: &[u32], i: usize) -> Vec<Kid> {
    let c = bvh2.nodes[i].first_index as usize;
    let mut kids = vec![Kid::of(bvh2, count, c), Kid::of(bvh2, count, c + 1)];
    loop {
        if kids.len() < WIDTH && open_largest(&mut kids, bvh2, count) {
            continue;
        }
        if !merge_best_pair(&mut kids) {
            return kids;
        }
    }
}

/// Replaces the largest child that is too big for a leaf (by surface area) with its two
/// children; false when there is none.
fn open_largest(kids: &mut Vec<Kid>, bvh2: &Bvh2, count: &[u32]) -> bool {
    let open = kids
        .iter()
        .enumerate()
        .filter(|(_, k)| k.count > LEAF_MAX && !bvh2.nodes[k.nodes[0]].is_leaf())
        .max_by(|a, b| a.1.aabb.half_area().total_cmp(&b.1.aabb.half_area()))
        .map(|(slot, _)| slot);
    let Some(slot) = open else {
        return false;
    };
    let k = kids.swap_remove(slot).nodes[0];
    let c = bvh2.nodes[k].first_index as usize;
    kids.extend([Kid::of(bvh2, count, c), Kid::of(bvh2, count, c + 1)]);
    true
}

/// Merges the pair [`best_merge`] picks into one slot; false when there is none.
fn merge_best_pair(kids: &mut Vec<Kid>) -> bool {
    let Some((i, j)) = best_merge(kids) else {
        return false;
    };
    // i < j, so removing j leaves i where it is.
    let b = kids.swap_remove(j);
    let a = &mut kids[i];
    a.nodes.extend(b.nodes);
    a.aabb = a.aabb.union(&b.aabb);
    a.count += b.count;
    true
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

/// Writes box `b`, padded, into slot `slot` of the node's columns.
fn set_child_box(node: &mut Node, slot: usize, b: &Aabb) {
    let p = pad(b);
    for axis in 0..3 {
        let mut lo = node.bounds[axis][0].to_array();
        let mut hi = node.bounds[axis][1].to_array();
        lo[slot] = b.min[axis] - p;
        hi[slot] = b.max[axis] + p;
        node.bounds[axis][0] = f32x8::new(lo);
        node.bounds[axis][1] = f32x8::new(hi);
    }
}

/// Outward padding of a box: covers the kernel's edge slack (a hit may lie EDGE_EPSILON · |e|
/// outside its triangle) and a few ulps of the slab test, with a wide margin.
fn pad(b: &Aabb) -> f32 {
    let extent = (b.max - b.min).max_element();
    let magnitude = b.min.abs().max(b.max.abs()).max_element();
    1e-5 * (extent + magnitude)
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
