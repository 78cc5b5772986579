//! Mesh rays: raywave's wavefront intersect stage and occlusion pass (its own 8-wide BVH,
//! `wavefront::bvh::MeshBvh`) against obvhs's one-ray CWBVH traversal and
//! (with `--features embree`) Embree's single rays and 8-ray packets, on the same primary,
//! shadow and incoherent rays of the generated ~12k and ~1M triangle Cornell boxes.
//!
//! ```text
//! for scene in [12k, 1M]:                        generated in memory by meshgen, built once
//!     print triangles, BVH build times, ray counts, hit agreement against obvhs
//!     for set in [primary, shadow, incoherent, shadow_fan]:  group "<set>_<scene>", throughput in rays
//!         obvhs_one_ray, wavefront, wavefront_bvh (closest-hit sets),
//!         wavefront_one_ray (primary only), embree_single, embree_packet8
//! ```
//!
//! `wavefront` is the engine's intersect stage (traversal, then point, normal and material for
//! shading) on closest-hit sets and its occlusion pass on shadow sets; `wavefront_bvh` is the
//! stage's traversal alone, which returns what obvhs and Embree return (t and prim). The stage
//! traces camera rays in 8-ray packets and all others one ray at a time; `wavefront_one_ray`
//! is the traversal one ray at a time on the camera rays too, so each run shows what the
//! packets buy.
//!
//! Every engine traces on one thread, two-sided, on the scene without its emissive wall
//! (`peer::without_emitters`; see `src/peer/mod.rs`). `cargo bench --bench mesh_rays` runs it;
//! `-- --test` traces each set once on a 32×32 image (CI), `-- --quick` shortens the timing.
//!
//! `RAYWAVE_INTERLEAVE=ROUNDS cargo bench --bench mesh_rays` skips criterion and times the
//! engines in turn, one pass each per round, printing median rays/s and the median of the
//! per-round ratios: on a machine whose speed drifts from second to second, a ratio taken
//! within a round is steadier than one between criterion groups timed seconds apart.
//! `RAYWAVE_MESH=12k` (or `1M`) limits either mode to one scene. The test mode ignores both
//! switches.

mod common;

use criterion::{BenchmarkId, Criterion, Throughput};
use raywave::bench::record::median;
use raywave::meshgen::{bands_for, cornell_box_mesh_spheres, triangle_count};
use raywave::peer::{
    Hits, ObvhsMesh, RayKind, RaySet, RaySets, hit_agreement, occlusion_agreement,
    wavefront_bvh_closest, wavefront_bvh_closest_one_ray, wavefront_closest, wavefront_occluded,
    without_emitters,
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
use raywave::peer::embree::EmbreeMesh;

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
        bvh.build_time.as_secs_f64(),
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
            wavefront_bvh_closest(ctx, set, &mut other);
            lines.push(("wavefront_bvh", hit_agreement(&reference, &other)));
            wavefront_bvh_closest_one_ray(ctx, set, &mut other);
            lines.push(("wavefront_one_ray", hit_agreement(&reference, &other)));
            #[cfg(feature = "embree")]
            {
                s.embree.closest1(set, coherent(set), &mut other);
                lines.push(("embree_single", hit_agreement(&reference, &other)));
                s.embree.closest8(set, coherent(set), &mut other);
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
    let mut out = Outputs::default();
    for engine in engines(set) {
        group.bench_function(BenchmarkId::from_parameter(engine), |b| {
            b.iter(|| trace(s, ctx, set, engine, &mut out))
        });
    }
    group.finish();
}

/// Embree's ray-coherence hint for `set`: every set but the incoherent one.
#[cfg(feature = "embree")]
fn coherent(set: &RaySet) -> bool {
    set.kind != RayKind::Incoherent
}

/// One pass of `engine` over `set`: the same calls the criterion groups time.
fn trace(s: &Setup, ctx: &Context, set: &RaySet, engine: &str, out: &mut Outputs) {
    let shadow = set.kind.is_occlusion();
    let set = black_box(set);
    match (engine, shadow) {
        ("obvhs_one_ray", true) => s.obvhs.occluded(&s.scene, set, &mut out.blocked),
        ("obvhs_one_ray", false) => s.obvhs.closest(&s.scene, set, &mut out.hits),
        ("wavefront", true) => wavefront_occluded(ctx, set, &mut out.blocked),
        ("wavefront", false) => wavefront_closest(ctx, set, &mut out.scratch, &mut out.hits),
        ("wavefront_bvh", false) => wavefront_bvh_closest(ctx, set, &mut out.hits),
        ("wavefront_one_ray", false) => wavefront_bvh_closest_one_ray(ctx, set, &mut out.hits),
        #[cfg(feature = "embree")]
        ("embree_single", true) => s.embree.occluded1(set, &mut out.blocked),
        #[cfg(feature = "embree")]
        ("embree_single", false) => s.embree.closest1(set, coherent(set), &mut out.hits),
        #[cfg(feature = "embree")]
        ("embree_packet8", true) => s.embree.occluded8(set, &mut out.blocked),
        #[cfg(feature = "embree")]
        ("embree_packet8", false) => s.embree.closest8(set, coherent(set), &mut out.hits),
        _ => unreachable!("engine {engine}"),
    }
    black_box(&*out);
}

#[derive(Default)]
struct Outputs {
    hits: Hits,
    blocked: Vec<bool>,
    scratch: HitBatch,
}

/// Every engine, in the order they are timed. `wavefront` is the intersect stage for closest
/// hits (traversal, then the shading columns) and the occlusion pass for shadow rays;
/// `wavefront_bvh` is the stage's traversal alone, with the same outputs (t, prim) as obvhs and
/// Embree, so it is timed on closest-hit sets only (on shadow sets it is `wavefront`).
const ENGINES: &[&str] = &[
    "obvhs_one_ray",
    "wavefront",
    "wavefront_bvh",
    "wavefront_one_ray",
    #[cfg(feature = "embree")]
    "embree_single",
    #[cfg(feature = "embree")]
    "embree_packet8",
];

/// The engines timed on `set`.
fn engines(set: &RaySet) -> Vec<&'static str> {
    let shadow = set.kind.is_occlusion();
    ENGINES
        .iter()
        .copied()
        .filter(|&e| !(shadow && e == "wavefront_bvh"))
        .filter(|&e| set.kind == RayKind::Primary || e != "wavefront_one_ray")
        .collect()
}

/// `RAYWAVE_INTERLEAVE=ROUNDS`: instead of criterion's groups (each engine timed for seconds,
/// one after another), every round times one pass of each engine in turn, and the ratios are
/// taken within a round. Load from outside the machine then moves both sides of a ratio alike;
/// the medians over rounds are printed.
fn interleaved(s: &Setup, ctx: &Context, rounds: usize) {
    let mut out = Outputs::default();
    for set in s.sets.all() {
        let rays = set.len() as f64;
        let engines = engines(set);
        let mut rates: Vec<Vec<f64>> = vec![Vec::new(); engines.len()];
        for round in 0..=rounds {
            // Each round starts one engine later, so that no engine always follows the same
            // one: `wavefront_bvh` right after `wavefront` would find the same tree and rays
            // in the caches every time.
            for step in 0..engines.len() {
                let e = (round + step) % engines.len();
                let engine = engines[e];
                let start = Instant::now();
                trace(s, ctx, set, engine, &mut out);
                let rate = rays / start.elapsed().as_secs_f64() / 1e6;
                if round > 0 {
                    // round 0 warms the caches and is not counted
                    rates[e].push(rate);
                }
            }
        }
        let mut line = format!(
            "{}_{} Mrays/s, median of {rounds}:",
            set.kind.name(),
            s.label
        );
        for (e, engine) in engines.iter().enumerate() {
            line += &format!(" {engine} {:.2}", median(&rates[e]));
        }
        // Ratios within each round, then their median.
        let ratio = |a: usize, b: usize| {
            let ratios: Vec<f64> = rates[a].iter().zip(&rates[b]).map(|(x, y)| x / y).collect();
            median(&ratios)
        };
        for (ours, theirs) in [
            ("wavefront", "obvhs_one_ray"),
            ("wavefront_bvh", "obvhs_one_ray"),
            ("wavefront", "embree_single"),
            ("wavefront_bvh", "embree_single"),
            ("wavefront_bvh", "wavefront_one_ray"),
            ("wavefront", "embree_packet8"),
        ] {
            let at = |name| engines.iter().position(|&e| e == name);
            if let (Some(a), Some(b)) = (at(ours), at(theirs)) {
                line += &format!(" | {ours}/{theirs} {:.2}x", ratio(a, b));
            }
        }
        println!("{line}");
    }
}

fn main() {
    // The test mode ignores the RAYWAVE_* switches, so that CI's run stays short whatever the
    // environment.
    let test_mode = common::test_mode();
    // RAYWAVE_MESH=12k or 1M: one scene only, in either mode.
    let only = if test_mode {
        String::new()
    } else {
        std::env::var("RAYWAVE_MESH").unwrap_or_default()
    };
    if !["", "12k", "1M"].contains(&only.as_str()) {
        exit_with(&format!("RAYWAVE_MESH={only}: expected 12k or 1M"));
    }
    // RAYWAVE_INTERLEAVE=ROUNDS: the interleaved mode instead of criterion's groups.
    let interleave = match std::env::var("RAYWAVE_INTERLEAVE") {
        Ok(rounds) if !test_mode => match rounds.parse::<usize>() {
            Ok(n) if n > 0 => Some(n),
            _ => exit_with(&format!(
                "RAYWAVE_INTERLEAVE={rounds}: expected a number of rounds, 1 or more"
            )),
        },
        _ => None,
    };
    let size = if test_mode { TEST_SIZE } else { SIZE };
    let mut c = common::criterion_for_frames(Duration::from_millis(300));
    eprintln!(
        "machine: {}, simd {}",
        raywave::machine::cpu_model(),
        raywave::simd_path()
    );
    for (label, target) in [("12k", 12_000), ("1M", 1_000_000)] {
        if !only.is_empty() && only != label {
            continue;
        }
        let s = setup(label, target, size);
        let ctx = Context::new(&s.scene, &s.settings);
        if let Some(rounds) = interleave {
            interleaved(&s, &ctx, rounds);
            continue;
        }
        report(&s, &ctx);
        for set in s.sets.all() {
            bench_set(&mut c, &s, &ctx, set);
        }
        if test_mode {
            // The interleaved mode's code, once, so that CI keeps it running.
            interleaved(&s, &ctx, 1);
        }
    }
    if interleave.is_none() {
        c.final_summary();
    }
}

/// Prints `message` and exits with status 2 (a bad switch, before any measuring).
fn exit_with(message: &str) -> ! {
    eprintln!("mesh_rays: {message}");
    std::process::exit(2)
}
