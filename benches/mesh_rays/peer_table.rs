//! The peer table (`RAYWAVE_PEER_TABLE=ROUNDS`): raywave's traversal against each peer's on
//! the same rays, and the renderer's stages beside them, printed as Markdown
//! (docs/BENCHMARKING.md, "The peer table").

use super::{
    Outputs, Setup, agreement, answer, builds, peers, ratio, stage_engine, time_rounds, trace,
};
use crate::peer::stage::ShadowStage;
use raywave::render::wavefront::context::Context;
use raywave::stats::median;
/// Agreement of a peer with raywave below which the peer table flags a cell.
const TABLE_MIN_AGREEMENT: f64 = 0.9999;

/// The peer table's rows, its stage table's rows and the notes under them.
#[derive(Default)]
pub struct Tables {
    rows: Vec<String>,
    stage_rows: Vec<String>,
    notes: Vec<String>,
}

/// The rows of the peer table and of the stage table for one scene, and its notes (builds,
/// agreement).
pub fn peer_rows(s: &Setup, ctx: &Context, rounds: usize, tables: &mut Tables) {
    let Tables {
        rows,
        stage_rows,
        notes,
    } = tables;
    let peers = peers();
    let title = match ctx.accel {
        Some(_) => format!("{} ({} triangles)", s.label, s.scene.triangles.len()),
        None => format!("lab box ({} triangles, no BVH)", s.scene.triangles.len()),
    };
    notes.push(format!("{title}, builds: {}.", builds(s, ctx).join("; ")));
    for set in s.sets.all() {
        let stage = stage_engine(set);
        let mut engines = vec!["raywave", stage];
        engines.extend(peers.iter().map(|(engine, _)| *engine));
        let stage_settings = ShadowStage::settings(&s.settings, set.kind);
        let mut out = Outputs {
            stage: stage_settings
                .as_ref()
                .map(|settings| ShadowStage::new(&s.scene, settings, &s.sets.primary)),
            ..Outputs::default()
        };
        let stage_rays = trace(s, ctx, set, stage, &mut out);
        // Agreement with raywave first: a fast wrong answer is not a figure.
        let reference = answer(s, ctx, set, "raywave");
        let mut marks = Vec::new();
        for (engine, column) in &peers {
            let a = agreement(s, ctx, set, &reference, engine);
            let low = a.fraction() <= TABLE_MIN_AGREEMENT;
            if low {
                notes.push(format!(
                    "**{title}, {}, {column}: agrees with raywave on only {} of {} rays.**",
                    set.kind.title(),
                    a.agree,
                    a.rays
                ));
            }
            marks.push(if low { " ✗" } else { "" });
        }
        let rates = time_rounds(s, ctx, set, &engines, rounds, &mut out);
        // tinybvh has no occlusion query in the crate: its shadow figures are closest hits.
        let closest_only = |engine: &str| set.kind.is_occlusion() && engine.starts_with("tinybvh");
        let mut row = format!(
            "| {title} | {} | {} | {:.2} |",
            set.kind.title(),
            set.len(),
            median(&rates[0])
        );
        let mut cells = String::new();
        for (p, (engine, _)) in peers.iter().enumerate() {
            let dagger = if closest_only(engine) { "†" } else { "" };
            cells += &format!(" {:.2}{dagger}{} |", median(&rates[p + 2]), marks[p]);
        }
        row += &cells;
        for p in 0..peers.len() {
            row += &format!(" {:.2}× |", ratio(&rates, 0, p + 2));
        }
        rows.push(row);
        let mut row = format!(
            "| {title} | {} | {stage_rays} | {:.2} | {:.2} |{cells} {:.2}× |",
            set.kind.title(),
            median(&rates[1]),
            median(&rates[0]),
            ratio(&rates, 1, 0)
        );
        for p in 0..peers.len() {
            row += &format!(" {:.2}× |", ratio(&rates, 1, p + 2));
        }
        stage_rows.push(row);
    }
}

/// `RAYWAVE_PEER_TABLE=ROUNDS`: the peer table and the stage table of every scene, printed as
/// Markdown.
pub fn print_peer_table(rounds: usize, size: u32, tables: &Tables) {
    let Tables {
        rows,
        stage_rows,
        notes,
    } = tables;
    let peers = peers();
    let mut header = "| scene | ray kind | rays | raywave".to_string();
    let mut rule = "| --- | --- | ---: | ---:".to_string();
    for (_, column) in &peers {
        header += &format!(" | {column}");
        rule += " | ---:";
    }
    for (_, column) in &peers {
        header += &format!(" | raywave / {column}");
        rule += " | ---:";
    }
    println!(
        "Mrays/s on one thread, median of {rounds} interleaved rounds (every engine once per \
         round, in rotating order); ratios are medians of the per-round ratios. {size}×{size} \
         camera rays; machine: {}, simd {}.\n",
        raywave::output::machine::cpu_model(),
        raywave::simd_path()
    );
    println!("{header} |");
    println!("{rule} |");
    for row in rows {
        println!("{row}");
    }
    println!();
    println!(
        "raywave: the path the renderer takes for the scene (the BVH traversal of the intersect \
         stage, camera rays in packets of 8, and `MeshBvh::occluded` for shadow rays; below 64 \
         triangles the brute-force `simd::closest_hits`/`simd::occluded`). Every engine traces \
         two-sided, on the scene without its light wall (and the lab box without its spheres: \
         the peers trace triangles)."
    );
    #[cfg(feature = "embree4")]
    println!(
        "\nEmbree single: `rtcIntersect1`/`rtcOccluded1`. Embree packet8: \
         `rtcIntersect8`/`rtcOccluded8` on 8 consecutive rays of the set (one origin per packet \
         on soft-shadow rows). Both with the `COHERENT` flag on every set but the incoherent \
         one, after a build at the quality the notes give (`RAYWAVE_EMBREE_QUALITY`, default \
         high: SAH with spatial splits). Embree 4: the library of `RAYWAVE_EMBREE4_DIR` \
         (the embreex wheel's), loaded with dlopen. Bytes: raywave's nodes and triangle \
         blocks; Embree's from its memory monitor, what the commit left held (the BVH and its \
         Triangle4 leaves)."
    );
    #[cfg(feature = "tinybvh")]
    println!(
        "\ntinybvh: one ray per `Intersect` call through tinybvh-rs 0.1.0-beta.3 (tinybvh 1.6.8). \
         † tinybvh-rs binds no occlusion query: its shadow rays are traced with the closest-hit \
         `Intersect` limited to tmax, which does not stop at the first blocker. tinybvh-rs has \
         no BVH4_CPU layout and no packet calls."
    );
    let mut header = "| scene | ray kind | stage rays | raywave stage | raywave".to_string();
    let mut rule = "| --- | --- | ---: | ---: | ---:".to_string();
    for (_, column) in &peers {
        header += &format!(" | {column}");
        rule += " | ---:";
    }
    header += " | stage / raywave";
    rule += " | ---:";
    for (_, column) in &peers {
        header += &format!(" | stage / {column}");
        rule += " | ---:";
    }
    println!(
        "\nThe renderer's stages, timed in the same rounds: for camera and incoherent rays the \
         intersect stage on the same rays (the hit search, then each hit's point, normal and \
         material); for shadow rays the whole shadow stage (`peer::stage::ShadowStage`: \
         spawning, occlusion and shading, as a frame at zero bounces runs it) over the camera \
         hits, on rays of the same kind: one per hit for hard shadows (to the light's \
         centroid), n per hit for n soft points (stratified). The other columns are the \
         table above's.\n"
    );
    println!("{header} |");
    println!("{rule} |");
    for row in stage_rows {
        println!("{row}");
    }
    if !peers.is_empty() {
        println!(
            "\n✗: the peer disagrees with raywave on more than 0.01% of the set's rays (the \
             rules of `peer::hit_agreement`, `occlusion_agreement` and, for †, \
             `blocker_agreement`; see the notes)."
        );
    }
    println!();
    for note in notes {
        println!("- {note}");
    }
}
