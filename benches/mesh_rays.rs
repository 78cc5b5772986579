//! Mesh rays: raywave's wavefront intersect stage and occlusion pass (its own 8-wide BVH,
//! `wavefront::bvh::MeshBvh`) against obvhs's one-ray CWBVH traversal and
//! (with `--features embree`) Embree's single rays and 8-ray packets, on the same primary,
//! shadow and incoherent rays of the generated ~12k and ~1M triangle Cornell boxes.
//!
//! ```text
//! for scene in [12k, 1M]:                        generated in memory by meshgen, built once
//!     print triangles, BVH build times, ray counts, hit agreement against obvhs
//!     for set in [primary, shadow, incoherent, shadow_fan]:  group "<set>_<scene>", throughput in rays
//!         obvhs_one_ray, wavefront, embree_single, embree_packet8
//! ```
//!
//! Every engine traces on one thread, two-sided, on the scene without its emissive wall
//! (`peer::without_emitters`; see `src/peer/mod.rs`). `cargo bench --bench mesh_rays` runs it;
//! `-- --test` traces each set once on a 32×32 image (CI), `-- --quick` shortens the timing.

use criterion::{BenchmarkId, Criterion, Throughput};
use raywave::meshgen::{bands_for, cornell_box_mesh_spheres, triangle_count};
use raywave::peer::{
    Hits, ObvhsMesh, RaySet, RaySets, hit_agreement, occlusion_agreement, wavefront_closest,
    wavefront_occluded, without_emitters,
};
use raywave::scene::{Scene, parse_scene_str};
use raywave::settings::RenderSettings;
use raywave::wavefront::batch::HitBatch;
use raywave::wavefront::context::Context;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Image size of the primary set (65,536 rays; shadow and incoherent: one per primary hit).
const SIZE: u32 = 256;
/// Image size in criterion's `--test` mode.
const TEST_SIZE: u32 = 32;
/// Seed of the shadow and incoherent rays.
const SEED: u64 = 2026;

#[cfg(feature = "embree")]
use raywave::peer::{RayKind, embree::EmbreeMesh};

/// Everything one scene's groups need, built before any timing.
struct Setup {
    label: &'static str,
    scene: Scene,
    settings: RenderSettings,
    obvhs: ObvhsMesh,
    sets: RaySets,
    #[cfg(feature = "embree")]
    embree: EmbreeMesh,
}

fn setup(label: &'static str, target_triangles: usize, size: u32) -> Setup {
    let bands = bands_for(target_triangles);
    let start = Instant::now();
    let text = cornell_box_mesh_spheres(bands);
    let scene = parse_scene_str(&text, label).expect("a generated scene parses");
    let scene = without_emitters(&scene);
    eprintln!(
        "[{label}] {} triangles ({} generated, light wall removed), generated and parsed in {:.2?}",
        scene.triangles.len(),
        triangle_count(bands),
        start.elapsed()
    );
    let obvhs = ObvhsMesh::new(&scene);
    let sets = RaySets::new(&scene, &obvhs, size, size, SEED);
    Setup {
        label,
        settings: RenderSettings {
            width: size,
            height: size,
            two_sided: true,
            ..RenderSettings::default()
        },
        #[cfg(feature = "embree")]
        embree: EmbreeMesh::new(&scene).expect("Embree builds the scene"),
        scene,
        obvhs,
        sets,
    }
}

/// Prints build times, ray counts and agreement: the non-timing half of the comparison.
fn report(s: &Setup, ctx: &Context) {
    let bvh = ctx.accel.as_ref().expect("mesh scenes have a BVH");
    let (nodes, blocks) = bvh.size();
    eprintln!(
        "[{}] BVH build: obvhs CWBVH {:.3} s, wavefront MeshBvh {:.3} s ({nodes} 8-wide nodes, \
         {blocks} triangle blocks, depth {})",
        s.label,
        s.obvhs.build_time.as_secs_f64(),
        ctx.bvh_build_time.as_secs_f64(),
        bvh.depth
    );
    #[cfg(feature = "embree")]
    eprintln!(
        "[{}] BVH build: Embree {:.3} s ({})",
        s.label,
        s.embree.build_time.as_secs_f64(),
        s.embree.describe()
    );
    let mut scratch = HitBatch::default();
    for set in s.sets.all() {
        let mut lines = Vec::new();
        if set.kind.is_occlusion() {
            let (mut reference, mut other) = (Vec::new(), Vec::new());
            s.obvhs.occluded(&s.scene, set, &mut reference);
            let blocked = reference.iter().filter(|&&b| b).count();
            wavefront_occluded(ctx, set, &mut other);
            lines.push(("wavefront", occlusion_agreement(&reference, &other)));
            #[cfg(feature = "embree")]
            {
                s.embree.occluded1(set, &mut other);
                lines.push(("embree_single", occlusion_agreement(&reference, &other)));
                s.embree.occluded8(set, &mut other);
                lines.push(("embree_packet8", occlusion_agreement(&reference, &other)));
            }
            eprintln!(
                "[{}] {}: {} rays, {blocked} blocked",
                s.label,
                set.kind.name(),
                set.len()
            );
        } else {
            let (mut reference, mut other) = (Hits::default(), Hits::default());
            s.obvhs.closest(&s.scene, set, &mut reference);
            let hit = reference.prim.iter().filter(|&&p| p != u32::MAX).count();
            wavefront_closest(ctx, set, &mut scratch, &mut other);
            lines.push(("wavefront", hit_agreement(&reference, &other)));
            #[cfg(feature = "embree")]
            {
                let coherent = set.kind == RayKind::Primary;
                s.embree.closest1(set, coherent, &mut other);
                lines.push(("embree_single", hit_agreement(&reference, &other)));
                s.embree.closest8(set, coherent, &mut other);
                lines.push(("embree_packet8", hit_agreement(&reference, &other)));
            }
            eprintln!(
                "[{}] {}: {} rays, {hit} hit",
                s.label,
                set.kind.name(),
                set.len()
            );
        }
        for (engine, a) in lines {
            eprintln!(
                "[{}] {} agreement with obvhs, {engine}: {:.6} ({} of {} differ; {} on shared edges)",
                s.label,
                set.kind.name(),
                a.fraction(),
                a.disagree(),
                a.rays,
                a.same_t_other_prim
            );
        }
    }
}

fn bench_set(c: &mut Criterion, s: &Setup, ctx: &Context, set: &RaySet) {
    let mut group = c.benchmark_group(format!("{}_{}", set.kind.name(), s.label));
    group.throughput(Throughput::Elements(set.len() as u64));
    let (mut hits, mut blocked, mut scratch) = (Hits::default(), Vec::new(), HitBatch::default());
    let shadow = set.kind.is_occlusion();
    group.bench_function(BenchmarkId::from_parameter("obvhs_one_ray"), |b| {
        b.iter(|| {
            if shadow {
                s.obvhs.occluded(&s.scene, black_box(set), &mut blocked);
            } else {
                s.obvhs.closest(&s.scene, black_box(set), &mut hits);
            }
        })
    });
    group.bench_function(BenchmarkId::from_parameter("wavefront"), |b| {
        b.iter(|| {
            if shadow {
                wavefront_occluded(ctx, black_box(set), &mut blocked);
            } else {
                wavefront_closest(ctx, black_box(set), &mut scratch, &mut hits);
            }
        })
    });
    #[cfg(feature = "embree")]
    {
        let coherent = set.kind != RayKind::Incoherent;
        group.bench_function(BenchmarkId::from_parameter("embree_single"), |b| {
            b.iter(|| {
                if shadow {
                    s.embree.occluded1(black_box(set), &mut blocked);
                } else {
                    s.embree.closest1(black_box(set), coherent, &mut hits);
                }
            })
        });
        group.bench_function(BenchmarkId::from_parameter("embree_packet8"), |b| {
            b.iter(|| {
                if shadow {
                    s.embree.occluded8(black_box(set), &mut blocked);
                } else {
                    s.embree.closest8(black_box(set), coherent, &mut hits);
                }
            })
        });
    }
    black_box((&hits, &blocked));
    group.finish();
}

fn main() {
    // criterion's test mode: `cargo bench -- --test`, or `cargo test --all-targets`, which runs
    // the bench binary without the `--bench` flag that `cargo bench` passes.
    let args: Vec<String> = std::env::args().collect();
    let test_mode = args.iter().any(|a| a == "--test") || !args.iter().any(|a| a == "--bench");
    let size = if test_mode { TEST_SIZE } else { SIZE };
    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        // The plotters backend panics without system fonts (FontUnavailable) on this machine.
        .without_plots()
        .configure_from_args();
    eprintln!("machine: {}, simd {}", cpu_model(), raywave::simd_path());
    for (label, target) in [("12k", 12_000), ("1M", 1_000_000)] {
        let s = setup(label, target, size);
        let ctx = Context::new(&s.scene, &s.settings);
        report(&s, &ctx);
        for set in s.sets.all() {
            bench_set(&mut c, &s, &ctx, set);
        }
    }
    c.final_summary();
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}
