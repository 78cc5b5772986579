//! Timing the engines at one point: untimed warm-up runs, then timed runs in rounds, each
//! round running every engine once and starting one engine later than the round before, so
//! that no engine always runs after the same one (and inherits its caches, its heat, the
//! turbo state it left).
//!
//! ```text
//! prepare each engine (BVH, tables) on the pool
//! warm-up:  for w in 0..warmup: every engine once, untimed
//! timed:    for round in 0..runs: engines rotated by round, each once; seconds, rays, stages
//! per engine: medians of every figure, and the summary of the headline figures
//! ```

use crate::bench::{BenchOptions, Plan};
use crate::output::bench_record::{EngineRecord, KindFigures, Measurement, summarise};
use crate::render::engine::{Engine, Prepared, clamped_warning};
use crate::render::film::Film;
use crate::render::progress::{Progress, Steps};
use crate::render::scene::Scene;
use crate::render::wavefront::DEFAULT_BATCH_SIZE;
use std::time::Instant;

/// Warm-up and timed runs of `plan`'s engines on its pool, with `args`' run counts and lane
/// width; `runs_done` steps after each run (warm-up included), `notice` for a run that clamped
/// pixels. Records come back in the plan's engine order.
pub(in crate::bench) fn measure(
    plan: &Plan,
    scene: &Scene,
    args: &BenchOptions,
    runs_done: &Steps,
    notice: &(dyn Fn(&str) + Sync),
) -> Vec<EngineRecord> {
    plan.pool.install(|| {
        let prepared: Vec<Prepared> = plan
            .engines
            .iter()
            .map(|e| e.prepare_lanes(scene, &plan.setup.settings, DEFAULT_BATCH_SIZE, args.lanes))
            .collect();
        let time = |engine: &Prepared| {
            let start = Instant::now();
            let (film, stats) = engine.render(&Progress::SILENT);
            let seconds = start.elapsed().as_secs_f64();
            drop::<Film>(film);
            if let Some(w) = clamped_warning(&stats) {
                notice(&w);
            }
            let stages = match engine.engine() {
                Engine::Wavefront => stats.stage_figures(),
                Engine::Reference => Vec::new(),
            };
            Measurement {
                rays: KindFigures::new(&stats, seconds),
                stages,
            }
        };
        for _ in 0..args.warmup {
            for engine in &prepared {
                time(engine);
                runs_done.step();
            }
        }
        let mut measured: Vec<Vec<Measurement>> = vec![Vec::new(); prepared.len()];
        for round in 0..args.runs as usize {
            for i in round_order(prepared.len(), round) {
                measured[i].push(time(&prepared[i]));
                runs_done.step();
            }
        }
        prepared
            .iter()
            .zip(measured)
            .map(|(engine, runs)| EngineRecord {
                engine: engine.engine().name().to_string(),
                median: Measurement::median_of(&runs),
                summary: summarise(&runs),
                runs,
            })
            .collect()
    })
}

/// The order in which round `round` runs `n` engines: 0..n rotated by `round`, so each engine
/// goes first in turn.
fn round_order(n: usize, round: usize) -> Vec<usize> {
    (0..n).map(|i| (i + round) % n.max(1)).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn each_engine_goes_first_in_turn() {
        assert_eq!(super::round_order(2, 0), [0, 1]);
        assert_eq!(super::round_order(2, 1), [1, 0]);
        assert_eq!(super::round_order(2, 2), [0, 1]);
        assert_eq!(super::round_order(1, 5), [0]);
        assert_eq!(super::round_order(3, 1), [1, 2, 0]);
    }
}
