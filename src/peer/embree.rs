//! The same triangles in an Embree 3 scene (feature `embree`): single rays (`rtcIntersect1`,
//! `rtcOccluded1`) and 8-ray packets (`rtcIntersect8`, `rtcOccluded8`).
//!
//! The `embree` crate (0.3.8) builds and links against Debian's Embree 3.13.5: its `sys`
//! bindings were generated from 3.12.1 with `RTC_MAX_INSTANCE_LEVEL_COUNT = 1` and no
//! `RTC_MIN_WIDTH`, which is exactly how Debian configures 3.13.5 (`rtcore_config.h`), so
//! `RTCIntersectContext`, `RTCRayHit` and `RTCRayHit8` have the same layout. Its safe wrapper
//! only offers single rays and 4-ray packets, and ties scenes to devices by lifetimes, so this
//! module calls `embree::sys` directly for everything: the device, the scene, and the
//! 8-wide packet calls. Embree (built without `EMBREE_BACKFACE_CULLING`) is two-sided.
//!
//! ```text
//! new:      one TRIANGLE geometry, 3 vertices per triangle (v0, v0 + e1, v0 + e2, the
//!           corners obvhs gets), primID = index in Scene::triangles; commit (medium quality)
//! single:   per ray, RTCRayHit { tnear = T_MIN, tfar = tmax }; hit when geomID is valid
//! packet8:  8 rays of a batch at a time in RTCRayHit8, valid = -1 for live lanes, 0 past
//!           the end of the batch
//! ```

use super::{Hits, RaySet};
use crate::render::geometry::T_MIN;
use crate::render::scene::{NO_HIT, Scene};
use embree::sys;
use std::time::{Duration, Instant};

/// `RTC_INVALID_GEOMETRY_ID`.
const INVALID_ID: u32 = u32::MAX;

/// An Embree device and committed scene over a raywave scene's triangles.
pub struct EmbreeMesh {
    device: sys::RTCDevice,
    scene: sys::RTCScene,
    /// Wall time of geometry upload and `rtcCommitScene` (Embree builds with all its threads).
    pub build_time: Duration,
}

// Embree scenes are safe to trace from several threads once committed.
unsafe impl Send for EmbreeMesh {}
unsafe impl Sync for EmbreeMesh {}

impl Drop for EmbreeMesh {
    fn drop(&mut self) {
        // SAFETY: both handles were created by `new` and are released once.
        unsafe {
            sys::rtcReleaseScene(self.scene);
            sys::rtcReleaseDevice(self.device);
        }
    }
}

impl EmbreeMesh {
    /// Uploads the triangles and builds Embree's BVH; errors carry Embree's error code.
    pub fn new(scene: &Scene) -> anyhow::Result<Self> {
        let start = Instant::now();
        // SAFETY: plain Embree API calls; the buffers returned by rtcSetNewGeometryBuffer are
        // written within the item counts they were created with.
        unsafe {
            let device = sys::rtcNewDevice(std::ptr::null());
            if device.is_null() {
                anyhow::bail!("rtcNewDevice failed (is libembree3 installed?)");
            }
            let n = scene.triangles.len();
            let geometry = sys::rtcNewGeometry(device, sys::RTCGeometryType::TRIANGLE);
            let vertices = sys::rtcSetNewGeometryBuffer(
                geometry,
                sys::RTCBufferType::VERTEX,
                0,
                sys::RTCFormat::FLOAT3,
                12,
                3 * n,
            ) as *mut [f32; 3];
            let indices = sys::rtcSetNewGeometryBuffer(
                geometry,
                sys::RTCBufferType::INDEX,
                0,
                sys::RTCFormat::UINT3,
                12,
                n,
            ) as *mut [u32; 3];
            if vertices.is_null() || indices.is_null() {
                let error = sys::rtcGetDeviceError(device);
                sys::rtcReleaseGeometry(geometry);
                sys::rtcReleaseDevice(device);
                anyhow::bail!("Embree could not allocate buffers for {n} triangles: {error:?}");
            }
            let vertices = std::slice::from_raw_parts_mut(vertices, 3 * n);
            let indices = std::slice::from_raw_parts_mut(indices, n);
            for (k, tri) in scene.triangles.iter().enumerate() {
                vertices[3 * k] = tri.v0.to_array();
                vertices[3 * k + 1] = (tri.v0 + tri.e1).to_array();
                vertices[3 * k + 2] = (tri.v0 + tri.e2).to_array();
                let base = 3 * k as u32;
                indices[k] = [base, base + 1, base + 2];
            }
            sys::rtcCommitGeometry(geometry);
            let rtc_scene = sys::rtcNewScene(device);
            sys::rtcSetSceneBuildQuality(rtc_scene, sys::RTCBuildQuality::MEDIUM);
            sys::rtcAttachGeometry(rtc_scene, geometry);
            sys::rtcReleaseGeometry(geometry);
            sys::rtcCommitScene(rtc_scene);
            let error = sys::rtcGetDeviceError(device);
            if error != sys::RTCError::NONE {
                sys::rtcReleaseScene(rtc_scene);
                sys::rtcReleaseDevice(device);
                anyhow::bail!("Embree scene build failed: {error:?}");
            }
            Ok(EmbreeMesh {
                device,
                scene: rtc_scene,
                build_time: start.elapsed(),
            })
        }
    }

    /// Embree's version and whether it has native 8-wide packets and backface culling, e.g.
    /// `"Embree 3.13.5, native ray8: yes, backface culling: no"`.
    pub fn describe(&self) -> String {
        let prop = |p| unsafe { sys::rtcGetDeviceProperty(self.device, p) };
        let yes = |v: isize| if v != 0 { "yes" } else { "no" };
        let version = prop(sys::RTCDeviceProperty::VERSION);
        format!(
            "Embree {}.{}.{}, native ray8: {}, backface culling: {}",
            version / 10000,
            version / 100 % 100,
            version % 100,
            yes(prop(sys::RTCDeviceProperty::NATIVE_RAY8_SUPPORTED)),
            yes(prop(sys::RTCDeviceProperty::BACKFACE_CULLING_ENABLED)),
        )
    }

    /// Closest hit of every ray with `rtcIntersect1`, into `out`.
    pub fn closest1(&self, set: &RaySet, coherent: bool, out: &mut Hits) {
        out.clear();
        let mut ctx = context(coherent);
        for batch in &set.batches {
            for i in 0..batch.len() {
                let mut rh = sys::RTCRayHit {
                    ray: ray1(batch, i),
                    hit: empty_hit1(),
                };
                // SAFETY: a committed scene and a fully initialised ray/hit.
                unsafe { sys::rtcIntersect1(self.scene, &mut ctx, &mut rh) };
                if rh.hit.geomID == INVALID_ID {
                    out.push(f32::INFINITY, NO_HIT);
                } else {
                    out.push(rh.ray.tfar, rh.hit.primID);
                }
            }
        }
    }

    /// Closest hits with `rtcIntersect8`, 8 rays of a batch per call, into `out`.
    pub fn closest8(&self, set: &RaySet, coherent: bool, out: &mut Hits) {
        out.clear();
        let mut ctx = context(coherent);
        for batch in &set.batches {
            for start in (0..batch.len()).step_by(8) {
                let lanes = (batch.len() - start).min(8);
                let (ray, valid) = ray8(batch, start, lanes);
                let mut rh = sys::RTCRayHit8 {
                    ray,
                    hit: empty_hit8(),
                };
                // SAFETY: `RTCRayHit8` is 32-byte aligned by its type; invalid lanes are masked.
                unsafe { sys::rtcIntersect8(valid.as_ptr(), self.scene, &mut ctx, &mut rh) };
                for k in 0..lanes {
                    if rh.hit.geomID[k] == INVALID_ID {
                        out.push(f32::INFINITY, NO_HIT);
                    } else {
                        out.push(rh.ray.tfar[k], rh.hit.primID[k]);
                    }
                }
            }
        }
    }

    /// Occlusion of every segment with `rtcOccluded1` (tfar becomes −inf when blocked).
    pub fn occluded1(&self, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        let mut ctx = context(true);
        for batch in &set.batches {
            for i in 0..batch.len() {
                let mut ray = ray1(batch, i);
                // SAFETY: a committed scene and a fully initialised ray.
                unsafe { sys::rtcOccluded1(self.scene, &mut ctx, &mut ray) };
                out.push(ray.tfar == f32::NEG_INFINITY);
            }
        }
    }

    /// Occlusion with `rtcOccluded8`, 8 segments per call.
    pub fn occluded8(&self, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        let mut ctx = context(true);
        for batch in &set.batches {
            for start in (0..batch.len()).step_by(8) {
                let lanes = (batch.len() - start).min(8);
                let (mut ray, valid) = ray8(batch, start, lanes);
                // SAFETY: as in `closest8`.
                unsafe { sys::rtcOccluded8(valid.as_ptr(), self.scene, &mut ctx, &mut ray) };
                out.extend(ray.tfar[..lanes].iter().map(|&t| t == f32::NEG_INFINITY));
            }
        }
    }
}

/// `rtcInitIntersectContext` (an inline function in the C header) with a coherence hint.
fn context(coherent: bool) -> sys::RTCIntersectContext {
    sys::RTCIntersectContext {
        flags: if coherent {
            sys::RTCIntersectContextFlags::COHERENT
        } else {
            sys::RTCIntersectContextFlags::INCOHERENT
        },
        filter: None,
        instID: [INVALID_ID],
    }
}

fn ray1(batch: &crate::render::wavefront::batch::RayBatch, i: usize) -> sys::RTCRay {
    sys::RTCRay {
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

fn empty_hit1() -> sys::RTCHit {
    sys::RTCHit {
        Ng_x: 0.0,
        Ng_y: 0.0,
        Ng_z: 0.0,
        u: 0.0,
        v: 0.0,
        primID: INVALID_ID,
        geomID: INVALID_ID,
        instID: [INVALID_ID],
    }
}

fn ray8(
    batch: &crate::render::wavefront::batch::RayBatch,
    start: usize,
    lanes: usize,
) -> (sys::RTCRay8, [i32; 8]) {
    let fill = |column: &[f32]| {
        let mut out = [0.0; 8];
        out[..lanes].copy_from_slice(&column[start..start + lanes]);
        out
    };
    let mut valid = [0i32; 8];
    valid[..lanes].fill(-1);
    let ray = sys::RTCRay8 {
        org_x: fill(&batch.origin.x),
        org_y: fill(&batch.origin.y),
        org_z: fill(&batch.origin.z),
        tnear: [T_MIN; 8],
        dir_x: fill(&batch.direction.x),
        dir_y: fill(&batch.direction.y),
        dir_z: fill(&batch.direction.z),
        time: [0.0; 8],
        tfar: fill(&batch.tmax),
        mask: [u32::MAX; 8],
        id: [0, 1, 2, 3, 4, 5, 6, 7],
        flags: [0; 8],
    };
    (ray, valid)
}

fn empty_hit8() -> sys::RTCHit8 {
    sys::RTCHit8 {
        Ng_x: [0.0; 8],
        Ng_y: [0.0; 8],
        Ng_z: [0.0; 8],
        u: [0.0; 8],
        v: [0.0; 8],
        primID: [INVALID_ID; 8],
        geomID: [INVALID_ID; 8],
        instID: [[INVALID_ID; 8]],
    }
}
