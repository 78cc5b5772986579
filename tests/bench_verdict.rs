//! The bench verdict at its edges: a fall of exactly the threshold is not a regression ("fell
//! by more than"), one just past it is; a record from another SIMD path is noted.

use raywave::bench::compare::compare;
use raywave::bench::record::{
    BenchRecord, EngineRecord, FORMAT, KindRates, Machine, Measurement, SceneId, Setup,
    StageFigure, rfc3339_utc,
};
use raywave::settings::RenderSettings;
use raywave::stats::RayCounts;

/// A record whose total runs at `total` rays/s and whose one stage at `stage` rays/s.
// A deliberate twin of the `record` in src/bench/compare.rs's unit tests: an integration test
// cannot reach `#[cfg(test)]` code, and this one builds the record through the public API only.
fn record(total: f64, stage: f64) -> BenchRecord {
    let rays = RayCounts {
        camera: 100,
        shadow: 1000,
        reflection: 100,
    };
    let seconds = rays.total() as f64 / total;
    let m = Measurement {
        seconds,
        rays,
        rays_per_second: KindRates::new(&rays, seconds),
        stages: vec![StageFigure {
            stage: "shadow".into(),
            rays: 1000,
            thread_seconds: 1000.0 / stage,
            rays_per_thread_second: stage,
        }],
    };
    BenchRecord {
        format: FORMAT,
        raywave: "0".into(),
        git_commit: "unknown".into(),
        git_dirty: None,
        timestamp: rfc3339_utc(0),
        machine: Machine {
            hostname: "h".into(),
            cpu: "c".into(),
            logical_cpus: 2,
            os: "linux".into(),
            arch: "x86_64".into(),
        },
        simd: "avx2".into(),
        setup: Setup {
            scene: SceneId {
                source: "a.obj".into(),
                text_hash: "00".into(),
                triangles: 12,
                spheres: 3,
                lights: 1,
            },
            settings: RenderSettings::preview(),
            threads: 2,
            batch_size: 4096,
        },
        runs: 1,
        engines: vec![EngineRecord {
            engine: "wavefront".into(),
            median: m.clone(),
            runs: vec![m],
        }],
    }
}

#[test]
fn a_fall_of_exactly_the_threshold_passes_and_just_past_it_fails() {
    // 1200 -> 600 rays/s is -50% exactly (in binary too).
    let c = compare(&record(1200.0, 1000.0), &record(600.0, 1000.0), 50.0).unwrap();
    let total = c.rows.iter().find(|r| r.name == "total").unwrap();
    assert_eq!(total.change_pct, -50.0);
    assert!(
        !c.regressed(),
        "exactly the threshold is not past it:\n{}",
        c.table()
    );
    // The same for a stage.
    let c = compare(&record(1000.0, 1000.0), &record(1000.0, 500.0), 50.0).unwrap();
    assert!(!c.regressed(), "{}", c.table());
    // One ray per second more is past it.
    let c = compare(&record(1200.0, 1000.0), &record(599.0, 1000.0), 50.0).unwrap();
    assert!(c.regressed(), "{}", c.table());
    let c = compare(&record(1000.0, 1000.0), &record(1000.0, 499.0), 50.0).unwrap();
    assert!(c.regressed(), "{}", c.table());
}

#[test]
fn another_simd_path_is_noted() {
    let mut after = record(1000.0, 1000.0);
    after.simd = "sse2".into();
    let c = compare(&record(1000.0, 1000.0), &after, 10.0).unwrap();
    assert_eq!(c.notes.len(), 1, "{:?}", c.notes);
    assert!(
        c.notes[0].contains("simd avx2") && c.notes[0].contains("simd sse2"),
        "{:?}",
        c.notes
    );
    assert!(!c.regressed());
}
