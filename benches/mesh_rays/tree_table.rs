//! The tree table (`RAYWAVE_TREE_TABLE=ROUNDS`, feature `embree4`): raywave's mesh tree
//! against the trees Embree 4's builder makes of the same triangles, all collapsed by
//! `MeshBvh::from_bvh2` and traced by raywave's one walk, so that only the builds differ
//! (docs/BENCHMARKING.md, "The tree table").
//!
//! ```text
//! per mesh scene, per tree [raywave: obvhs PLOC + reinsertion (medium_build),
//!                           Embree: binned SAH (medium), Embree: SAH + spatial splits (high)]:
//!     notes    build time, 8-wide nodes, triangle blocks, bytes, depth
//!     per ray set: nodes, leaves and triangles tested per ray (the counted walk), Mrays/s
//!              (the uncounted walk the renderer runs), interleaved rounds, and the median of
//!              the per-round ratios to raywave's tree; answers checked against it first
//! ```

use super::{Outputs, Setup, agreement, answer, exit_with, ratio, trace};
use crate::peer::embree4::BuildQuality;
use crate::peer::embree4_tree::embree_bvh2;
use crate::peer::{RaySet, mesh_bvh_bytes};
use raywave::render::wavefront::bvh::MeshBvh;
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::cost::{Cost, PerRay};
use raywave::render::wavefront::intersect;
use raywave::stats::median;
use std::time::Instant;

/// The table's rows and the notes under it.
#[derive(Default)]
pub struct TreeTable {
    rows: Vec<String>,
    notes: Vec<String>,
}

/// Nodes, leaves and triangles tested per ray of `set` through `bvh`, as the renderer's walk
/// counts them (`--stats`, the cost map).
fn per_ray(ctx: &Context, bvh: &MeshBvh, set: &RaySet) -> [f64; 3] {
    let mut sum = Cost::default();
    let two_sided = ctx.settings.two_sided;
    for batch in &set.batches {
        let mut costs = vec![Cost::default(); batch.len()];
        let mut sink = PerRay(&mut costs);
        if set.kind.is_occlusion() {
            let mut blocked = vec![false; batch.len()];
            let rays = intersect::columns(batch);
            bvh.occluded(ctx.scene, &rays, two_sided, &mut blocked, &mut sink);
        } else {
            let (mut t, mut prim) = (vec![0.0; batch.len()], vec![0; batch.len()]);
            intersect::mesh_hits(
                bvh, ctx.scene, batch, two_sided, &mut t, &mut prim, &mut sink,
            );
        }
        for c in costs {
            sum += c;
        }
    }
    let n = set.len().max(1) as f64;
    [sum.nodes, sum.leaves, sum.tests].map(|x| x as f64 / n)
}

/// The rows and notes of one mesh scene (`ctx` holds raywave's own tree).
pub fn tree_rows(s: &Setup, ctx: &Context, rounds: usize, table: &mut TreeTable) {
    let Some(ours) = &ctx.accel else {
        return; // the lab's box: no tree
    };
    let title = format!("{} ({} triangles)", s.label, s.scene.triangles.len());
    let mut trees = vec![("raywave (obvhs PLOC, medium_build)", None)];
    let mut builds = vec![format!("raywave {:.3} s", ours.build_time.as_secs_f64())];
    for (name, quality) in [
        ("Embree 4 binned SAH (medium)", BuildQuality::Medium),
        ("Embree 4 SAH + spatial splits (high)", BuildQuality::High),
    ] {
        let (bvh2, time) =
            embree_bvh2(&s.scene, quality).unwrap_or_else(|e| exit_with(&format!("{e:#}")));
        let tree = MeshBvh::from_bvh2(&s.scene, &bvh2);
        builds.push(format!(
            "{name} {:.3} s (Embree's threads) + collapse {:.3} s, {} references to {} triangles",
            time.as_secs_f64(),
            tree.build_time.as_secs_f64(),
            bvh2.primitive_indices.len(),
            s.scene.triangles.len()
        ));
        let mut other = Context::new(&s.scene, &s.settings);
        other.accel = Some(tree);
        trees.push((name, Some(other)));
    }
    let contexts: Vec<&Context> = trees
        .iter()
        .map(|(_, c)| c.as_ref().unwrap_or(ctx))
        .collect();
    for ((name, _), c) in trees.iter().zip(&contexts) {
        let bvh = c.accel.as_ref().expect("every tree row has a tree");
        let (nodes, blocks) = bvh.size();
        table.notes.push(format!(
            "{title}, {name}: {nodes} 8-wide nodes, {blocks} triangle blocks, depth {}, {:.1} MB.",
            bvh.depth,
            mesh_bvh_bytes(bvh) as f64 / 1e6
        ));
    }
    table
        .notes
        .push(format!("{title}, builds: {}.", builds.join("; ")));
    for set in s.sets.all() {
        let reference = answer(s, ctx, set, "raywave");
        for (&c, (name, _)) in contexts.iter().zip(&trees).skip(1) {
            let a = agreement(s, c, set, &reference, "raywave");
            let (agree, rays) = (a.agree, a.rays);
            if agree < rays {
                table.notes.push(format!(
                    "{title}, {}, {name}: {agree} of {rays} answers equal raywave's tree's \
                     (the grazing exception: which of two hits a grazing ray finds first).",
                    set.kind.title()
                ));
            }
        }
        let rates = time_trees(s, &contexts, set, rounds);
        for (e, ((name, _), c)) in trees.iter().zip(&contexts).enumerate() {
            let [nodes, leaves, tests] = per_ray(c, c.accel.as_ref().expect("a tree"), set);
            table.rows.push(format!(
                "| {title} | {} | {name} | {nodes:.2} | {leaves:.2} | {tests:.1} | {:.2} | {:.2}× |",
                set.kind.title(),
                median(&rates[e]),
                ratio(&rates, e, 0)
            ));
        }
    }
}

/// Mrays/s of raywave's walk on `set` through each context's tree, one pass each per round,
/// each round starting one tree later; round 0 warms the caches and is not counted.
fn time_trees(s: &Setup, contexts: &[&Context], set: &RaySet, rounds: usize) -> Vec<Vec<f64>> {
    let mut rates = vec![Vec::new(); contexts.len()];
    let mut out = Outputs::default();
    for round in 0..=rounds {
        for step in 0..contexts.len() {
            let e = (round + step) % contexts.len();
            let start = Instant::now();
            let rays = trace(s, contexts[e], set, "raywave", &mut out) as f64;
            if round > 0 {
                rates[e].push(rays / start.elapsed().as_secs_f64() / 1e6);
            }
        }
    }
    rates
}

/// Prints the table and its notes as Markdown.
pub fn print_tree_table(rounds: usize, size: u32, table: &TreeTable) {
    println!(
        "\nTrees, one walk (raywave's), {size}×{size} ray sets, one thread, medians of {rounds} \
         interleaved rounds:\n"
    );
    println!(
        "| scene | ray kind | tree | nodes / ray | leaves / ray | triangles / ray | Mrays/s | \
         / raywave's tree |"
    );
    println!("| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |");
    for row in &table.rows {
        println!("{row}");
    }
    println!();
    for note in &table.notes {
        println!("- {note}");
    }
}
