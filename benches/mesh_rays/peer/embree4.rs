//! The same triangles in an Embree 4 scene (feature `embree4`): single rays (`rtcIntersect1`,
//! `rtcOccluded1`) and 8-ray packets (`rtcIntersect8`, `rtcOccluded8`).
//!
//! ```text
//! library:  libembree4*.so.4 in $RAYWAVE_EMBREE4_DIR (at run time, else as it was at build
//!           time, e.g. the embreex 4.4.0 wheel's embreex.libs/), else libembree4.so.4 on the
//!           system's library path; dlopen'ed once, RTLD_LOCAL | RTLD_DEEPBIND
//! new:      device (memory monitor on), one TRIANGLE geometry (fill_triangles), scene at the
//!           chosen BuildQuality, commit; bytes before and after the commit
//! loops:    per ray set, one QueryArguments (RTCIntersectArguments / RTCOccludedArguments as
//!           rtcInitIntersectArguments makes them: all features, no context, no callbacks;
//!           COHERENT on every set but the incoherent one); per ray or per 8 rays of a batch,
//!           one call, then (t, prim) or blocked pushed in order
//! ```
//!
//! Why dlopen and not a link: the wheel's library is renamed (`libembree4-4aef3270.so.4`),
//! which `-lembree4` does not answer, and its TBB exports the same names as any other TBB in
//! the process; loaded locally with deep binding, Embree 4 and its TBB resolve their own
//! symbols. The crate `embree4-sys` (0.0.12) was not used: it carries Embree 4.2's headers,
//! generates its bindings with bindgen (libclang) and links `-lembree4`. The few declarations
//! here follow Embree 4.4.0's `include/embree4/*.h`; the sizes and offsets asserted below are
//! those `gcc` prints for them (`rtcore_ray.h` with the release's `rtcore_config.h`: one
//! instance level, instance arrays on, no min-width). Embree (built without
//! `EMBREE_BACKFACE_CULLING`) is two-sided.

#[cfg(not(target_os = "linux"))]
compile_error!("the embree4 feature loads libembree4 with dlopen and RTLD_DEEPBIND: Linux only");

use super::{Hits, RaySet};
use anyhow::{Context as _, bail};
use raywave::render::geometry::T_MIN;
use raywave::render::scene::{NO_HIT, Scene};
use raywave::render::wavefront::batch::RayBatch;
use std::ffi::{CStr, CString, c_char, c_void};
use std::mem::offset_of;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicI64, Ordering};
use std::time::{Duration, Instant};

/// The variable naming the folder that holds `libembree4*.so.4` (read at run time, and at
/// build time for the default).
const DIR_ENV: &str = "RAYWAVE_EMBREE4_DIR";

pub(super) type Device = *mut c_void;
type Geometry = *mut c_void;
type RtcScene = *mut c_void;
type MemoryMonitor = unsafe extern "C" fn(*mut c_void, isize, bool) -> bool;

/// `RTCIntersectArguments` and `RTCOccludedArguments` (one layout: flags, feature mask,
/// context, filter, callback; no `minWidthDistanceFactor`, `RTC_MIN_WIDTH` is 0).
#[repr(C)]
pub struct QueryArguments {
    flags: u32,
    feature_mask: u32,
    context: *mut c_void,
    filter: *const c_void,
    callback: *const c_void,
}

impl QueryArguments {
    /// The arguments of one ray set: coherent rays (`COHERENT` flag) or incoherent ones.
    pub fn new(coherent: bool) -> Self {
        QueryArguments {
            flags: if coherent { COHERENT } else { 0 },
            feature_mask: FEATURE_ALL,
            context: std::ptr::null_mut(),
            filter: std::ptr::null(),
            callback: std::ptr::null(),
        }
    }
}

const _: () = assert!(size_of::<QueryArguments>() == 32);

/// `RTC_RAY_QUERY_FLAG_COHERENT` (`INCOHERENT` is 0).
const COHERENT: u32 = 1 << 16;
/// `RTC_FEATURE_FLAG_ALL`.
const FEATURE_ALL: u32 = u32::MAX;
/// `RTC_GEOMETRY_TYPE_TRIANGLE`, `RTC_BUFFER_TYPE_INDEX`/`VERTEX`, `RTC_FORMAT_UINT3`/`FLOAT3`.
const TRIANGLE: u32 = 0;
const INDEX: u32 = 0;
const VERTEX: u32 = 1;
const UINT3: u32 = 0x5003;
const FLOAT3: u32 = 0x9003;
/// `RTCDeviceProperty` values.
const PROPERTY_VERSION: u32 = 0;
const PROPERTY_NATIVE_RAY8: u32 = 33;
const PROPERTY_BACKFACE_CULLING: u32 = 65;

/// `RTC_INVALID_GEOMETRY_ID`.
const INVALID_ID: u32 = u32::MAX;

/// `RTCRay`: one ray (48 bytes, 16-aligned).
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

/// `RTCHit` (48 bytes).
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
    /// Instance-array primitive id (`RTC_GEOMETRY_INSTANCE_ARRAY`, on in the release builds).
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

/// `RTCHit8` (288 bytes).
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

/// The library's entry points this module calls, resolved once by `dlsym`; other modules
/// resolve theirs with [`Api::function`].
pub(super) struct Api {
    path: PathBuf,
    /// The `dlopen` handle, never closed.
    handle: usize,
    pub(super) new_device: unsafe extern "C" fn(*const c_char) -> Device,
    pub(super) release_device: unsafe extern "C" fn(Device),
    device_property: unsafe extern "C" fn(Device, u32) -> isize,
    device_error: unsafe extern "C" fn(Device) -> u32,
    last_error_message: unsafe extern "C" fn(Device) -> *const c_char,
    set_memory_monitor: unsafe extern "C" fn(Device, Option<MemoryMonitor>, *mut c_void),
    new_geometry: unsafe extern "C" fn(Device, u32) -> Geometry,
    set_new_geometry_buffer:
        unsafe extern "C" fn(Geometry, u32, u32, u32, usize, usize) -> *mut c_void,
    commit_geometry: unsafe extern "C" fn(Geometry),
    release_geometry: unsafe extern "C" fn(Geometry),
    new_scene: unsafe extern "C" fn(Device) -> RtcScene,
    set_scene_build_quality: unsafe extern "C" fn(RtcScene, u32),
    attach_geometry: unsafe extern "C" fn(RtcScene, Geometry) -> u32,
    commit_scene: unsafe extern "C" fn(RtcScene),
    release_scene: unsafe extern "C" fn(RtcScene),
    intersect1: unsafe extern "C" fn(RtcScene, *mut RayHit1, *mut QueryArguments),
    occluded1: unsafe extern "C" fn(RtcScene, *mut Ray1, *mut QueryArguments),
    intersect8: unsafe extern "C" fn(*const i32, RtcScene, *mut RayHit8, *mut QueryArguments),
    occluded8: unsafe extern "C" fn(*const i32, RtcScene, *mut Ray8, *mut QueryArguments),
}

/// The library file: `libembree4*.so*` in `RAYWAVE_EMBREE4_DIR` (the run's, else the
/// build's), or `libembree4.so.4` for the system's search path when neither is set.
fn library_path() -> anyhow::Result<PathBuf> {
    let dir = std::env::var_os(DIR_ENV)
        .map(PathBuf::from)
        .or_else(|| option_env!("RAYWAVE_EMBREE4_DIR").map(PathBuf::from));
    let Some(dir) = dir else {
        return Ok(PathBuf::from("libembree4.so.4"));
    };
    let entries = std::fs::read_dir(&dir)
        .with_context(|| format!("{DIR_ENV}={}: cannot read the folder", dir.display()))?;
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
            name.is_some_and(|n| n.starts_with("libembree4") && n.contains(".so"))
        })
        .collect();
    found.sort();
    match found.as_slice() {
        [one] => Ok(one.clone()),
        [] => bail!(
            "{DIR_ENV}={}: no libembree4*.so* in it (expected the embreex wheel's \
             embreex.libs folder, docs/BENCHMARKING.md section 5)",
            dir.display()
        ),
        many => bail!(
            "{DIR_ENV}={}: several Embree 4 libraries: {many:?}",
            dir.display()
        ),
    }
}

/// A symbol's address as the function pointer type `F`.
///
/// # Safety
/// `F` is the C signature of the function at `p`.
unsafe fn as_fn<F: Copy>(p: *mut c_void) -> F {
    const { assert!(std::mem::size_of::<F>() == std::mem::size_of::<*mut c_void>()) };
    // SAFETY: a function pointer is an address of the same size (asserted), and the caller
    // vouches for the signature.
    unsafe { std::mem::transmute_copy(&p) }
}

/// `dlerror()`'s message, or `what` when it has none.
fn dl_error(what: &str) -> String {
    // SAFETY: dlerror returns null or a NUL-terminated string valid until the next dl call.
    let message = unsafe { libc::dlerror() };
    if message.is_null() {
        what.to_string()
    } else {
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    }
}

/// The address of `name` in the library `handle` (opened from `path`), or an error naming both.
fn symbol(handle: *mut c_void, path: &Path, name: &str) -> anyhow::Result<*mut c_void> {
    let c_name = CString::new(name).expect("symbol names have no NUL");
    // SAFETY: a live `dlopen` handle (never closed) and a valid C string.
    let p = unsafe { libc::dlsym(handle, c_name.as_ptr()) };
    if p.is_null() {
        bail!(
            "{}: no symbol {name}: {}",
            path.display(),
            dl_error("not found")
        );
    }
    Ok(p)
}

impl Api {
    /// Opens the library and resolves every entry point.
    fn load() -> anyhow::Result<Api> {
        let path = library_path()?;
        let c_path = CString::new(path.as_os_str().as_encoded_bytes())
            .with_context(|| format!("{}: a NUL in the path", path.display()))?;
        // SAFETY: dlopen with a valid C string; the handle is never closed (the library stays
        // loaded for the process, as its TBB threads may).
        let handle = unsafe {
            libc::dlopen(
                c_path.as_ptr(),
                libc::RTLD_NOW | libc::RTLD_LOCAL | libc::RTLD_DEEPBIND,
            )
        };
        if handle.is_null() {
            bail!(
                "cannot load Embree 4 from {}: {} (set {DIR_ENV} to the folder holding \
                 libembree4*.so.4, docs/BENCHMARKING.md section 5)",
                path.display(),
                dl_error("dlopen failed")
            );
        }
        let symbol = |name: &str| symbol(handle, &path, name);
        macro_rules! resolve {
            ($name:literal) => {
                // SAFETY: the symbol is the Embree 4.4 function of that name, whose C
                // signature the field's type declares (include/embree4/*.h).
                unsafe { as_fn(symbol($name)?) }
            };
        }
        Ok(Api {
            new_device: resolve!("rtcNewDevice"),
            release_device: resolve!("rtcReleaseDevice"),
            device_property: resolve!("rtcGetDeviceProperty"),
            device_error: resolve!("rtcGetDeviceError"),
            last_error_message: resolve!("rtcGetDeviceLastErrorMessage"),
            set_memory_monitor: resolve!("rtcSetDeviceMemoryMonitorFunction"),
            new_geometry: resolve!("rtcNewGeometry"),
            set_new_geometry_buffer: resolve!("rtcSetNewGeometryBuffer"),
            commit_geometry: resolve!("rtcCommitGeometry"),
            release_geometry: resolve!("rtcReleaseGeometry"),
            new_scene: resolve!("rtcNewScene"),
            set_scene_build_quality: resolve!("rtcSetSceneBuildQuality"),
            attach_geometry: resolve!("rtcAttachGeometry"),
            commit_scene: resolve!("rtcCommitScene"),
            release_scene: resolve!("rtcReleaseScene"),
            intersect1: resolve!("rtcIntersect1"),
            occluded1: resolve!("rtcOccluded1"),
            intersect8: resolve!("rtcIntersect8"),
            occluded8: resolve!("rtcOccluded8"),
            handle: handle as usize,
            path,
        })
    }

    /// The entry point `name` as the function pointer type `F`.
    ///
    /// # Safety
    /// `F` is the C signature of Embree 4.4's function of that name (include/embree4/*.h).
    pub(super) unsafe fn function<F: Copy>(&self, name: &str) -> anyhow::Result<F> {
        let p = symbol(self.handle as *mut c_void, &self.path, name)?;
        // SAFETY: the caller's.
        Ok(unsafe { as_fn(p) })
    }

    /// The library, loaded on first use; the same error on every later call if it failed.
    pub(super) fn get() -> anyhow::Result<&'static Api> {
        static API: OnceLock<Result<Api, String>> = OnceLock::new();
        API.get_or_init(|| Api::load().map_err(|e| format!("{e:#}")))
            .as_ref()
            .map_err(|e| anyhow::anyhow!("{e}"))
    }

    /// The device's error code and last message, e.g. `error 4: out of memory`.
    pub(super) fn error(&self, device: Device) -> String {
        // SAFETY: a device handle (or null, for the thread's device-creation error).
        unsafe {
            let code = (self.device_error)(device);
            let message = (self.last_error_message)(device);
            let message = if message.is_null() {
                String::new()
            } else {
                CStr::from_ptr(message).to_string_lossy().into_owned()
            };
            format!("error {code}: {message}")
        }
    }
}

/// An Embree 4 device and committed scene over a raywave scene's triangles.
pub struct Embree4Mesh {
    api: &'static Api,
    device: Device,
    scene: RtcScene,
    /// The quality the BVH was built with.
    pub quality: BuildQuality,
    /// Wall time of geometry upload and `rtcCommitScene` (Embree builds with all its threads).
    pub build_time: Duration,
    /// The device's bytes, from its memory monitor.
    pub memory: EmbreeMemory,
    // Last: the device's memory monitor writes here until the device is released in `drop`.
    _count: Box<MemoryCount>,
}

// Embree scenes are safe to trace from several threads once committed.
unsafe impl Send for Embree4Mesh {}
unsafe impl Sync for Embree4Mesh {}

impl Drop for Embree4Mesh {
    fn drop(&mut self) {
        // SAFETY: both handles were created by `new` and are released once.
        unsafe {
            (self.api.release_scene)(self.scene);
            (self.api.release_device)(self.device);
        }
    }
}

impl Embree4Mesh {
    /// Loads Embree 4 (once), uploads the triangles and builds its BVH at `quality`; errors
    /// name the library file or carry Embree's error code and message.
    pub fn new(scene: &Scene, quality: BuildQuality) -> anyhow::Result<Self> {
        let api = Api::get()?;
        let start = Instant::now();
        let count = Box::<MemoryCount>::default();
        // SAFETY: plain Embree API calls on handles this function created; the buffers are
        // written within the item counts they were created with; `count` outlives the device
        // (the mesh owns both and releases the device first).
        unsafe {
            let device = (api.new_device)(std::ptr::null());
            if device.is_null() {
                bail!(
                    "rtcNewDevice failed ({}): {}",
                    api.path.display(),
                    api.error(device)
                );
            }
            let monitor: MemoryMonitor = count_memory;
            let count_ptr = &*count as *const MemoryCount as *mut c_void;
            (api.set_memory_monitor)(device, Some(monitor), count_ptr);
            let n = scene.triangles.len();
            let geometry = (api.new_geometry)(device, TRIANGLE);
            let vertices = (api.set_new_geometry_buffer)(geometry, VERTEX, 0, FLOAT3, 12, 3 * n)
                as *mut [f32; 3];
            let indices =
                (api.set_new_geometry_buffer)(geometry, INDEX, 0, UINT3, 12, n) as *mut [u32; 3];
            if geometry.is_null() || vertices.is_null() || indices.is_null() {
                let error = api.error(device);
                if !geometry.is_null() {
                    (api.release_geometry)(geometry);
                }
                (api.release_device)(device);
                bail!("Embree 4 could not allocate buffers for {n} triangles: {error}");
            }
            fill_triangles(
                scene,
                std::slice::from_raw_parts_mut(vertices, 3 * n),
                std::slice::from_raw_parts_mut(indices, n),
            );
            (api.commit_geometry)(geometry);
            let rtc_scene = (api.new_scene)(device);
            (api.set_scene_build_quality)(rtc_scene, quality.rtc());
            (api.attach_geometry)(rtc_scene, geometry);
            (api.release_geometry)(geometry);
            let buffers = count.now();
            (api.commit_scene)(rtc_scene);
            if (api.device_error)(device) != 0 {
                let error = api.error(device);
                (api.release_scene)(rtc_scene);
                (api.release_device)(device);
                bail!("Embree 4 scene build failed: {error}");
            }
            Ok(Embree4Mesh {
                api,
                device,
                scene: rtc_scene,
                quality,
                build_time: start.elapsed(),
                memory: count.after_commit(buffers),
                _count: count,
            })
        }
    }

    /// The library's version, file, build quality and whether it has native 8-wide packets and
    /// backface culling, e.g. `"Embree 4.4.0 (libembree4-4aef3270.so.4, quality high, native
    /// ray8: yes, backface culling: no)"`.
    pub fn describe(&self) -> String {
        // SAFETY: a live device.
        let prop = |p| unsafe { (self.api.device_property)(self.device, p) };
        let yes = |v: isize| if v != 0 { "yes" } else { "no" };
        let version = prop(PROPERTY_VERSION);
        let file = Path::new(&self.api.path)
            .file_name()
            .map_or_else(String::new, |f| f.to_string_lossy().into_owned());
        format!(
            "Embree {}.{}.{} ({file}, quality {}, native ray8: {}, backface culling: {})",
            version / 10000,
            version / 100 % 100,
            version % 100,
            self.quality.name(),
            yes(prop(PROPERTY_NATIVE_RAY8)),
            yes(prop(PROPERTY_BACKFACE_CULLING)),
        )
    }

    /// `rtcIntersect1`: the closest hit of one ray, into its record.
    #[inline]
    pub fn intersect1(&self, args: &mut QueryArguments, rayhit: &mut RayHit1) {
        // SAFETY: a committed scene, a fully initialised 16-aligned ray/hit.
        unsafe { (self.api.intersect1)(self.scene, rayhit, args) }
    }

    /// `rtcIntersect8`: the closest hits of the live lanes of `valid`, into their records.
    #[inline]
    pub fn intersect8(&self, args: &mut QueryArguments, valid: &Valid8, rayhit: &mut RayHit8) {
        // SAFETY: 32-aligned mask and rays by their types; invalid lanes are masked.
        unsafe { (self.api.intersect8)(valid.0.as_ptr(), self.scene, rayhit, args) }
    }

    /// Closest hit of every ray with `rtcIntersect1`, into `out`.
    pub fn closest_single(&self, set: &RaySet, out: &mut Hits) {
        out.clear();
        let mut args = QueryArguments::new(set.kind.is_coherent());
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
    pub fn closest_packet8(&self, set: &RaySet, out: &mut Hits) {
        out.clear();
        let mut args = QueryArguments::new(set.kind.is_coherent());
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
    pub fn occluded_single(&self, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        let mut args = QueryArguments::new(set.kind.is_coherent());
        for batch in &set.batches {
            for i in 0..batch.len() {
                let mut ray = ray1(batch, i);
                // SAFETY: a committed scene, a fully initialised 16-aligned ray.
                unsafe { (self.api.occluded1)(self.scene, &mut ray, &mut args) };
                out.push(ray.tfar == f32::NEG_INFINITY);
            }
        }
    }

    /// Occlusion with `rtcOccluded8`, 8 consecutive segments per call.
    pub fn occluded_packet8(&self, set: &RaySet, out: &mut Vec<bool>) {
        out.clear();
        let mut args = QueryArguments::new(set.kind.is_coherent());
        for batch in &set.batches {
            for start in (0..batch.len()).step_by(8) {
                let lanes = (batch.len() - start).min(8);
                let (mut ray, valid) = ray8(batch, start, lanes);
                // SAFETY: 32-aligned mask and rays by their types; invalid lanes are masked.
                unsafe { (self.api.occluded8)(valid.0.as_ptr(), self.scene, &mut ray, &mut args) };
                out.extend(ray.tfar[..lanes].iter().map(|&t| t == f32::NEG_INFINITY));
            }
        }
    }
}

/// A hit record before the call: no geometry, no instance.
const EMPTY_HIT1: Hit1 = Hit1 {
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
fn ray1(batch: &RayBatch, i: usize) -> Ray1 {
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
fn fill_triangles(scene: &Scene, vertices: &mut [[f32; 3]], indices: &mut [[u32; 3]]) {
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

    /// The environment variable that chooses the build's quality.
    const ENV: &'static str = "RAYWAVE_EMBREE_QUALITY";

    /// `low`, `medium` or `high`.
    pub fn name(self) -> &'static str {
        match self {
            BuildQuality::Low => "low",
            BuildQuality::Medium => "medium",
            BuildQuality::High => "high",
        }
    }

    /// The `RTCBuildQuality` value (0, 1, 2 in `rtcore_common.h`).
    pub(super) fn rtc(self) -> u32 {
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
struct MemoryCount {
    now: AtomicI64,
    peak: AtomicI64,
}

impl MemoryCount {
    /// Bytes held now.
    fn now(&self) -> i64 {
        self.now.load(Ordering::Relaxed)
    }

    /// A committed build's bytes, `buffers` being what was held before `rtcCommitScene`.
    fn after_commit(&self, buffers: i64) -> EmbreeMemory {
        EmbreeMemory {
            buffers,
            bvh: self.now() - buffers,
            peak: self.peak.load(Ordering::Relaxed),
        }
    }
}

/// The device's `RTCMemoryMonitorFunction`: `ptr` is a `MemoryCount`, `bytes` > 0 for an
/// allocation and < 0 for a free. Returns true: never refuse.
///
/// # Safety
/// `ptr` points to a `MemoryCount` that outlives the device.
unsafe extern "C" fn count_memory(ptr: *mut c_void, bytes: isize, _post: bool) -> bool {
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
