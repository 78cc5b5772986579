//! Cancellation: `Prepared::render_until` stops within about one work unit per thread once its
//! flag is set, and a render it lets finish is `render`'s, bit for bit.
//!
//! The units are counted through `progress`, to which the engines report each unit they render
//! (a wavefront tile, a reference row). The flag is set from `progress` itself after `K`
//! units: at that moment every other worker holds at most one unit it has already started, so
//! at most `K + threads - 1` units can be rendered in all. Each image has many times more units
//! than that, so a worker that did not read the flag before each unit would render them all.

use raywave::render::engine::{Engine, Prepared};
use raywave::render::film::Film;
use raywave::render::progress::Progress;
use raywave::render::scene::Scene;
use raywave::render::settings::{RenderSettings, ShadowMode};
use raywave::render::wavefront::stats::RenderStats;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Units rendered before the flag is set.
const K: u64 = 5;

/// Camera samples per wavefront tile: 16 pixels at 1 aa sample, so 64 tiles in 32 × 32.
const BATCH: usize = 16;

fn settings() -> RenderSettings {
    RenderSettings {
        width: 32,
        height: 64,
        bounces: 1,
        shadows: ShadowMode::Soft,
        shadow_samples: 2,
        aa_samples: 1,
        ..RenderSettings::default()
    }
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// Renders with a flag that `progress` sets after its `stop_after`-th unit; returns the result,
/// how many units were rendered, and the units in all with their name.
fn render_stopping_after(
    prepared: &Prepared,
    threads: usize,
    stop_after: u64,
) -> (Option<(Film, RenderStats)>, u64, (u64, String)) {
    let done = AtomicU64::new(0);
    let cancel = AtomicBool::new(false);
    let units = Mutex::new((0, String::new()));
    let report = |steps: u64, total: u64, what: &str| {
        if steps == 0 {
            *units.lock().unwrap() = (total, what.to_owned());
        } else if done.fetch_add(1, Ordering::Relaxed) + 1 == stop_after {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let progress = Progress {
        report: &report,
        ..Progress::SILENT
    };
    let result = pool(threads).install(|| prepared.render_until(&progress, &cancel));
    (result, done.into_inner(), units.into_inner().unwrap())
}

/// The units of one render of `prepared`, and their name.
fn units_of(prepared: &Prepared) -> (u64, String) {
    render_stopping_after(prepared, 1, u64::MAX).2
}

fn bits(film: &Film) -> Vec<[u32; 3]> {
    film.pixels
        .iter()
        .map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()])
        .collect()
}

#[test]
fn a_cancelled_render_stops_within_a_unit_per_thread() {
    let scene = Scene::builtin_default();
    let s = settings();
    for engine in [Engine::Wavefront, Engine::Reference] {
        let prepared = engine.prepare(&scene, &s, BATCH);
        let (units, what) = units_of(&prepared);
        for threads in [1, 2, 4] {
            let bound = K + threads as u64 - 1;
            assert!(units > 4 * bound, "{engine:?}: {units} {what} are too few");
            let (result, done, _) = render_stopping_after(&prepared, threads, K);
            // One thread: exactly K, the unit that set the flag is the last one started.
            assert!(
                (K..=bound).contains(&done),
                "{engine:?}, {threads} threads: {done} of {units} {what} rendered after a \
                 cancel at {K}, expected {K}..={bound}"
            );
            assert!(
                result.is_none(),
                "{engine:?}, {threads} threads: a cancelled render returned an image"
            );
        }
    }
}

#[test]
fn an_uncancelled_render_until_is_render_bit_for_bit() {
    let scene = Scene::builtin_default();
    let s = RenderSettings {
        aa_samples: 2,
        bounces: 2,
        ..settings()
    };
    for engine in [Engine::Wavefront, Engine::Reference] {
        let prepared = engine.prepare(&scene, &s, BATCH);
        let (units, _) = units_of(&prepared);
        let (film, stats) = pool(2).install(|| prepared.render(&Progress::SILENT));
        let never = AtomicBool::new(false);
        let (until, until_stats) = pool(2)
            .install(|| prepared.render_until(&Progress::SILENT, &never))
            .unwrap_or_else(|| panic!("{engine:?}: an unset flag cancelled the render"));
        assert_eq!(bits(&film), bits(&until), "{engine:?}: flag never set");
        assert_eq!(stats.counts, until_stats.counts, "{engine:?}");
        assert_eq!(
            stats.clamped_pixels, until_stats.clamped_pixels,
            "{engine:?}"
        );
        // A flag set by the last unit skips nothing: the image is whole, and returned.
        let (last, done, _) = render_stopping_after(&prepared, 2, units);
        assert_eq!(done, units, "{engine:?}");
        let (last, last_stats) =
            last.unwrap_or_else(|| panic!("{engine:?}: a flag set after the last unit lost it"));
        assert_eq!(bits(&film), bits(&last), "{engine:?}: flag set at the end");
        assert_eq!(stats.counts, last_stats.counts, "{engine:?}");
        // And the images are not empty: the check compares something.
        assert!(
            stats.counts.shadow > 0 && stats.counts.reflection > 0,
            "{stats:?}"
        );
    }
}
