//! Criterion benchmarks of the wavefront engine: `stages` times each stage on one tile of the
//! lab benchmark (soft shadows, 64 stratified points) on one thread; `frame` renders a small
//! frame of every bundled scene on the default rayon pool (all cores); `light_points` times
//! every sampler's points on the lab's light, 8 and 16 lanes at a time as the shadow stage
//! draws them and one at a time as the reference does (the cost table of docs/SAMPLING.md).
//! Inputs are built once, deterministically (the sampler is a pure hash of a fixed seed), and
//! throughput is declared in rays (points for `light_points`) so criterion prints rays/s.
//!
//! `cargo bench --bench wavefront` (add `-- stages`, `-- frame` or `-- light_points` to pick a
//! group).

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use raywave::render::progress::Progress;
use raywave::render::sampling::{LightSampler, SampleKey};
use raywave::render::scene::Scene;
use raywave::render::settings::RenderSettings;
use raywave::render::wavefront::batch::{HitBatch, Radiance, RayBatch, ShadowQueue};
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::cost::NoCount;
use raywave::render::wavefront::lanes::{Lanes, f32x8, f32x16};
use raywave::render::wavefront::simd::{self, LightBlock};
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
    intersect::closest(&ctx, &rays, &mut hits, &mut NoCount);
    let mut queue = ShadowQueue::default();
    let shadow_rays = shadow::direct_light(
        &ctx,
        &rays,
        &mut hits,
        &mut queue,
        TILE as usize,
        &mut NoCount,
    );
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
        b.iter(|| intersect::closest(&ctx, black_box(&rays), &mut out, &mut NoCount))
    });
    g.throughput(Throughput::Elements(shadow_rays));
    g.bench_function("shadow", |b| {
        let mut h = hits.clone();
        let mut q = ShadowQueue::default();
        b.iter(|| {
            shadow::direct_light(
                &ctx,
                black_box(&rays),
                &mut h,
                &mut q,
                TILE as usize,
                &mut NoCount,
            )
        })
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
        let rays = engine.render(&Progress::SILENT).1.counts.total();
        g.throughput(Throughput::Elements(rays));
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        g.bench_function(name.unwrap_or_default(), |b| {
            b.iter(|| black_box(engine.render(&Progress::SILENT)))
        });
    }
    g.finish();
}

/// Streams and points per stream of `light_points`: the lab benchmark's 64 points.
const STREAMS: u32 = 1024;
const POINTS: u32 = 64;

/// Every stream's points, `V::N` at a time, as the shadow stage draws them.
fn blocks<V: Lanes>(
    ctx: &Context,
    keys: &[SampleKey],
    light: (glam::Vec3, glam::Vec3, glam::Vec3),
) {
    let (origin, edge_u, edge_v) = light;
    for key in keys {
        let block = LightBlock {
            prefix: shadow::key_prefix(key),
            j0: 0,
            sampler: ctx.block_sampler(key),
            origin,
            edge_u,
            edge_v,
        };
        for j0 in (0..POINTS).step_by(V::N) {
            black_box(simd::light_points::<V>(&LightBlock { j0, ..block }));
        }
    }
}

fn light_points(c: &mut Criterion) {
    let scene = Scene::builtin_default();
    let keys: Vec<SampleKey> = (0..STREAMS)
        .map(|i| SampleKey {
            pixel: i * 1031,
            sample: 0,
            bounce: 0,
            light: 0,
            seed: 0,
        })
        .collect();
    let mut g = c.benchmark_group("light_points");
    g.throughput(Throughput::Elements(u64::from(STREAMS * POINTS)));
    for sampler in LightSampler::ALL {
        let settings = RenderSettings {
            sampler,
            ..RenderSettings::lab_benchmark(1024)
        };
        let ctx = Context::new(&scene, &settings);
        let light = ctx.lights[0]
            .parallelogram
            .expect("the lab's light is a parallelogram");
        let lamp = &scene.lights[0];
        g.bench_function(format!("{}/8", sampler.name()), |b| {
            b.iter(|| blocks::<f32x8>(&ctx, &keys, light))
        });
        g.bench_function(format!("{}/16", sampler.name()), |b| {
            b.iter(|| blocks::<f32x16>(&ctx, &keys, light))
        });
        g.bench_function(format!("{}/scalar", sampler.name()), |b| {
            b.iter(|| {
                for key in &keys {
                    for j in 0..POINTS {
                        let (u, v) = ctx.points.point(key, j);
                        black_box(lamp.point(u, v));
                    }
                }
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = common::criterion();
    targets = stages, frame, light_points
}
criterion_main!(benches);
