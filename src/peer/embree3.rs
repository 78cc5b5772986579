//! The same triangles in an Embree 3 scene (feature `embree`): single rays (`rtcIntersect1`,
//! `rtcOccluded1`) and 8-ray packets (`rtcIntersect8`, `rtcOccluded8`), through the loops of
//! `embree_shared::EmbreeCalls`, as the Embree 4 peer (`embree4.rs`) runs them.
//!
//! The `embree` crate (0.3.8) builds and links against Debian's Embree 3.13.5: its `sys`
//! bindings were generated from 3.12.1 with `RTC_MAX_INSTANCE_LEVEL_COUNT = 1` and no
//! `RTC_MIN_WIDTH`, which is exactly how Debian configures 3.13.5 (`rtcore_config.h`), so
//! `RTCIntersectContext`, `RTCRayHit` and `RTCRayHit8` have the same layout. Its safe wrapper
//! only offers single rays and 4-ray packets, and ties scenes to devices by lifetimes, so this
//! module calls `embree::sys` directly for everything. The rays and hits are
//! `embree_shared`'s (Embree 4.4's layout, whose hit is Embree 3's with one more field at the
//! end), passed by pointer; the assertions below hold the two layouts together. Embree (built
//! without `EMBREE_BACKFACE_CULLING`) is two-sided.

use super::embree_shared::{
    BuildQuality, EmbreeCalls, EmbreeMemory, INVALID_ID, MemoryCount, Ray1, Ray8, RayHit1, RayHit8,
    Valid8, count_memory, fill_triangles,
};
use crate::render::scene::Scene;
use embree::sys;
use std::mem::{offset_of, size_of};
use std::time::{Duration, Instant};

// Embree 3's structures are prefixes of the shared ones.
const _: () = {
    assert!(size_of::<sys::RTCRay>() == size_of::<Ray1>());
    assert!(size_of::<sys::RTCRay8>() == size_of::<Ray8>());
    assert!(offset_of!(sys::RTCRayHit, hit) == offset_of!(RayHit1, hit));
    assert!(offset_of!(sys::RTCRayHit8, hit) == offset_of!(RayHit8, hit));
    assert!(size_of::<sys::RTCRayHit>() <= size_of::<RayHit1>());
    assert!(size_of::<sys::RTCRayHit8>() <= size_of::<RayHit8>());
    assert!(offset_of!(sys::RTCHit, primID) == offset_of!(super::embree_shared::Hit1, prim_id));
    assert!(offset_of!(sys::RTCHit, geomID) == offset_of!(super::embree_shared::Hit1, geom_id));
    assert!(offset_of!(sys::RTCHit8, geomID) == offset_of!(super::embree_shared::Hit8, geom_id));
    assert!(offset_of!(sys::RTCRay8, tfar) == offset_of!(Ray8, tfar));
};

/// An Embree 3 device and committed scene over a raywave scene's triangles.
pub struct Embree3Mesh {
    device: sys::RTCDevice,
    scene: sys::RTCScene,
    /// The quality the BVH was built with.
    pub quality: BuildQuality,
    /// Wall time of geometry upload and `rtcCommitScene` (Embree builds with all its threads).
    pub build_time: Duration,
    /// The device's bytes, from its memory monitor.
    pub memory: EmbreeMemory,
    // The device's memory monitor writes here until the device is released in `drop`.
    _count: Box<MemoryCount>,
}

// Embree scenes are safe to trace from several threads once committed.
unsafe impl Send for Embree3Mesh {}
unsafe impl Sync for Embree3Mesh {}

impl Drop for Embree3Mesh {
    fn drop(&mut self) {
        // SAFETY: both handles were created by `new` and are released once.
        unsafe {
            sys::rtcReleaseScene(self.scene);
            sys::rtcReleaseDevice(self.device);
        }
    }
}

impl Embree3Mesh {
    /// Uploads the triangles and builds Embree's BVH at `quality`; errors carry Embree's
    /// error code.
    pub fn new(scene: &Scene, quality: BuildQuality) -> anyhow::Result<Self> {
        let start = Instant::now();
        let count = Box::<MemoryCount>::default();
        // SAFETY: plain Embree API calls; the buffers returned by rtcSetNewGeometryBuffer are
        // written within the item counts they were created with; `count` outlives the device.
        unsafe {
            let device = sys::rtcNewDevice(std::ptr::null());
            if device.is_null() {
                anyhow::bail!("rtcNewDevice failed (is libembree3 installed?)");
            }
            let count_ptr = &*count as *const MemoryCount as *mut std::ffi::c_void;
            sys::rtcSetDeviceMemoryMonitorFunction(device, Some(count_memory), count_ptr);
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
            fill_triangles(
                scene,
                std::slice::from_raw_parts_mut(vertices, 3 * n),
                std::slice::from_raw_parts_mut(indices, n),
            );
            sys::rtcCommitGeometry(geometry);
            let rtc_scene = sys::rtcNewScene(device);
            sys::rtcSetSceneBuildQuality(rtc_scene, rtc_quality(quality));
            sys::rtcAttachGeometry(rtc_scene, geometry);
            sys::rtcReleaseGeometry(geometry);
            let buffers = count.now();
            sys::rtcCommitScene(rtc_scene);
            let error = sys::rtcGetDeviceError(device);
            if error != sys::RTCError::NONE {
                sys::rtcReleaseScene(rtc_scene);
                sys::rtcReleaseDevice(device);
                anyhow::bail!("Embree scene build failed: {error:?}");
            }
            Ok(Embree3Mesh {
                device,
                scene: rtc_scene,
                quality,
                build_time: start.elapsed(),
                memory: count.after_commit(buffers),
                _count: count,
            })
        }
    }

    /// Embree's version, the build quality and whether it has native 8-wide packets and
    /// backface culling, e.g. `"Embree 3.13.5 (quality high, native ray8: yes, backface
    /// culling: no)"`.
    pub fn describe(&self) -> String {
        let prop = |p| unsafe { sys::rtcGetDeviceProperty(self.device, p) };
        let yes = |v: isize| if v != 0 { "yes" } else { "no" };
        let version = prop(sys::RTCDeviceProperty::VERSION);
        format!(
            "Embree {}.{}.{} (quality {}, native ray8: {}, backface culling: {})",
            version / 10000,
            version / 100 % 100,
            version % 100,
            self.quality.name(),
            yes(prop(sys::RTCDeviceProperty::NATIVE_RAY8_SUPPORTED)),
            yes(prop(sys::RTCDeviceProperty::BACKFACE_CULLING_ENABLED)),
        )
    }
}

/// The `embree` crate's name for a quality.
fn rtc_quality(quality: BuildQuality) -> sys::RTCBuildQuality {
    match quality {
        BuildQuality::Low => sys::RTCBuildQuality::LOW,
        BuildQuality::Medium => sys::RTCBuildQuality::MEDIUM,
        BuildQuality::High => sys::RTCBuildQuality::HIGH,
    }
}

impl EmbreeCalls for Embree3Mesh {
    type Args = sys::RTCIntersectContext;

    /// `rtcInitIntersectContext` (an inline function in the C header) with a coherence hint.
    fn args(&self, coherent: bool) -> sys::RTCIntersectContext {
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

    #[inline]
    fn intersect1(&self, ctx: &mut sys::RTCIntersectContext, rayhit: &mut RayHit1) {
        // SAFETY: a committed scene and a fully initialised ray/hit, of which Embree 3's
        // RTCRayHit is a prefix (asserted above).
        unsafe { sys::rtcIntersect1(self.scene, ctx, (rayhit as *mut RayHit1).cast()) }
    }

    #[inline]
    fn occluded1(&self, ctx: &mut sys::RTCIntersectContext, ray: &mut Ray1) {
        // SAFETY: as in `intersect1`; the layouts are equal.
        unsafe { sys::rtcOccluded1(self.scene, ctx, (ray as *mut Ray1).cast()) }
    }

    #[inline]
    fn intersect8(&self, ctx: &mut sys::RTCIntersectContext, valid: &Valid8, rayhit: &mut RayHit8) {
        // SAFETY: 32-aligned by their types; invalid lanes are masked; a prefix layout.
        unsafe {
            sys::rtcIntersect8(
                valid.0.as_ptr(),
                self.scene,
                ctx,
                (rayhit as *mut RayHit8).cast(),
            )
        }
    }

    #[inline]
    fn occluded8(&self, ctx: &mut sys::RTCIntersectContext, valid: &Valid8, ray: &mut Ray8) {
        // SAFETY: as in `intersect8`.
        unsafe { sys::rtcOccluded8(valid.0.as_ptr(), self.scene, ctx, (ray as *mut Ray8).cast()) }
    }
}
