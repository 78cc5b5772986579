//! The noise-free gate: instruction counts of the hot kernels under callgrind, against
//! committed baselines (`benches/baselines/icount.json`) with a tight threshold.
//!
//! ```text
//! runner (this test, in release builds):
//!     child = this test built for x86-64-v3 (cargo, in target/icount-x86-64-v3), or this
//!             binary when it is such a build: valgrind runs that on every x86-64 machine
//!     valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*icount_region_*'
//!              --dump-after=...icount_region_NAME  <child>  (child mode)
//!     one dump per region → instructions per region; the child prints its key
//!     key = rustc version · target arch · enabled x86 features · valgrind version
//!     baseline for the key?  compare each region: rise > THRESHOLD fails, fall > THRESHOLD notes
//!     nothing compared (no baseline, no valgrind, a debug build)?  fail when CI is set, else
//!                            say why and pass
//! child (RAYWAVE_ICOUNT_CHILD set):
//!     build each workload's inputs (not counted), run the kernel once to size its buffers
//!     (not counted), then run it once more inside its #[inline(never)] icount_region_* (counted)
//! ```
//!
//! Workloads, single-threaded and deterministic: the wavefront stages (generate, intersect,
//! shadow, film, reflect) on a 1024-pixel tile of the lab scene (64×64, 5 bounces, 16
//! stratified soft-shadow points), their scalar twins (`Accel::closest` on the same rays, the
//! reference renderer on 128 of the tile's pixels), and intersect and shadow on
//! `scenes/mesh_spheres_small.obj` (684 triangles), which go through the mesh BVH (`MeshBvh`).
//!
//! Re-record deliberately (after a change to a kernel, rustc, a dependency, or on a new
//! machine): `RAYWAVE_RECORD=1 cargo test --release --test icount`. It rewrites this key's
//! entry and keeps the others. See docs/BENCHMARKING.md ("The instruction-count gate").

use raywave::geometry::{Accel, Ray};
use raywave::reference::Reference;
use raywave::sampling::LightSampler;
use raywave::scene::Scene;
use raywave::settings::{RenderSettings, ShadowMode};
use raywave::stats::RayCounts;
use raywave::wavefront::batch::{HitBatch, Radiance, RayBatch, ShadowQueue};
use raywave::wavefront::context::Context;
use raywave::wavefront::{film, generate, intersect, reflect, shadow};
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::Path;
use std::process::Command;

/// A region whose count rises by more than this fraction fails. Counts repeat exactly from run
/// to run on one machine (docs/BENCHMARKING.md); the threshold absorbs what the key does not
/// capture, chiefly glibc's `memset`/`memcpy`/`malloc`, which are picked per CPU at run time.
const THRESHOLD: f64 = 0.01;
/// The committed baselines.
const RECORD: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/baselines/icount.json");
/// The one command that re-records this machine's baselines.
const RECORD_COMMAND: &str = "RAYWAVE_RECORD=1 cargo test --release --test icount";
/// Set in the child process that valgrind runs.
const CHILD: &str = "RAYWAVE_ICOUNT_CHILD";
/// The regions, in the order the child runs them (the dumps come in this order).
const REGIONS: [&str; 9] = [
    "generate",
    "intersect",
    "shadow",
    "film",
    "reflect",
    "intersect_scalar",
    "reference",
    "intersect_mesh",
    "shadow_mesh",
];
/// Tile of the lab image: 16 rows below the middle (walls, floor, mirror spheres, penumbrae).
const SIZE: u32 = 64;
const FIRST: u32 = SIZE * 36;
const TILE: u32 = SIZE * 16;
/// Pixels the scalar reference renders (whole paths: a fraction of the tile keeps it quick).
const REFERENCE_PIXELS: u32 = 128;

fn lab_settings() -> RenderSettings {
    RenderSettings {
        width: SIZE,
        height: SIZE,
        bounces: 5,
        shadows: ShadowMode::Soft,
        shadow_samples: 16,
        sampler: LightSampler::Stratified,
        ..RenderSettings::default()
    }
}

// The regions: each is one call of a kernel, never inlined, so callgrind can switch collection
// on at its entry and dump at its exit. The `black_box(id)` after the call keeps the call from
// becoming a tail jump (callgrind would not see the region return) and makes every body
// distinct, so rustc's function merging cannot fold two regions into one symbol.

#[inline(never)]
fn icount_region_generate(ctx: &Context, rays: &mut RayBatch) {
    generate::camera_rays(ctx, black_box(FIRST), TILE, rays);
    black_box(0u8);
}

#[inline(never)]
fn icount_region_intersect(ctx: &Context, rays: &RayBatch, hits: &mut HitBatch) {
    intersect::closest(ctx, black_box(rays), hits);
    black_box(1u8);
}

#[inline(never)]
fn icount_region_shadow(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    queue: &mut ShadowQueue,
) -> u64 {
    let cast = shadow::direct_light(ctx, black_box(rays), hits, queue, TILE as usize);
    black_box(2u8);
    cast
}

#[inline(never)]
fn icount_region_film(
    ctx: &Context,
    rays: &RayBatch,
    hits: &HitBatch,
    radiance: &mut Radiance,
    out: &mut [glam::Vec3],
) {
    radiance.reset(rays.len());
    film::accumulate(ctx, black_box(rays), hits, radiance);
    film::resolve(radiance, 1, out);
    black_box(3u8);
}

#[inline(never)]
fn icount_region_reflect(ctx: &Context, rays: &RayBatch, hits: &HitBatch, next: &mut RayBatch) {
    reflect::mirror_rays(ctx, black_box(rays), hits, next);
    black_box(4u8);
}

#[inline(never)]
fn icount_region_intersect_scalar(scene: &Scene, accel: &Accel, rays: &[Ray], out: &mut [u32]) {
    for (ray, prim) in black_box(rays).iter().zip(out) {
        *prim = accel.closest(scene, ray, f32::INFINITY, false).prim;
    }
    black_box(5u8);
}

#[inline(never)]
fn icount_region_reference(reference: &Reference, out: &mut [glam::Vec3]) {
    // `pixels`, not the generic `pixel`: the library's own compiled loop, as the renderer
    // runs it (a copy instantiated here once missed a 24% rise in the binary's reference).
    reference.pixels(black_box(FIRST), out, &mut RayCounts::default());
    black_box(6u8);
}

// The mesh regions are deliberate twins of `intersect` and `shadow`: a symbol of their own, so
// callgrind counts the mesh scene's BVH walk apart from the lab scene's.
#[inline(never)]
fn icount_region_intersect_mesh(ctx: &Context, rays: &RayBatch, hits: &mut HitBatch) {
    intersect::closest(ctx, black_box(rays), hits);
    black_box(7u8);
}

#[inline(never)]
fn icount_region_shadow_mesh(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    queue: &mut ShadowQueue,
) -> u64 {
    let cast = shadow::direct_light(ctx, black_box(rays), hits, queue, TILE as usize);
    black_box(8u8);
    cast
}

/// The child: every region once, in `REGIONS` order, each after an uncounted warm-up call.
fn workloads() {
    let scene = Scene::builtin_default();
    let settings = lab_settings();
    let ctx = Context::new(&scene, &settings);
    assert!(
        ctx.accel.is_none(),
        "the lab scene goes through the 8-wide kernels"
    );
    let mut rays = RayBatch::default();
    generate::camera_rays(&ctx, FIRST, TILE, &mut rays);
    icount_region_generate(&ctx, &mut rays);

    let mut hits = HitBatch::default();
    intersect::closest(&ctx, &rays, &mut hits);
    icount_region_intersect(&ctx, &rays, &mut hits);

    let mut queue = ShadowQueue::default();
    let mut h = hits.clone();
    shadow::direct_light(&ctx, &rays, &mut h, &mut queue, TILE as usize);
    let cast = icount_region_shadow(&ctx, &rays, &mut hits, &mut queue);
    assert!(cast > 0, "the lab tile casts shadow rays");

    let mut radiance = Radiance::default();
    let mut pixels = vec![glam::Vec3::ZERO; TILE as usize];
    radiance.reset(rays.len());
    film::accumulate(&ctx, &rays, &hits, &mut radiance);
    icount_region_film(&ctx, &rays, &hits, &mut radiance, &mut pixels);

    let mut next = RayBatch::default();
    reflect::mirror_rays(&ctx, &rays, &hits, &mut next);
    icount_region_reflect(&ctx, &rays, &hits, &mut next);
    assert!(!next.is_empty(), "the lab tile has mirror hits");

    let accel = Accel::new(&scene);
    let scalar_rays: Vec<Ray> = (0..rays.len())
        .map(|i| Ray {
            origin: rays.origin(i),
            direction: rays.direction(i),
        })
        .collect();
    let mut prims = vec![0u32; scalar_rays.len()];
    icount_region_intersect_scalar(&scene, &accel, &scalar_rays, &mut prims);
    assert_eq!(
        prims[..],
        hits.prim[..prims.len()],
        "scalar twin agrees with intersect"
    );

    let reference = Reference::new(&scene, &settings);
    let mut out = vec![glam::Vec3::ZERO; REFERENCE_PIXELS as usize];
    icount_region_reference(&reference, &mut out);

    let mesh_path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/mesh_spheres_small.obj");
    let mesh = Scene::load(Path::new(mesh_path)).expect("scenes/mesh_spheres_small.obj");
    let mesh_ctx = Context::new(&mesh, &settings);
    assert!(
        mesh_ctx.accel.is_some(),
        "the mesh scene goes through the mesh BVH"
    );
    let mut mesh_rays = RayBatch::default();
    generate::camera_rays(&mesh_ctx, FIRST, TILE, &mut mesh_rays);
    let mut mesh_hits = HitBatch::default();
    intersect::closest(&mesh_ctx, &mesh_rays, &mut mesh_hits);
    icount_region_intersect_mesh(&mesh_ctx, &mesh_rays, &mut mesh_hits);
    let mut h = mesh_hits.clone();
    shadow::direct_light(&mesh_ctx, &mesh_rays, &mut h, &mut queue, TILE as usize);
    icount_region_shadow_mesh(&mesh_ctx, &mesh_rays, &mut mesh_hits, &mut queue);
    black_box((&hits, &pixels, &next, &prims, &out, &mesh_hits));
}

/// What makes counts differ between machines and toolchains.
fn key() -> String {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let rustc = Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "rustc unknown".into());
    // The features this build was compiled with (`target-cpu=native` in .cargo/config.toml
    // makes them the build machine's).
    let features: Vec<&str> = [
        ("sse4.1", cfg!(target_feature = "sse4.1")),
        ("sse4.2", cfg!(target_feature = "sse4.2")),
        ("popcnt", cfg!(target_feature = "popcnt")),
        ("avx", cfg!(target_feature = "avx")),
        ("avx2", cfg!(target_feature = "avx2")),
        ("fma", cfg!(target_feature = "fma")),
        ("bmi1", cfg!(target_feature = "bmi1")),
        ("bmi2", cfg!(target_feature = "bmi2")),
        ("lzcnt", cfg!(target_feature = "lzcnt")),
        ("avx512f", cfg!(target_feature = "avx512f")),
        ("avx512vl", cfg!(target_feature = "avx512vl")),
    ]
    .into_iter()
    .filter_map(|(name, on)| on.then_some(name))
    .collect();
    format!(
        "{rustc} · {} · {} · {}",
        std::env::consts::ARCH,
        if features.is_empty() {
            "baseline features".to_string()
        } else {
            features.join(",")
        },
        valgrind_version().unwrap_or_default()
    )
}

fn valgrind_version() -> Option<String> {
    let out = Command::new("valgrind").arg("--version").output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// `benches/baselines/icount.json`: instructions per region, per key.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
struct Baselines {
    how_to_update: String,
    threshold_percent: f64,
    baselines: BTreeMap<String, BTreeMap<String, u64>>,
}

/// The child's key and its instructions per region, in `REGIONS` order.
type Measured = (String, Vec<(&'static str, u64)>);

/// Runs `exe` (this test, built for `FIXED_TARGET`) as the child under callgrind and returns
/// the child's key and (region, instructions) in `REGIONS` order, or the reason it could not.
fn measure(exe: &Path) -> Result<Measured, String> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let out_file = dir.path().join("callgrind.out");
    let output = Command::new("valgrind")
        .args([
            "--tool=callgrind",
            "--collect-atstart=no",
            "--toggle-collect=*icount_region_*",
        ])
        .args(
            // One exact name each: callgrind's --dump-after takes no wildcard.
            REGIONS.map(|r| format!("--dump-after=icount::icount_region_{r}")),
        )
        .arg(format!("--callgrind-out-file={}", out_file.display()))
        .arg(exe)
        .args([
            "--exact",
            "kernel_instruction_counts",
            "--nocapture",
            "--test-threads",
            "1",
        ])
        .env(CHILD, "1")
        .output()
        .expect("run valgrind");
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        if stderr.contains("unhandled instruction") || stderr.contains("unrecognised instruction") {
            return Err(format!(
                "valgrind cannot run {} (an instruction it does not emulate)\n{stderr}",
                exe.display()
            ));
        }
        panic!(
            "icount: the workloads failed under valgrind ({}):\n{}\n{stderr}",
            output.status,
            String::from_utf8_lossy(&output.stdout)
        );
    }
    // One part per dump (`callgrind.out.1`, `.2`, ...), then the final one at exit.
    let mut counts = Vec::new();
    for (i, region) in REGIONS.iter().enumerate() {
        let part = dir.path().join(format!("callgrind.out.{}", i + 1));
        let text = std::fs::read_to_string(&part).unwrap_or_else(|e| {
            panic!(
                "icount: no dump {} ({e}): was region {region} inlined or renamed?\n{stderr}",
                part.display()
            )
        });
        assert!(
            text.lines().any(|l| l.starts_with("desc: Trigger:")
                && l.trim_end().ends_with(&format!("::icount_region_{region}"))),
            "icount: dump {} is not region {region}:\n{}",
            i + 1,
            text.lines()
                .filter(|l| l.starts_with("desc:"))
                .collect::<Vec<_>>()
                .join("\n")
        );
        let total = text
            .lines()
            .find_map(|l| l.strip_prefix("summary:").or(l.strip_prefix("totals:")))
            .and_then(|v| v.split_whitespace().next()?.parse::<u64>().ok())
            .unwrap_or_else(|| panic!("icount: no total in {}", part.display()));
        assert!(total > 0, "icount: region {region} counted no instructions");
        counts.push((*region, total));
    }
    let stdout = String::from_utf8_lossy(&output.stdout);
    let key = stdout
        .lines()
        // The test harness's "test ... " may precede it on the same line.
        .find_map(|l| l.find(KEY_LINE).map(|i| &l[i + KEY_LINE.len()..]))
        .ok_or_else(|| format!("the child printed no `{KEY_LINE}` line:\n{stdout}"))?;
    Ok((key.to_string(), counts))
}

/// The CPU the gate measures for, whatever the machine: valgrind runs x86-64-v3 code on every
/// x86-64 machine it runs on (this machine's native AVX-512 build it cannot), so one baseline
/// serves them all.
const FIXED_TARGET: &str = "x86-64-v3";
/// Where the fixed-target build of this test goes: its own target directory, so that building
/// it does not wait on the lock of the `cargo test` that runs this.
const FIXED_TARGET_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/target/icount-x86-64-v3");
/// The line by which the child tells the runner its key.
const KEY_LINE: &str = "icount-key: ";

/// This test built for `FIXED_TARGET`: this binary when it is one (a build with exactly that
/// target's features and no AVX-512), else one built now by cargo (a release build of this test
/// only, in `FIXED_TARGET_DIR`; a minute or two the first time, then incremental).
fn fixed_target_child() -> Result<std::path::PathBuf, String> {
    let is_fixed = cfg!(all(
        target_feature = "avx2",
        target_feature = "fma",
        target_feature = "bmi2"
    )) && !cfg!(target_feature = "avx512f");
    if is_fixed && std::env::var_os("RAYWAVE_ICOUNT_REBUILD").is_none() {
        return std::env::current_exe().map_err(|e| format!("cannot find this test binary: {e}"));
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = Command::new(cargo)
        .args([
            "test",
            "--release",
            "--test",
            "icount",
            "--no-run",
            "--message-format=json",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("RUSTFLAGS", format!("-C target-cpu={FIXED_TARGET}"))
        .env("CARGO_TARGET_DIR", FIXED_TARGET_DIR)
        .output()
        .map_err(|e| format!("cannot run cargo to build the {FIXED_TARGET} child: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "building the {FIXED_TARGET} child failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == "icount")
        .find_map(|m| m["executable"].as_str().map(std::path::PathBuf::from))
        .ok_or_else(|| format!("cargo built no icount executable for {FIXED_TARGET}"))
}

/// A gate that did not compare is a pass on a developer's machine (with the reason printed) and
/// a failure in CI (`CI` set), where a silent pass would be a false green.
fn not_gated(why: &str) {
    let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false" && v != "0");
    assert!(!ci, "icount: the gate did not run, and CI is set: {why}");
    eprintln!("icount: SKIPPED: {why}");
}

/// A region's count against its baseline.
#[derive(Debug, PartialEq)]
enum Verdict {
    Within,
    Rose,
    Fell,
}

/// The relative change of `now` against `before`, and what the gate makes of it.
fn judge(before: u64, now: u64) -> (f64, Verdict) {
    let change = (now as f64 - before as f64) / before.max(1) as f64;
    let verdict = if change > THRESHOLD {
        Verdict::Rose
    } else if change < -THRESHOLD {
        Verdict::Fell
    } else {
        Verdict::Within
    };
    (change, verdict)
}

#[test]
fn the_threshold_is_one_percent_either_way() {
    assert_eq!(judge(1_000_000, 1_000_000).1, Verdict::Within);
    assert_eq!(judge(1_000_000, 1_010_000).1, Verdict::Within);
    assert_eq!(judge(1_000_000, 1_010_001).1, Verdict::Rose);
    assert_eq!(judge(1_000_000, 989_999).1, Verdict::Fell);
    assert_eq!(judge(1_000_000, 990_000).1, Verdict::Within);
}

#[test]
fn kernel_instruction_counts() {
    if std::env::var_os(CHILD).is_some() {
        println!("{KEY_LINE}{}", key());
        workloads();
        return;
    }
    if cfg!(debug_assertions) {
        return not_gated("a debug build: the baselines are release counts (cargo test --release)");
    }
    if valgrind_version().is_none() {
        return not_gated(
            "valgrind is not installed (Debian: apt-get install valgrind; .ci/run installs it)",
        );
    }
    let child = match fixed_target_child() {
        Ok(child) => child,
        Err(why) => return not_gated(&why),
    };
    let (key, counts) = match measure(&child) {
        Ok(measured) => measured,
        Err(why) => return not_gated(&why),
    };
    let mut record: Baselines = std::fs::read_to_string(RECORD)
        .ok()
        .map(|text| serde_json::from_str(&text).unwrap_or_else(|e| panic!("icount: {RECORD}: {e}")))
        .unwrap_or_default();
    let baseline = record.baselines.get(&key);
    println!("icount: key {key}");
    println!(
        "{:<18} {:>14} {:>14} {:>9}",
        "region", "instructions", "baseline", "change"
    );
    let mut rose = Vec::new();
    let mut fell = Vec::new();
    for &(region, now) in &counts {
        let before = baseline.and_then(|b| b.get(region)).copied();
        let (cell, change) = match before {
            Some(b) => {
                let (change, verdict) = judge(b, now);
                match verdict {
                    Verdict::Rose => {
                        rose.push(format!("{region} {:+.2}% ({b} -> {now})", change * 100.0))
                    }
                    Verdict::Fell => fell.push(format!("{region} {:+.2}%", change * 100.0)),
                    Verdict::Within => {}
                }
                (b.to_string(), format!("{:+.2}%", change * 100.0))
            }
            None => ("-".into(), "-".into()),
        };
        println!("{region:<18} {now:>14} {cell:>14} {change:>9}");
    }

    if std::env::var_os("RAYWAVE_RECORD").is_some_and(|v| !v.is_empty() && v != "0") {
        record.how_to_update = format!(
            "Instruction counts of tests/icount.rs per key, re-recorded deliberately with `{RECORD_COMMAND}`; see docs/BENCHMARKING.md"
        );
        record.threshold_percent = THRESHOLD * 100.0;
        record.baselines.insert(
            key.clone(),
            counts.iter().map(|&(r, n)| (r.to_string(), n)).collect(),
        );
        let text = serde_json::to_string_pretty(&record).expect("serialise") + "\n";
        let tmp = Path::new(RECORD).with_extension("json.tmp");
        std::fs::write(&tmp, text).expect("write the baselines");
        std::fs::rename(&tmp, RECORD).expect("replace the baselines");
        println!("icount: RAYWAVE_RECORD is set: wrote this key's counts to {RECORD}");
        return;
    }
    let Some(baseline) = baseline else {
        return not_gated(&format!(
            "NO BASELINE for this key in {RECORD}: nothing compared (every region ran under \
             callgrind). Keys recorded: {:?}. To record this one: {RECORD_COMMAND}",
            record.baselines.keys().collect::<Vec<_>>()
        ));
    };
    let missing: Vec<_> = REGIONS
        .iter()
        .filter(|r| !baseline.contains_key(**r))
        .collect();
    assert!(
        missing.is_empty(),
        "icount: regions {missing:?} have no baseline for this key: record them with {RECORD_COMMAND}"
    );
    if !fell.is_empty() {
        println!(
            "icount: fewer instructions than the baseline: {}; if meant, re-record to keep the gate tight: {RECORD_COMMAND}",
            fell.join(", ")
        );
    }
    assert!(
        rose.is_empty(),
        "icount: instruction counts ROSE by more than {:.1}%: {}. Counts are exact, so this is \
         a real change of the code or toolchain; if it is meant, re-record: {RECORD_COMMAND}",
        THRESHOLD * 100.0,
        rose.join(", ")
    );
    println!(
        "icount: every region within {:.1}% of its baseline",
        THRESHOLD * 100.0
    );
}
