//! Embree 4's tree shape under raywave's traversal: Embree's public BVH builder
//! (`rtcBuildBVH`, the builders behind its own scenes: binned SAH at quality medium, SAH with
//! spatial splits at quality high) run over the scene's triangles into a binary tree, which
//! `MeshBvh::from_bvh2` collapses into raywave's 8-wide nodes and 8-triangle blocks as it does
//! obvhs's. Traced by the same walk, the two trees' node, leaf and triangle counts per ray and
//! their speed compare the builds alone (the tree table, docs/BENCHMARKING.md).
//!
//! ```text
//! primitives   one RTCBuildPrimitive per triangle (its box, primID = the triangle's index),
//!              in an array twice as long, the room spatial splits take for fragments
//! rtcBuildBVH  branching 2, leaves of 1..=8 triangles, traversal and intersection cost 1;
//!              callbacks: nodes and leaves in Embree's thread-local memory (tagged),
//!              splitPrimitive clips the triangle at the plane (its two parts' boxes)
//! to_bvh2      the tree walked once into obvhs's Bvh2 (siblings adjacent), before
//!              rtcReleaseBVH frees Embree's memory
//! ```
//!
//! This is Embree's builder, not Embree's own BVH8 (which groups triangles in blocks of 4 and
//! leaves of up to 7 blocks): the binary tree's splits are Embree's, the 8-wide collapse and
//! the leaves raywave's.

use super::embree4::{Api, BuildQuality, Device};
use anyhow::bail;
use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::{Bvh2, node::Bvh2Node};
use raywave::render::scene::{Scene, Triangle};
use std::ffi::c_void;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The builder's entry points (`rtcore_builder.h`), resolved once.
struct BuilderApi {
    new_bvh: unsafe extern "C" fn(Device) -> *mut c_void,
    build_bvh: unsafe extern "C" fn(*const BuildArguments) -> *mut c_void,
    thread_local_alloc: unsafe extern "C" fn(*mut c_void, usize, usize) -> *mut c_void,
    release_bvh: unsafe extern "C" fn(*mut c_void),
}

impl BuilderApi {
    /// The entry points, from the library `api` loaded; the same error on every later call if
    /// one is missing.
    fn get(api: &Api) -> anyhow::Result<&'static BuilderApi> {
        static BUILDER: OnceLock<Result<BuilderApi, String>> = OnceLock::new();
        let load = || -> anyhow::Result<BuilderApi> {
            // SAFETY: each field's type is the C signature of the function of that name.
            unsafe {
                Ok(BuilderApi {
                    new_bvh: api.function("rtcNewBVH")?,
                    build_bvh: api.function("rtcBuildBVH")?,
                    thread_local_alloc: api.function("rtcThreadLocalAlloc")?,
                    release_bvh: api.function("rtcReleaseBVH")?,
                })
            }
        };
        BUILDER
            .get_or_init(|| load().map_err(|e| format!("{e:#}")))
            .as_ref()
            .map_err(|e| anyhow::anyhow!("{e}"))
    }
}

/// Most triangles in one leaf of the binary tree: one block of raywave's.
const MAX_LEAF: usize = 8;

/// `RTCBounds`.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct Bounds {
    lower: [f32; 3],
    _align0: f32,
    upper: [f32; 3],
    _align1: f32,
}

/// `RTCBuildPrimitive`.
#[repr(C, align(32))]
#[derive(Clone, Copy)]
struct BuildPrimitive {
    lower: [f32; 3],
    geom_id: u32,
    upper: [f32; 3],
    prim_id: u32,
}

type CreateNode = unsafe extern "C" fn(*mut c_void, u32, *mut c_void) -> *mut c_void;
type SetChildren = unsafe extern "C" fn(*mut c_void, *mut *mut c_void, u32, *mut c_void);
type SetBounds = unsafe extern "C" fn(*mut c_void, *const *const Bounds, u32, *mut c_void);
type CreateLeaf =
    unsafe extern "C" fn(*mut c_void, *const BuildPrimitive, usize, *mut c_void) -> *mut c_void;
type SplitPrimitive =
    unsafe extern "C" fn(*const BuildPrimitive, u32, f32, *mut Bounds, *mut Bounds, *mut c_void);

/// `RTCBuildArguments` (Embree 4.4's `include/embree4/rtcore_builder.h`).
#[repr(C)]
struct BuildArguments {
    byte_size: usize,
    build_quality: u32,
    build_flags: u32,
    max_branching_factor: u32,
    max_depth: u32,
    sah_block_size: u32,
    min_leaf_size: u32,
    max_leaf_size: u32,
    traversal_cost: f32,
    intersection_cost: f32,
    bvh: *mut c_void,
    primitives: *mut BuildPrimitive,
    primitive_count: usize,
    primitive_array_capacity: usize,
    create_node: Option<CreateNode>,
    set_node_children: Option<SetChildren>,
    set_node_bounds: Option<SetBounds>,
    create_leaf: Option<CreateLeaf>,
    split_primitive: Option<SplitPrimitive>,
    build_progress: Option<unsafe extern "C" fn(*mut c_void, f64) -> bool>,
    user_ptr: *mut c_void,
}

/// What the callbacks share: the allocator entry point and the triangles.
struct Shared<'a> {
    alloc: unsafe extern "C" fn(*mut c_void, usize, usize) -> *mut c_void,
    triangles: &'a [Triangle],
}

const INNER: u32 = 0;
const LEAF: u32 = 1;

/// A binary node in Embree's memory (`tag` first, as in `Leaf`).
#[repr(C)]
struct Inner {
    tag: u32,
    count: u32,
    children: [*const u32; 2],
    bounds: [Bounds; 2],
}

/// A leaf in Embree's memory: up to `MAX_LEAF` triangle indices.
#[repr(C)]
struct Leaf {
    tag: u32,
    count: u32,
    ids: [u32; MAX_LEAF],
}

unsafe extern "C" fn create_node(alloc: *mut c_void, count: u32, user: *mut c_void) -> *mut c_void {
    // SAFETY: `user` is the build's `Shared`; the allocator hands out `size` aligned bytes.
    unsafe {
        let shared = &*(user as *const Shared);
        let node = (shared.alloc)(alloc, size_of::<Inner>(), align_of::<Inner>()) as *mut Inner;
        node.write(Inner {
            tag: INNER,
            count,
            children: [std::ptr::null(); 2],
            bounds: [Bounds {
                lower: [0.0; 3],
                _align0: 0.0,
                upper: [0.0; 3],
                _align1: 0.0,
            }; 2],
        });
        node as *mut c_void
    }
}

unsafe extern "C" fn set_children(
    node: *mut c_void,
    kids: *mut *mut c_void,
    n: u32,
    _: *mut c_void,
) {
    // SAFETY: `node` is an `Inner` from `create_node`; `kids` holds `n` ≤ 2 pointers.
    unsafe {
        let node = &mut *(node as *mut Inner);
        for k in 0..(n as usize).min(2) {
            node.children[k] = *kids.add(k) as *const u32;
        }
    }
}

unsafe extern "C" fn set_bounds(
    node: *mut c_void,
    b: *const *const Bounds,
    n: u32,
    _: *mut c_void,
) {
    // SAFETY: as `set_children`, with `n` bounds.
    unsafe {
        let node = &mut *(node as *mut Inner);
        for k in 0..(n as usize).min(2) {
            node.bounds[k] = **b.add(k);
        }
    }
}

unsafe extern "C" fn create_leaf(
    alloc: *mut c_void,
    prims: *const BuildPrimitive,
    n: usize,
    user: *mut c_void,
) -> *mut c_void {
    // SAFETY: as `create_node`; `prims` holds `n` primitives, n ≤ MAX_LEAF (the build's
    // maxLeafSize; more are dropped, and `to_bvh2` then refuses the leaf by its count).
    unsafe {
        let shared = &*(user as *const Shared);
        let leaf = (shared.alloc)(alloc, size_of::<Leaf>(), align_of::<Leaf>()) as *mut Leaf;
        let mut ids = [0; MAX_LEAF];
        for (k, id) in ids.iter_mut().enumerate().take(n) {
            *id = (*prims.add(k)).prim_id;
        }
        leaf.write(Leaf {
            tag: LEAF,
            count: n as u32,
            ids,
        });
        leaf as *mut c_void
    }
}

/// The boxes of the parts of triangle `prim` on either side of the plane `axis = pos`, each
/// clipped to the primitive's box (a fragment's box after earlier splits).
unsafe extern "C" fn split(
    prim: *const BuildPrimitive,
    axis: u32,
    pos: f32,
    left: *mut Bounds,
    right: *mut Bounds,
    user: *mut c_void,
) {
    // SAFETY: `user` is the build's `Shared`; the pointers are Embree's, valid for this call.
    unsafe {
        let shared = &*(user as *const Shared);
        let p = &*prim;
        let (l, r) = split_triangle(&shared.triangles[p.prim_id as usize], axis as usize, pos);
        let clip = |b: Aabb| Bounds {
            lower: (b.min.max(Vec3A::from(p.lower))).into(),
            _align0: 0.0,
            upper: (b.max.min(Vec3A::from(p.upper))).into(),
            _align1: 0.0,
        };
        *left = clip(l);
        *right = clip(r);
    }
}

/// The boxes of a triangle's parts below and above `pos` on `axis`: each holds the corners on
/// its side and the points where edges cross the plane.
pub fn split_triangle(t: &Triangle, axis: usize, pos: f32) -> (Aabb, Aabb) {
    let v = [t.v0, t.v0 + t.e1, t.v0 + t.e2];
    let (mut left, mut right) = (Aabb::INVALID, Aabb::INVALID);
    for k in 0..3 {
        let (a, b) = (v[k], v[(k + 1) % 3]);
        if a[axis] <= pos {
            left.extend(a.into());
        }
        if a[axis] >= pos {
            right.extend(a.into());
        }
        if (a[axis] < pos && b[axis] > pos) || (a[axis] > pos && b[axis] < pos) {
            let s = (pos - a[axis]) / (b[axis] - a[axis]);
            let mut x: Vec3 = a + (b - a) * s;
            x[axis] = pos;
            left.extend(x.into());
            right.extend(x.into());
        }
    }
    left.max[axis] = left.max[axis].min(pos);
    right.min[axis] = right.min[axis].max(pos);
    (left, right)
}

/// Embree's binary tree over `scene.triangles` at `quality` (medium: binned SAH; high: with
/// spatial splits), as obvhs's `Bvh2`, and the build's wall time (Embree's threads).
pub fn embree_bvh2(scene: &Scene, quality: BuildQuality) -> anyhow::Result<(Bvh2, Duration)> {
    let api = Api::get()?;
    let builder = BuilderApi::get(api)?;
    let tris = &scene.triangles;
    if tris.is_empty() {
        return Ok((Bvh2::default(), Duration::ZERO));
    }
    let mut prims: Vec<BuildPrimitive> = tris
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let mut b = Aabb::from_point(t.v0.into());
            b.extend((t.v0 + t.e1).into());
            b.extend((t.v0 + t.e2).into());
            BuildPrimitive {
                lower: b.min.into(),
                geom_id: 0,
                upper: b.max.into(),
                prim_id: i as u32,
            }
        })
        .collect();
    let count = prims.len();
    prims.resize(2 * count, prims[0]);
    let shared = Shared {
        alloc: builder.thread_local_alloc,
        triangles: tris,
    };
    let start = Instant::now();
    // SAFETY: a device and a BVH handle from the library, arguments laid out as
    // `RTCBuildArguments`, callbacks with its signatures; the tree lives in the BVH's memory
    // until `release_bvh`, after `to_bvh2` has copied it.
    unsafe {
        let device = (api.new_device)(std::ptr::null());
        if device.is_null() {
            bail!("rtcNewDevice failed: {}", api.error(device));
        }
        let bvh = (builder.new_bvh)(device);
        let args = BuildArguments {
            byte_size: size_of::<BuildArguments>(),
            build_quality: quality.rtc(),
            build_flags: 0,
            max_branching_factor: 2,
            max_depth: 64,
            sah_block_size: 1,
            min_leaf_size: 1,
            max_leaf_size: MAX_LEAF as u32,
            traversal_cost: 1.0,
            intersection_cost: 1.0,
            bvh,
            primitives: prims.as_mut_ptr(),
            primitive_count: count,
            primitive_array_capacity: prims.len(),
            create_node: Some(create_node),
            set_node_children: Some(set_children),
            set_node_bounds: Some(set_bounds),
            create_leaf: Some(create_leaf),
            split_primitive: Some(split),
            build_progress: None,
            user_ptr: &shared as *const Shared as *mut c_void,
        };
        let root = (builder.build_bvh)(&args);
        let time = start.elapsed();
        let tree = if root.is_null() {
            Err(anyhow::anyhow!("rtcBuildBVH failed: {}", api.error(device)))
        } else {
            to_bvh2(root as *const u32)
        };
        (builder.release_bvh)(bvh);
        (api.release_device)(device);
        Ok((tree?, time))
    }
}

/// The tree under `root` (an `Inner` or a `Leaf`) as a `Bvh2`: the root first, each node's two
/// children side by side, leaves' triangles in `primitive_indices`.
///
/// # Safety
/// `root` and everything under it are the build's live nodes and leaves.
unsafe fn to_bvh2(root: *const u32) -> anyhow::Result<Bvh2> {
    let mut out = Bvh2::default();
    out.nodes.push(Bvh2Node::default());
    // (node, its slot in `out.nodes`, its box)
    let mut todo = vec![(root, 0usize, Aabb::INVALID)];
    while let Some((node, slot, aabb)) = todo.pop() {
        // SAFETY: the caller's.
        unsafe {
            if *node == LEAF {
                let leaf = &*(node as *const Leaf);
                if leaf.count as usize > MAX_LEAF {
                    bail!("Embree made a leaf of {} triangles", leaf.count);
                }
                out.nodes[slot] = Bvh2Node {
                    aabb,
                    prim_count: leaf.count,
                    first_index: out.primitive_indices.len() as u32,
                    ..Default::default()
                };
                out.primitive_indices
                    .extend_from_slice(&leaf.ids[..leaf.count as usize]);
            } else {
                let inner = &*(node as *const Inner);
                if inner.count != 2 {
                    bail!("Embree made a node of {} children", inner.count);
                }
                let first = out.nodes.len();
                out.nodes.extend([Bvh2Node::default(); 2]);
                let mut union = Aabb::INVALID;
                for k in 0..2 {
                    let b = inner.bounds[k];
                    let child = Aabb::new(Vec3A::from(b.lower), Vec3A::from(b.upper));
                    union = union.union(&child);
                    todo.push((inner.children[k], first + k, child));
                }
                out.nodes[slot] = Bvh2Node {
                    aabb: if slot == 0 { union } else { aabb },
                    prim_count: 0,
                    first_index: first as u32,
                    ..Default::default()
                };
            }
        }
    }
    out.uses_spatial_splits = true;
    Ok(out)
}
