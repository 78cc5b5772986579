//! The same triangles in tinybvh (feature `tinybvh`), through the `tinybvh-rs` crate
//! (0.1.0-beta.3, pinned: it compiles tinybvh 1.6.8's C++ with cxx and `-march=native`).
//!
//! What the crate offers, and so what this module can time:
//!
//! - two CPU layouts with a closest-hit `Intersect`: the plain binary BVH (tinybvh's `BVH`,
//!   "Wald" layout, binned SAH build) and `BVH8_CPU` (8-wide nodes, leaves of 4 triangles,
//!   Fuetterling et al. 2017), the latter only where the build has AVX2 (the crate's own
//!   `cfg`); `BVH4_CPU` exists in the C++ but the crate does not bind it;
//! - **no occlusion query**: tinybvh's C++ has `IsOccluded`, but the crate does not bind it,
//!   so shadow segments are traced here with the closest-hit `Intersect` limited to the
//!   segment (`hit.t = tmax` on entry; blocked when a hit is found), which keeps looking for a
//!   closer hit after the first blocker. Every table and note that shows these figures says
//!   "closest hit ≤ tmax";
//! - no packets (`Intersect256Rays` is not bound either): one ray per call.
//!
//! ```text
//! new:      positions = 3 × [x, y, z, 0] per triangle (v0, v0 + e1, v0 + e2, the corners
//!           obvhs and Embree get), in Scene::triangles order, so hit.prim is raywave's id
//!           wald  = BVH::new(positions)                       (the crate's default build)
//!           bvh8  = BVH::new(positions).split_leaves(4) → MBVH8 → BVH8_CPU
//! per ray:  Ray { O, D, rD = safercp(D), hit.t = min(tmax, 1e30), hit.prim = NO_HIT }
//!           in a 128-byte, 64-aligned slot (see `RaySlot`); Intersect; hit when prim changed
//! ```
//!
//! tinybvh's triangle tests are two-sided (|det| < 1e-6 is a miss in the plain layout's
//! scalar test, an absolute bound that small triangles seen at a slant fall under: 209 of the
//! 211 camera rays it disagrees with raywave on in the 1M box at 256×256, the other two
//! through a crack between two triangles, which its test has no slack for;
//! `BVH8_CPU` takes an approximate 1/det), and accept t ≥ 0 (plain: −0 too) or t > 0
//! (`BVH8_CPU`) where raywave and Embree need t > 0. The ray sets leave every surface by 1e-4,
//! but a ray that leaves the box's edge lies in the other wall's plane: the plain layout hits
//! that wall at t = −0 (71 of 43,264 shadow rays of the mesh test scene at 256×256), which
//! `peer::NEAR_ORIGIN_T` and `blocker_agreement` count as agreeing. Agreement with raywave is
//! checked in `tests/kernels/peer_agreement.rs` and printed with every peer table.

use super::{Hits, RaySet};
use raywave::render::scene::{NO_HIT, Scene};
use raywave::render::wavefront::batch::RayBatch;
use std::cell::RefCell;
use std::time::{Duration, Instant};
use tinybvh_rs::{Intersection, Intersector, Ray, bvh};
#[cfg(target_feature = "avx2")]
use tinybvh_rs::{bvh8_cpu, mbvh};

/// tinybvh's "no hit" distance (`BVH_FAR`, 1e30): the crate's rays start with it.
const FAR: f32 = tinybvh_rs::INFINITE;

/// One tinybvh layout, for table columns and benchmark ids.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TinybvhLayout {
    /// The plain binary BVH (`tinybvh::BVH`, 32-byte Wald nodes), traversed one ray at a time.
    Wald,
    /// `tinybvh::BVH8_CPU`: 8-wide nodes, 4-triangle leaves, AVX2 traversal.
    Bvh8Cpu,
}

impl TinybvhLayout {
    /// The layouts this build can trace: `Bvh8Cpu` needs AVX2 (the crate binds its `Intersect`
    /// only then).
    pub const ALL: &'static [TinybvhLayout] = &[
        TinybvhLayout::Wald,
        #[cfg(target_feature = "avx2")]
        TinybvhLayout::Bvh8Cpu,
    ];

    /// Short name, for benchmark ids: `tinybvh_bvh`, `tinybvh_bvh8_cpu`.
    pub fn name(self) -> &'static str {
        match self {
            TinybvhLayout::Wald => "tinybvh_bvh",
            TinybvhLayout::Bvh8Cpu => "tinybvh_bvh8_cpu",
        }
    }

    /// Column title in the peer table.
    pub fn title(self) -> &'static str {
        match self {
            TinybvhLayout::Wald => "tinybvh BVH",
            TinybvhLayout::Bvh8Cpu => "tinybvh BVH8_CPU",
        }
    }
}

/// tinybvh's BVHs over a raywave scene's triangles.
pub struct TinybvhMesh {
    /// The plain BVH, unbound between calls. `bvh::BVH<'a>` borrows the positions, which a
    /// struct cannot hold beside them without `unsafe`; each call binds it again, which is
    /// one pointer store in the C++ (`BVH_setPrimitives`), outside the per-ray loop.
    wald: RefCell<Option<bvh::BVHData>>,
    /// 3 vertices per triangle: what `wald` traces against.
    positions: Vec<[f32; 4]>,
    /// `BVH8_CPU`, which keeps its own copy of the triangles.
    #[cfg(target_feature = "avx2")]
    bvh8: bvh8_cpu::BVH,
    /// Wall time of the plain BVH's build (vertex conversion included).
    pub wald_build_time: Duration,
    /// Wall time of the `BVH8_CPU` chain: build, split to 4-triangle leaves, MBVH8, convert.
    pub bvh8_build_time: Duration,
}

impl TinybvhMesh {
    /// Builds both layouts; errors carry the crate's message.
    pub fn new(scene: &Scene) -> anyhow::Result<Self> {
        let start = Instant::now();
        let positions: Vec<[f32; 4]> = scene
            .triangles
            .iter()
            .flat_map(|t| [t.v0, t.v0 + t.e1, t.v0 + t.e2])
            .map(|v| [v.x, v.y, v.z, 0.0])
            .collect();
        let wald = bvh::BVH::new(positions.as_slice().into())
            .map_err(|e| anyhow::anyhow!("tinybvh BVH build: {e}"))?
            .data();
        let wald_build_time = start.elapsed();
        let start = Instant::now();
        #[cfg(target_feature = "avx2")]
        let bvh8 = {
            let mut binary = bvh::BVH::new(positions.as_slice().into())
                .map_err(|e| anyhow::anyhow!("tinybvh BVH build: {e}"))?;
            // BVH8_CPU's leaves hold 4 triangles; the crate refuses other BVHs.
            binary.split_leaves(4);
            let wide = mbvh::BVH::new(&binary);
            bvh8_cpu::BVH::new(&wide).map_err(|e| anyhow::anyhow!("tinybvh BVH8_CPU: {e}"))?
        };
        Ok(TinybvhMesh {
            wald: RefCell::new(Some(wald)),
            positions,
            #[cfg(target_feature = "avx2")]
            bvh8,
            wald_build_time,
            bvh8_build_time: start.elapsed(),
        })
    }

    /// `trace(ray)` with `layout`'s `Intersect` over every ray of the set, in order.
    fn each_ray(&self, layout: TinybvhLayout, set: &RaySet, mut take: impl FnMut(&Ray, f32)) {
        match layout {
            TinybvhLayout::Wald => {
                let data = self
                    .wald
                    .take()
                    .expect("the plain BVH is bound back after each call");
                let wald = data
                    .bvh(self.positions.as_slice().into())
                    .expect("the positions it was built from");
                trace_set(&wald, set, &mut take);
                self.wald.replace(Some(wald.data()));
            }
            #[cfg(target_feature = "avx2")]
            TinybvhLayout::Bvh8Cpu => trace_set(&self.bvh8, set, &mut take),
            #[cfg(not(target_feature = "avx2"))]
            TinybvhLayout::Bvh8Cpu => panic!("BVH8_CPU needs an AVX2 build"),
        }
    }

    /// Closest hit of every ray with `layout`'s `Intersect`, into `out`.
    pub fn closest(&self, layout: TinybvhLayout, set: &RaySet, out: &mut Hits) {
        out.clear();
        self.each_ray(layout, set, |ray, _| {
            if ray.hit.prim == NO_HIT {
                out.push(f32::INFINITY, NO_HIT);
            } else {
                out.push(ray.hit.t, ray.hit.prim);
            }
        });
    }

    /// Occlusion of every segment **by a closest-hit query limited to tmax** (the crate has no
    /// any-hit query): blocked when `Intersect` found a hit closer than tmax.
    pub fn occluded_by_closest(&self, layout: TinybvhLayout, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        self.each_ray(layout, set, |ray, tmax| out.push(blocks(ray, tmax)));
    }

    /// The blocker `occluded_by_closest` found on every segment, its closest hit in [0, tmax):
    /// t and prim, or `INFINITY`, `NO_HIT` for a free segment. For agreement checks
    /// (`peer::blocker_agreement`): the plain layout accepts t = 0, so a segment that starts on
    /// another surface's plane is blocked there at t = −0 or 0.
    pub fn blockers(&self, layout: TinybvhLayout, set: &RaySet, out: &mut Hits) {
        out.clear();
        self.each_ray(layout, set, |ray, tmax| {
            if blocks(ray, tmax) {
                out.push(ray.hit.t, ray.hit.prim);
            } else {
                out.push(f32::INFINITY, NO_HIT);
            }
        });
    }
}

/// Whether a traced segment of length `tmax` is blocked: a hit was found short of tmax (tinybvh
/// accepts t = tmax, raywave's and Embree's segments are open there).
fn blocks(ray: &Ray, tmax: f32) -> bool {
    ray.hit.prim != NO_HIT && ray.hit.t < tmax
}

/// Room for one C++ `tinybvh::Ray`, whose first 64 bytes are the crate's `Ray`.
///
/// tinybvh 1.6.8's `Ray` is 128 bytes and 64-byte aligned (its `Intersection` carries an
/// instance id, an `auxData` pointer and 56 bytes of user data); the crate's `Ray` is 64 bytes,
/// 16-aligned, laid out like the first 64 (origin, mask, direction, instIdx, 1/direction, then
/// inst, t, u, v, prim), which is all that traversal reads and writes. The crate's `Ray::new`
/// returns a C++ `Ray` by value into a 64-byte Rust value, so it is never called here; rays
/// are built in Rust, in a slot with the C++ size and alignment.
#[repr(C, align(64))]
struct RaySlot {
    ray: Ray,
    /// C++'s `auxData` and user data: never touched by traversal.
    _tail: [u8; 64],
}

/// What `Ray::new` would set for a ray of the set: the C++ constructor without its
/// normalisation (the sets' directions are unit vectors, and the comparison wants every
/// engine to trace the same bits), with `hit.t` = tmax clamped to tinybvh's 1e30.
fn ray(batch: &RayBatch, i: usize) -> Ray {
    let d = [
        batch.direction.x[i],
        batch.direction.y[i],
        batch.direction.z[i],
    ];
    Ray {
        origin: [batch.origin.x[i], batch.origin.y[i], batch.origin.z[i]],
        // C++: `mask` = RAY_MASK_INTERSECT_ALL (only TLAS traversal reads it).
        padding_0: 0xffff,
        dir: d,
        // C++: `instIdx`.
        padding_1: 0,
        r_d: d.map(safe_rcp),
        // C++: `hit.inst`.
        padding_2: 0,
        hit: Intersection {
            t: batch.tmax[i].min(FAR),
            u: 0.0,
            v: 0.0,
            prim: NO_HIT,
        },
    }
}

/// tinybvh's `tinybvh_safercp`: 1/x, or ±1e30 for |x| ≤ 1e-12.
fn safe_rcp(x: f32) -> f32 {
    if !(-1e-12..=1e-12).contains(&x) {
        1.0 / x
    } else if x >= 0.0 {
        FAR
    } else {
        -FAR
    }
}

/// Every ray of the set through `bvh.intersect`, each result handed to `take` with its tmax.
fn trace_set(bvh: &impl Intersector, set: &RaySet, take: &mut impl FnMut(&Ray, f32)) {
    let mut slot = RaySlot {
        ray: Ray::default(),
        _tail: [0; 64],
    };
    for batch in &set.batches {
        for i in 0..batch.len() {
            slot.ray = ray(batch, i);
            bvh.intersect(&mut slot.ray);
            take(&slot.ray, batch.tmax[i]);
        }
    }
}
