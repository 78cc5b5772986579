//! The instruction-count gate's child: the workloads that `tests/gates/icount.rs` runs under
//! callgrind, built for x86-64-v3 against the library alone (`--no-default-features`), so that
//! the gate's second build is the renderer and its few dependencies, not the whole crate with
//! its dev-dependencies.
//!
//! ```text
//! print the key (rustc version · target arch · enabled x86 features · valgrind version)
//! for each region, in REGIONS order:
//!     build its inputs (not counted), run the kernel once to size its buffers (not counted),
//!     then once more inside its #[inline(never)] icount_region_* (counted: callgrind switches
//!     collection on at the region's entry and dumps at its exit)
//! ```
//!
//! Workloads, single-threaded and deterministic: the wavefront stages (generate, intersect,
//! shadow, film, reflect) on a 1024-pixel tile of the lab scene (64×64, 5 bounces, 16
//! stratified soft-shadow points), their scalar twins (`Accel::closest` on the same rays, the
//! reference renderer on 128 of the tile's pixels), and intersect and shadow on
//! `scenes/mesh_spheres_small.obj` (684 triangles), which go through the mesh BVH (`MeshBvh`).
//! Built only with the `icount-child` feature; the gate builds it (docs/TESTING.md, "The
//! instruction-count gate").

use raywave::render::geometry::{Accel, Ray};
use raywave::render::per_kind::RayCounts;
use raywave::render::reference::Reference;
use raywave::render::sampling::LightSampler;
use raywave::render::scene::Scene;
use raywave::render::settings::{RenderSettings, ShadowMode};
use raywave::render::wavefront::batch::{HitBatch, Radiance, RayBatch, ShadowQueue};
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::cost::NoCount;
use raywave::render::wavefront::{film, generate, intersect, reflect, shadow};
use std::hint::black_box;
use std::path::Path;
use std::process::Command;

/// The line by which the child tells the runner its key.
const KEY_LINE: &str = "icount-key: ";
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
    intersect::closest(ctx, black_box(rays), hits, &mut NoCount);
    black_box(1u8);
}

#[inline(never)]
fn icount_region_shadow(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    queue: &mut ShadowQueue,
) -> u64 {
    let cast = shadow::direct_light(
        ctx,
        black_box(rays),
        hits,
        queue,
        TILE as usize,
        &mut NoCount,
    );
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
    intersect::closest(ctx, black_box(rays), hits, &mut NoCount);
    black_box(7u8);
}

#[inline(never)]
fn icount_region_shadow_mesh(
    ctx: &Context,
    rays: &RayBatch,
    hits: &mut HitBatch,
    queue: &mut ShadowQueue,
) -> u64 {
    let cast = shadow::direct_light(
        ctx,
        black_box(rays),
        hits,
        queue,
        TILE as usize,
        &mut NoCount,
    );
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
    intersect::closest(&ctx, &rays, &mut hits, &mut NoCount);
    icount_region_intersect(&ctx, &rays, &mut hits);

    let mut queue = ShadowQueue::default();
    let mut h = hits.clone();
    shadow::direct_light(&ctx, &rays, &mut h, &mut queue, TILE as usize, &mut NoCount);
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
            origin: rays.origin.get(i),
            direction: rays.direction.get(i),
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

    let mesh_path = concat!(env!("RAYWAVE_REPO"), "/scenes/mesh_spheres_small.obj");
    let mesh = Scene::load(Path::new(mesh_path)).expect("scenes/mesh_spheres_small.obj");
    let mesh_ctx = Context::new(&mesh, &settings);
    assert!(
        mesh_ctx.accel.is_some(),
        "the mesh scene goes through the mesh BVH"
    );
    let mut mesh_rays = RayBatch::default();
    generate::camera_rays(&mesh_ctx, FIRST, TILE, &mut mesh_rays);
    let mut mesh_hits = HitBatch::default();
    intersect::closest(&mesh_ctx, &mesh_rays, &mut mesh_hits, &mut NoCount);
    icount_region_intersect_mesh(&mesh_ctx, &mesh_rays, &mut mesh_hits);
    let mut h = mesh_hits.clone();
    shadow::direct_light(
        &mesh_ctx,
        &mesh_rays,
        &mut h,
        &mut queue,
        TILE as usize,
        &mut NoCount,
    );
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

fn main() {
    println!("{KEY_LINE}{}", key());
    workloads();
}
