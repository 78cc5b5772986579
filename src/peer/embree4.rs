//! The same triangles in an Embree 4 scene (feature `embree4`): single rays (`rtcIntersect1`,
//! `rtcOccluded1`) and 8-ray packets (`rtcIntersect8`, `rtcOccluded8`), through the loops of
//! `embree_shared::EmbreeCalls`.
//!
//! ```text
//! library:  libembree4*.so.4 in $RAYWAVE_EMBREE4_DIR (at run time, else as it was at build
//!           time, e.g. the embreex 4.4.0 wheel's embreex.libs/), else libembree4.so.4 on the
//!           system's library path; dlopen'ed once, RTLD_LOCAL | RTLD_DEEPBIND
//! new:      device (memory monitor on), one TRIANGLE geometry (embree_shared::fill_triangles),
//!           scene at the chosen BuildQuality, commit; bytes before and after the commit
//! calls:    RTCIntersectArguments / RTCOccludedArguments as rtcInitIntersectArguments
//!           makes them (all features, no context, no callbacks), flags COHERENT or
//!           INCOHERENT per ray set
//! ```
//!
//! Why dlopen and not a link: Embree 3 and 4 export the same C names (`rtcNewDevice`,
//! `rtcIntersect1`, ...), and the wheel's TBB the same names as Debian's, so a binary linked
//! with both libraries would send both versions' calls to whichever the loader found first.
//! Loaded locally with deep binding, Embree 4 and its TBB resolve their own symbols, and the
//! `embree` feature's Embree 3 can run in the same process. The crate `embree4-sys` (0.0.12)
//! was not used: it carries Embree 4.2's headers, generates its bindings with bindgen (libclang)
//! and links `-lembree4`, which the wheel's renamed file does not answer. The few declarations
//! here follow Embree 4.4.0's `include/embree4/*.h`; `embree_shared` asserts the layouts.

#[cfg(not(target_os = "linux"))]
compile_error!("the embree4 feature loads libembree4 with dlopen and RTLD_DEEPBIND: Linux only");

use super::embree_shared::{
    BuildQuality, EmbreeCalls, EmbreeMemory, MemoryCount, Ray1, Ray8, RayHit1, RayHit8, Valid8,
    count_memory, fill_triangles,
};
use crate::render::scene::Scene;
use anyhow::{Context as _, bail};
use std::ffi::{CStr, CString, c_char, c_void};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The variable naming the folder that holds `libembree4*.so.4` (read at run time, and at
/// build time for the default).
pub const DIR_ENV: &str = "RAYWAVE_EMBREE4_DIR";

type Device = *mut c_void;
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

const _: () = assert!(std::mem::size_of::<QueryArguments>() == 32);

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

/// The library's entry points this module calls, resolved once by `dlsym`.
struct Api {
    path: PathBuf,
    new_device: unsafe extern "C" fn(*const c_char) -> Device,
    release_device: unsafe extern "C" fn(Device),
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
        let symbol = |name: &str| -> anyhow::Result<*mut c_void> {
            let c_name = CString::new(name).expect("symbol names have no NUL");
            // SAFETY: a live handle and a valid C string.
            let p = unsafe { libc::dlsym(handle, c_name.as_ptr()) };
            if p.is_null() {
                bail!(
                    "{}: no symbol {name}: {}",
                    path.display(),
                    dl_error("not found")
                );
            }
            Ok(p)
        };
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
            path,
        })
    }

    /// The library, loaded on first use; the same error on every later call if it failed.
    fn get() -> anyhow::Result<&'static Api> {
        static API: OnceLock<Result<Api, String>> = OnceLock::new();
        API.get_or_init(|| Api::load().map_err(|e| format!("{e:#}")))
            .as_ref()
            .map_err(|e| anyhow::anyhow!("{e}"))
    }

    /// The device's error code and last message, e.g. `error 4: out of memory`.
    fn error(&self, device: Device) -> String {
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
}

impl EmbreeCalls for Embree4Mesh {
    type Args = QueryArguments;

    fn args(&self, coherent: bool) -> QueryArguments {
        QueryArguments {
            flags: if coherent { COHERENT } else { 0 },
            feature_mask: FEATURE_ALL,
            context: std::ptr::null_mut(),
            filter: std::ptr::null(),
            callback: std::ptr::null(),
        }
    }

    #[inline]
    fn intersect1(&self, args: &mut QueryArguments, rayhit: &mut RayHit1) {
        // SAFETY: a committed scene, a fully initialised 16-aligned ray/hit.
        unsafe { (self.api.intersect1)(self.scene, rayhit, args) }
    }

    #[inline]
    fn occluded1(&self, args: &mut QueryArguments, ray: &mut Ray1) {
        // SAFETY: as in `intersect1`.
        unsafe { (self.api.occluded1)(self.scene, ray, args) }
    }

    #[inline]
    fn intersect8(&self, args: &mut QueryArguments, valid: &Valid8, rayhit: &mut RayHit8) {
        // SAFETY: 32-aligned mask and rays by their types; invalid lanes are masked.
        unsafe { (self.api.intersect8)(valid.0.as_ptr(), self.scene, rayhit, args) }
    }

    #[inline]
    fn occluded8(&self, args: &mut QueryArguments, valid: &Valid8, ray: &mut Ray8) {
        // SAFETY: as in `intersect8`.
        unsafe { (self.api.occluded8)(valid.0.as_ptr(), self.scene, ray, args) }
    }
}
