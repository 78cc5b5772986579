//! What the Embree 3 (`embree3.rs`) and Embree 4 (`embree4.rs`) peers share: the ray and hit
//! structures, the loops over a ray set, the build quality and the count of Embree's memory.
//!
//! ```text
//! layouts:  RTCRay, RTCRay8 are the same in Embree 3.13 and 4.4; Embree 4's RTCHit adds
//!           instPrimID after instID (RTC_GEOMETRY_INSTANCE_ARRAY, on in the release builds),
//!           so the structures here are 4.4's and Embree 3 writes a prefix of them
//! loops:    per ray set, Args made once (coherent or not); per ray or per 8 rays of a batch,
//!           one call of the version's EmbreeCalls, then (t, prim) or blocked pushed in order
//! ```
//!
//! The sizes and offsets asserted below are those `gcc` prints for Embree 4.4.0's headers
//! (`include/embree4/rtcore_ray.h`, with the release's `rtcore_config.h`: one instance level,
//! instance arrays on, no min-width) and for Debian's Embree 3.13.5 headers
//! (docs/BENCHMARKING.md, "The peer comparison").

use super::{Hits, RaySet};
use crate::render::geometry::T_MIN;
use crate::render::scene::{NO_HIT, Scene};
use crate::render::wavefront::batch::RayBatch;
use std::mem::{offset_of, size_of};
use std::sync::atomic::{AtomicI64, Ordering};

/// `RTC_INVALID_GEOMETRY_ID`.
pub(crate) const INVALID_ID: u32 = u32::MAX;

/// `RTCRay`: one ray (48 bytes, 16-aligned in both versions).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Ray1 {
    /// Origin x.
    pub org_x: f32,
    /// Origin y.
    pub org_y: f32,
    /// Origin z.
    pub org_z: f32,
    /// Start of the segment.
    pub tnear: f32,
    /// Direction x.
    pub dir_x: f32,
    /// Direction y.
    pub dir_y: f32,
    /// Direction z.
    pub dir_z: f32,
    /// Motion-blur time.
    pub time: f32,
    /// End of the segment; the hit distance after `rtcIntersect1`, −∞ after a blocked
    /// `rtcOccluded1`.
    pub tfar: f32,
    /// Ray mask.
    pub mask: u32,
    /// Ray id.
    pub id: u32,
    /// Ray flags.
    pub flags: u32,
}

/// `RTCHit` as Embree 4.4 declares it (48 bytes); Embree 3's is its first 32.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Hit1 {
    /// Geometric normal, unnormalised.
    pub ng: [f32; 3],
    /// Barycentric u.
    pub u: f32,
    /// Barycentric v.
    pub v: f32,
    /// Triangle index within its geometry.
    pub prim_id: u32,
    /// Geometry id; `INVALID_ID` on a miss.
    pub geom_id: u32,
    /// Instance id (one level).
    pub inst_id: u32,
    /// Embree 4's instance-array primitive id (Embree 3 has no such field).
    pub inst_prim_id: u32,
}

/// `RTCRayHit`.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct RayHit1 {
    /// The ray.
    pub ray: Ray1,
    /// Its hit.
    pub hit: Hit1,
}

/// `RTCRay8`: 8 rays as columns (384 bytes, 32-aligned).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Ray8 {
    /// Origins: x, y, z columns.
    pub org: [[f32; 8]; 3],
    /// Start of the segments.
    pub tnear: [f32; 8],
    /// Directions: x, y, z columns.
    pub dir: [[f32; 8]; 3],
    /// Motion-blur times.
    pub time: [f32; 8],
    /// Ends of the segments (hit distances, −∞ for blocked segments).
    pub tfar: [f32; 8],
    /// Ray masks.
    pub mask: [u32; 8],
    /// Ray ids.
    pub id: [u32; 8],
    /// Ray flags.
    pub flags: [u32; 8],
}

/// `RTCHit8` as Embree 4.4 declares it (288 bytes); Embree 3's is its first 256.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Hit8 {
    /// Geometric normals x, y, z.
    pub ng: [[f32; 8]; 3],
    /// Barycentric u.
    pub u: [f32; 8],
    /// Barycentric v.
    pub v: [f32; 8],
    /// Triangle indices.
    pub prim_id: [u32; 8],
    /// Geometry ids; `INVALID_ID` on a miss.
    pub geom_id: [u32; 8],
    /// Instance ids.
    pub inst_id: [u32; 8],
    /// Embree 4's instance-array primitive ids.
    pub inst_prim_id: [u32; 8],
}

/// `RTCRayHit8`.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct RayHit8 {
    /// The rays.
    pub ray: Ray8,
    /// Their hits.
    pub hit: Hit8,
}

/// The valid mask of an 8-ray call: −1 for a live lane, 0 for a masked one; 32-aligned, as
/// Embree's debug build checks.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Valid8(pub [i32; 8]);

// The layouts of the headers (see the module docs).
const _: () = {
    assert!(size_of::<Ray1>() == 48 && offset_of!(Ray1, tfar) == 32);
    assert!(offset_of!(Hit1, prim_id) == 20 && offset_of!(Hit1, inst_id) == 28);
    assert!(offset_of!(Hit1, inst_prim_id) == 32 && size_of::<Hit1>() == 48);
    assert!(offset_of!(RayHit1, hit) == 48 && size_of::<RayHit1>() == 96);
    assert!(size_of::<Ray8>() == 384 && offset_of!(Ray8, tfar) == 256);
    assert!(offset_of!(Ray8, flags) == 352);
    assert!(offset_of!(Hit8, u) == 96 && offset_of!(Hit8, prim_id) == 160);
    assert!(offset_of!(Hit8, geom_id) == 192 && offset_of!(Hit8, inst_id) == 224);
    assert!(offset_of!(Hit8, inst_prim_id) == 256 && size_of::<Hit8>() == 288);
    assert!(offset_of!(RayHit8, hit) == 384 && size_of::<RayHit8>() == 672);
    assert!(align_of::<Ray8>() == 32 && align_of::<Valid8>() == 32);
};

/// One Embree version's four ray calls; the loops over a ray set are the provided methods,
/// the same for every version, so that the versions' figures differ only by the library.
pub trait EmbreeCalls {
    /// What every call takes besides the rays (Embree 3's `RTCIntersectContext`, Embree 4's
    /// `RTCIntersectArguments` and `RTCOccludedArguments`), made once per ray set.
    type Args;

    /// The arguments for coherent rays (`COHERENT` flag) or incoherent ones.
    fn args(&self, coherent: bool) -> Self::Args;

    /// `rtcIntersect1`.
    fn intersect1(&self, args: &mut Self::Args, rayhit: &mut RayHit1);

    /// `rtcOccluded1`.
    fn occluded1(&self, args: &mut Self::Args, ray: &mut Ray1);

    /// `rtcIntersect8`.
    fn intersect8(&self, args: &mut Self::Args, valid: &Valid8, rayhit: &mut RayHit8);

    /// `rtcOccluded8`.
    fn occluded8(&self, args: &mut Self::Args, valid: &Valid8, ray: &mut Ray8);

    /// Closest hit of every ray with `rtcIntersect1`, into `out`.
    fn closest_single(&self, set: &RaySet, out: &mut Hits) {
        out.clear();
        let mut args = self.args(set.kind.is_coherent());
        for batch in &set.batches {
            for i in 0..batch.len() {
                let mut rh = RayHit1 {
                    ray: ray1(batch, i),
                    hit: EMPTY_HIT1,
                };
                self.intersect1(&mut args, &mut rh);
                if rh.hit.geom_id == INVALID_ID {
                    out.push(f32::INFINITY, NO_HIT);
                } else {
                    out.push(rh.ray.tfar, rh.hit.prim_id);
                }
            }
        }
    }

    /// Closest hits with `rtcIntersect8`, 8 consecutive rays of a batch per call, into `out`.
    fn closest_packet8(&self, set: &RaySet, out: &mut Hits) {
        out.clear();
        let mut args = self.args(set.kind.is_coherent());
        for batch in &set.batches {
            for start in (0..batch.len()).step_by(8) {
                let lanes = (batch.len() - start).min(8);
                let (ray, valid) = ray8(batch, start, lanes);
                let mut rh = RayHit8 {
                    ray,
                    hit: EMPTY_HIT8,
                };
                self.intersect8(&mut args, &valid, &mut rh);
                for k in 0..lanes {
                    if rh.hit.geom_id[k] == INVALID_ID {
                        out.push(f32::INFINITY, NO_HIT);
                    } else {
                        out.push(rh.ray.tfar[k], rh.hit.prim_id[k]);
                    }
                }
            }
        }
    }

    /// Occlusion of every segment with `rtcOccluded1` (tfar becomes −∞ when blocked).
    fn occluded_single(&self, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        let mut args = self.args(set.kind.is_coherent());
        for batch in &set.batches {
            for i in 0..batch.len() {
                let mut ray = ray1(batch, i);
                self.occluded1(&mut args, &mut ray);
                out.push(ray.tfar == f32::NEG_INFINITY);
            }
        }
    }

    /// Occlusion with `rtcOccluded8`, 8 consecutive segments per call.
    fn occluded_packet8(&self, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        let mut args = self.args(set.kind.is_coherent());
        for batch in &set.batches {
            for start in (0..batch.len()).step_by(8) {
                let lanes = (batch.len() - start).min(8);
                let (mut ray, valid) = ray8(batch, start, lanes);
                self.occluded8(&mut args, &valid, &mut ray);
                out.extend(ray.tfar[..lanes].iter().map(|&t| t == f32::NEG_INFINITY));
            }
        }
    }
}

/// A hit record before the call: no geometry, no instance.
pub(crate) const EMPTY_HIT1: Hit1 = Hit1 {
    ng: [0.0; 3],
    u: 0.0,
    v: 0.0,
    prim_id: INVALID_ID,
    geom_id: INVALID_ID,
    inst_id: INVALID_ID,
    inst_prim_id: INVALID_ID,
};

const EMPTY_HIT8: Hit8 = Hit8 {
    ng: [[0.0; 8]; 3],
    u: [0.0; 8],
    v: [0.0; 8],
    prim_id: [INVALID_ID; 8],
    geom_id: [INVALID_ID; 8],
    inst_id: [INVALID_ID; 8],
    inst_prim_id: [INVALID_ID; 8],
};

/// Ray `i` of `batch`, from `T_MIN` to its tmax.
pub(crate) fn ray1(batch: &RayBatch, i: usize) -> Ray1 {
    Ray1 {
        org_x: batch.origin.x[i],
        org_y: batch.origin.y[i],
        org_z: batch.origin.z[i],
        tnear: T_MIN,
        dir_x: batch.direction.x[i],
        dir_y: batch.direction.y[i],
        dir_z: batch.direction.z[i],
        time: 0.0,
        tfar: batch.tmax[i],
        mask: u32::MAX,
        id: i as u32,
        flags: 0,
    }
}

/// Rays `start..start + lanes` of `batch` (lanes ≤ 8) and their valid mask; lanes past them
/// are zero and masked.
fn ray8(batch: &RayBatch, start: usize, lanes: usize) -> (Ray8, Valid8) {
    let fill = |column: &[f32]| {
        let mut out = [0.0; 8];
        out[..lanes].copy_from_slice(&column[start..start + lanes]);
        out
    };
    let mut valid = Valid8([0; 8]);
    valid.0[..lanes].fill(-1);
    let ray = Ray8 {
        org: [
            fill(&batch.origin.x),
            fill(&batch.origin.y),
            fill(&batch.origin.z),
        ],
        tnear: [T_MIN; 8],
        dir: [
            fill(&batch.direction.x),
            fill(&batch.direction.y),
            fill(&batch.direction.z),
        ],
        time: [0.0; 8],
        tfar: fill(&batch.tmax),
        mask: [u32::MAX; 8],
        id: [0, 1, 2, 3, 4, 5, 6, 7],
        flags: [0; 8],
    };
    (ray, valid)
}

/// The scene's triangles as Embree's buffers: 3 vertices per triangle (v0, v0 + e1, v0 + e2,
/// the corners obvhs gets) and the index triple of triangle k = its index in
/// `Scene::triangles`, so that Embree's primID is raywave's.
pub(crate) fn fill_triangles(scene: &Scene, vertices: &mut [[f32; 3]], indices: &mut [[u32; 3]]) {
    for (k, tri) in scene.triangles.iter().enumerate() {
        vertices[3 * k] = tri.v0.to_array();
        vertices[3 * k + 1] = (tri.v0 + tri.e1).to_array();
        vertices[3 * k + 2] = (tri.v0 + tri.e2).to_array();
        let base = 3 * k as u32;
        indices[k] = [base, base + 1, base + 2];
    }
}

/// Embree's BVH build quality (`RTCBuildQuality`): which builder `rtcCommitScene` runs for a
/// static triangle scene (Embree 4.4's `Scene::createTriangleAccel` on AVX2: BVH8 over
/// Triangle4 leaves in each case).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildQuality {
    /// `RTC_BUILD_QUALITY_LOW`: a Morton-code two-level build, fastest to build, slowest to
    /// trace.
    Low,
    /// `RTC_BUILD_QUALITY_MEDIUM`, Embree's default: a binned SAH build.
    Medium,
    /// `RTC_BUILD_QUALITY_HIGH`: SAH with spatial splits (triangles split across nodes), the
    /// slowest build and usually the fastest tracing of a static scene.
    High,
}

impl BuildQuality {
    /// Every quality, from the fastest build to the slowest.
    pub const ALL: [BuildQuality; 3] =
        [BuildQuality::Low, BuildQuality::Medium, BuildQuality::High];

    /// The environment variable that chooses the peers' quality.
    pub const ENV: &'static str = "RAYWAVE_EMBREE_QUALITY";

    /// `low`, `medium` or `high`.
    pub fn name(self) -> &'static str {
        match self {
            BuildQuality::Low => "low",
            BuildQuality::Medium => "medium",
            BuildQuality::High => "high",
        }
    }

    /// The `RTCBuildQuality` value (0, 1, 2 in both versions' `rtcore_common.h`).
    pub fn rtc(self) -> u32 {
        match self {
            BuildQuality::Low => 0,
            BuildQuality::Medium => 1,
            BuildQuality::High => 2,
        }
    }

    /// The quality `RAYWAVE_EMBREE_QUALITY` names (`low`, `medium`, `high`), `High` when it
    /// is unset; an error names the variable and the values it takes.
    pub fn from_env() -> anyhow::Result<Self> {
        match std::env::var(Self::ENV) {
            Err(std::env::VarError::NotPresent) => Ok(BuildQuality::High),
            Ok(value) => Self::ALL
                .into_iter()
                .find(|q| q.name() == value)
                .ok_or_else(|| {
                    anyhow::anyhow!("{}={value}: expected low, medium or high", Self::ENV)
                }),
            Err(e) => anyhow::bail!("{}: {e}", Self::ENV),
        }
    }
}

/// Embree's device memory as its memory monitor reports it (`rtcSetDeviceMemoryMonitorFunction`:
/// every allocation and free of the device's buffers and BVH, from any build thread).
#[derive(Debug, Default)]
pub(crate) struct MemoryCount {
    now: AtomicI64,
    peak: AtomicI64,
}

impl MemoryCount {
    /// Bytes held now.
    pub(crate) fn now(&self) -> i64 {
        self.now.load(Ordering::Relaxed)
    }

    /// The most bytes held at once so far.
    pub(crate) fn peak(&self) -> i64 {
        self.peak.load(Ordering::Relaxed)
    }

    /// A committed build's bytes, `buffers` being what was held before `rtcCommitScene`.
    pub(crate) fn after_commit(&self, buffers: i64) -> EmbreeMemory {
        EmbreeMemory {
            buffers,
            bvh: self.now() - buffers,
            peak: self.peak(),
        }
    }
}

/// The `RTCMemoryMonitorFunction` of both versions: `ptr` is a `MemoryCount`, `bytes` > 0 for
/// an allocation and < 0 for a free. Returns true: never refuse.
///
/// # Safety
/// `ptr` points to a `MemoryCount` that outlives the device.
pub(crate) unsafe extern "C" fn count_memory(
    ptr: *mut std::ffi::c_void,
    bytes: isize,
    _post: bool,
) -> bool {
    // SAFETY: the device was given a pointer to a live `MemoryCount` (see the caller).
    let count = unsafe { &*(ptr as *const MemoryCount) };
    let now = count.now.fetch_add(bytes as i64, Ordering::Relaxed) + bytes as i64;
    count.peak.fetch_max(now, Ordering::Relaxed);
    true
}

/// The bytes of one Embree build, from its memory monitor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmbreeMemory {
    /// The vertex and index buffers (held before the commit).
    pub buffers: i64,
    /// What `rtcCommitScene` left held: the BVH, its Triangle4 leaves included.
    pub bvh: i64,
    /// The most held at once during the commit, buffers included.
    pub peak: i64,
}

impl EmbreeMemory {
    /// E.g. `BVH 88.1 MB (buffers 24.0 MB, peak in build 190.3 MB)`.
    pub fn describe(&self) -> String {
        let mb = |b: i64| b as f64 / 1e6;
        format!(
            "BVH {:.1} MB (buffers {:.1} MB, peak in build {:.1} MB)",
            mb(self.bvh),
            mb(self.buffers),
            mb(self.peak)
        )
    }
}
