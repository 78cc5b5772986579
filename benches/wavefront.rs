//! Criterion benchmarks of the wavefront engine: `stages` times each stage on one tile of the
//! lab benchmark (soft shadows, 64 stratified points) on one thread; `frame` renders a small
//! frame of every bundled scene on the default rayon pool (all cores). Inputs are built once,
//! deterministically (the sampler is a pure hash of a fixed seed), and throughput is declared
//! in rays so criterion prints rays/s.
//!
//! `cargo bench --bench wavefront` (add `-- stages` or `-- frame` to pick a group).

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use raywave::render::scene::Scene;
use raywave::render::settings::RenderSettings;
use raywave::render::wavefront::batch::{HitBatch, Radiance, RayBatch, ShadowQueue};
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::{Wavefront, film, generate, intersect, reflect, shadow};
use std::hint::black_box;

const TILE: u32 = 4096;

fn stages(c: &mut Criterion) {
    let scene = Scene::builtin_default();
    let settings = RenderSettings::lab_benchmark(1024);
    let ctx = Context::new(&scene, &settings);
    // A tile through the middle of the image: walls, spheres and mirrors.
    let first = 1024 * 600;
    let mut rays = RayBatch::default();
    generate::camera_rays(&ctx, first, TILE, &mut rays);
    let mut hits = HitBatch::default();
    intersect::closest(&ctx, &rays, &mut hits);
    let mut queue = ShadowQueue::default();
    let shadow_rays = shadow::direct_light(&ctx, &rays, &mut hits, &mut queue, TILE as usize);
    let mut next = RayBatch::default();
    let mirror_rays = reflect::mirror_rays(&ctx, &rays, &hits, &mut next);

    let mut g = c.benchmark_group("stages");
    g.throughput(Throughput::Elements(TILE as u64));
    g.bench_function("generate", |b| {
        let mut out = RayBatch::default();
        b.iter(|| generate::camera_rays(&ctx, black_box(first), TILE, &mut out))
    });
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("intersect", |b| {
        let mut out = HitBatch::default();
        b.iter(|| intersect::closest(&ctx, black_box(&rays), &mut out))
    });
    g.throughput(Throughput::Elements(shadow_rays));
    g.bench_function("shadow", |b| {
        let mut h = hits.clone();
        let mut q = ShadowQueue::default();
        b.iter(|| shadow::direct_light(&ctx, black_box(&rays), &mut h, &mut q, TILE as usize))
    });
    g.throughput(Throughput::Elements(mirror_rays.max(1)));
    g.bench_function("reflect", |b| {
        let mut out = RayBatch::default();
        b.iter(|| reflect::mirror_rays(&ctx, black_box(&rays), &hits, &mut out))
    });
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("film", |b| {
        let mut radiance = Radiance::default();
        let mut out = vec![glam::Vec3::ZERO; TILE as usize];
        b.iter(|| {
            radiance.reset(rays.len());
            film::accumulate(&ctx, black_box(&rays), &hits, &mut radiance);
            film::resolve(&radiance, 1, &mut out);
        })
    });
    g.finish();
}

fn frame(c: &mut Criterion) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .expect("scenes/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    let settings = RenderSettings {
        shadow_samples: 16,
        ..RenderSettings::lab_benchmark(96)
    };
    let mut g = c.benchmark_group("frame");
    g.sample_size(10);
    for path in paths {
        let Ok(scene) = Scene::load(&path) else {
            continue;
        };
        let engine = Wavefront::new(&scene, &settings, 4096);
        let rays = engine.render(&|| {}).1.counts.total();
        g.throughput(Throughput::Elements(rays));
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        g.bench_function(name.unwrap_or_default(), |b| {
            b.iter(|| black_box(engine.render(&|| {})))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = common::criterion();
    targets = stages, frame
}
criterion_main!(benches);
