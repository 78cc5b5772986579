//! The `--stats-json` file of `raywave render`: one render's figures, with the machine, the
//! build and the settings. It shares [`Machine`], [`KindFigures`], [`StageFigure`] and the
//! layout version ([`FORMAT`](crate::output::bench_record::FORMAT)) with `raywave bench`'s
//! records, so both describe a machine, a kind and a stage alike; docs/SCHEMA.md describes both
//! and docs/schema/ holds their JSON Schemas, generated from these types by [`schemas`].

use crate::output::bench_record::{BenchRecord, KindFigures};
use crate::output::machine::Machine;
use crate::render::engine::Engine;
use crate::render::per_kind::{PerKind, RayCounts};
use crate::render::settings::RenderSettings;
use crate::render::wavefront::cost::CostSum;
use crate::render::wavefront::stats::StageFigure;
use schemars::JsonSchema;
use serde::Serialize;
use std::path::Path;

/// Everything `--stats-json` writes.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct RenderRecord {
    /// Layout version, shared with bench records (`raywave::output::bench_record::FORMAT`).
    #[schemars(extend("const" = crate::output::bench_record::FORMAT))]
    pub format: u32,
    /// raywave's version.
    pub raywave: &'static str,
    /// The machine (without its host name).
    pub machine: Machine,
    /// The SIMD path the wavefront engine ran on (`raywave::simd_path_for` its `--lanes`).
    pub simd: &'static str,
    /// Worker threads.
    pub threads: usize,
    /// The engine that rendered.
    pub engine: Engine,
    /// Wavefront camera samples per tile (as given, whichever the engine).
    pub batch_size: u32,
    /// How the wavefront engine's shadow stage ran (`FusedSoft`, `FusedHard` or
    /// `QueuedPerHit`: `raywave::render::wavefront::shadow::ShadowPath`); null for the
    /// reference.
    pub shadow_path: Option<&'static str>,
    /// The scene.
    pub scene: SceneFigures,
    /// The settings the image was rendered with.
    pub settings: RenderSettings,
    /// Whose defaults filled which settings.
    pub defaults: DefaultsUsed,
    /// Wall-clock seconds of the render.
    pub seconds: f64,
    /// Rays by kind with each kind's rate per thread-second of its own work, and the total
    /// per wall-clock second.
    pub rays: KindFigures,
    /// How the kinds' thread-seconds were measured: `stage timers` (wavefront),
    /// `instrumented pass` (the reference: a second render of the frame with timers, so the
    /// timed render had none).
    pub kinds_timed_by: KindTiming,
    /// Wall-clock seconds of the reference's instrumented pass (null for the wavefront
    /// engine): beside `seconds`, the timers' cost.
    pub instrumented_seconds: Option<f64>,
    /// Per stage (null for the reference, which has no stages).
    pub stages: Option<Vec<StageFigure>>,
    /// The wavefront engine's traversal work per ray, by kind, from a second, counted render
    /// of the frame (null for the reference, which has no counters).
    pub traversal: Option<TraversalFigures>,
}

/// Each kind's traversal work, counted by a second render of the frame (the render timed in
/// `seconds` counted nothing).
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
pub struct TraversalFigures {
    /// Each kind: camera rays' and mirror rays' closest hits, shadow rays' occlusion tests.
    #[serde(flatten)]
    pub kinds: PerKind<TraversalFigure>,
    /// Wall-clock seconds of the counted pass.
    pub counted_seconds: f64,
}

/// One kind's BVH nodes, leaves and primitive tests, in all and per ray.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
pub struct TraversalFigure {
    /// Rays cast.
    pub rays: u64,
    /// Interior nodes visited (each an 8-wide test of child boxes; 0 without a BVH).
    pub nodes: u64,
    /// Leaves visited (each a block of up to 8 triangles; 0 without a BVH).
    pub leaves: u64,
    /// Primitives tested: the leaves' triangles, spheres, and without a BVH every primitive
    /// its 8- or 16-ray block tested.
    pub primitive_tests: u64,
    /// nodes / rays (null without rays).
    pub nodes_per_ray: Option<f64>,
    /// leaves / rays (null without rays).
    pub leaves_per_ray: Option<f64>,
    /// primitive_tests / rays (null without rays).
    pub primitive_tests_per_ray: Option<f64>,
}

impl TraversalFigures {
    /// The figures of a counted render's sums and its ray counts.
    pub fn new(totals: &PerKind<CostSum>, rays: &RayCounts, counted_seconds: f64) -> Self {
        TraversalFigures {
            kinds: PerKind::from_fn(|kind| {
                let (sum, n) = (totals[kind], rays[kind]);
                let per = |x: u64| (n > 0).then(|| x as f64 / n as f64);
                TraversalFigure {
                    rays: n,
                    nodes: sum.nodes,
                    leaves: sum.leaves,
                    primitive_tests: sum.tests,
                    nodes_per_ray: per(sum.nodes),
                    leaves_per_ray: per(sum.leaves),
                    primitive_tests_per_ray: per(sum.tests),
                }
            }),
            counted_seconds,
        }
    }
}

/// The scene's size, and the wavefront engine's BVH.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct SceneFigures {
    /// File path, or `<built-in ...>`.
    pub source: String,
    /// Triangles after parsing.
    pub triangles: usize,
    /// Spheres.
    pub spheres: usize,
    /// Lights.
    pub lights: usize,
    /// Whether the wavefront engine built a mesh BVH (null for the reference).
    pub bvh: Option<bool>,
    /// How long that took.
    pub bvh_build_seconds: Option<f64>,
}

/// Whose defaults filled the settings no flag set.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct DefaultsUsed {
    /// `raywave`, `lab` or `rpi`.
    pub from: &'static str,
    /// The settings they filled, as the summary names them.
    #[serde(rename = "for")]
    pub settings: Vec<&'static str>,
}

/// How a render's kinds were timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, JsonSchema)]
pub enum KindTiming {
    /// The wavefront engine's stage timers, which run in every render.
    #[serde(rename = "stage timers")]
    StageTimers,
    /// The reference's second render of the frame, with timers (the timed render had none).
    #[serde(rename = "instrumented pass")]
    InstrumentedPass,
}

/// The JSON Schemas of the `--stats-json` file and of a bench record, as (file name, pretty
/// JSON with a final newline): docs/schema/ holds these, and tests/commands/schema.rs checks that
/// it still does.
pub fn schemas() -> [(&'static str, String); 2] {
    // The files as written: every field required (an absent value is written as null),
    // except the few left out when empty (a bench record's host name in `--stats-json`).
    let settings = schemars::generate::SchemaSettings::draft2020_12().for_serialize();
    let generator = || settings.clone().into_generator();
    let pretty = |schema| serde_json::to_string_pretty(&schema).unwrap_or_default() + "\n";
    [
        (
            "render-record.schema.json",
            pretty(generator().into_root_schema_for::<RenderRecord>()),
        ),
        (
            "bench-record.schema.json",
            pretty(generator().into_root_schema_for::<BenchRecord>()),
        ),
    ]
}

impl RenderRecord {
    /// Writes the record as pretty JSON, whole or not at all, with `extra` as one more
    /// top-level entry (e.g. `mse_reference`, the render's error against `render
    /// --mse-reference`). It goes through `serde_json::Value`, whose objects sort their keys:
    /// the files have always listed every object's keys alphabetically.
    pub fn write(
        &self,
        path: &Path,
        extra: Option<(&str, serde_json::Value)>,
    ) -> anyhow::Result<()> {
        let mut json = serde_json::to_value(self)?;
        if let Some((key, value)) = extra {
            json[key] = value;
        }
        crate::output::image_file::write_json(path, &json)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::bench_record::FORMAT;
    use crate::render::wavefront::stats::RenderStats;

    #[test]
    fn the_file_keeps_its_keys_sorted_and_names_no_host() {
        let stats = RenderStats {
            counts: crate::render::per_kind::RayCounts {
                camera: 4,
                shadow: 6,
                reflection: 2,
            },
            kind_time: Some(crate::render::per_kind::PerKind {
                camera: std::time::Duration::from_millis(500),
                shadow: std::time::Duration::from_millis(1500),
                reflection: std::time::Duration::ZERO,
            }),
            ..RenderStats::default()
        };
        let record = RenderRecord {
            format: FORMAT,
            raywave: "0",
            machine: Machine {
                hostname: String::new(),
                ..Machine::current()
            },
            simd: "scalar",
            threads: 1,
            engine: Engine::Reference,
            batch_size: 8,
            shadow_path: None,
            scene: SceneFigures {
                source: "s".into(),
                triangles: 1,
                spheres: 0,
                lights: 0,
                bvh: None,
                bvh_build_seconds: None,
            },
            settings: RenderSettings::default(),
            defaults: DefaultsUsed {
                from: "raywave",
                settings: vec!["size"],
            },
            seconds: 2.0,
            rays: KindFigures::new(&stats, 2.0),
            kinds_timed_by: KindTiming::InstrumentedPass,
            instrumented_seconds: Some(2.5),
            stages: None,
            traversal: None,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.json");
        record.write(&path, None).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let top: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("  \"") && !l.starts_with("   "))
            .map(|l| l.trim().split('"').nth(1).unwrap())
            .collect();
        let mut sorted = top.clone();
        sorted.sort_unstable();
        assert_eq!(top, sorted);
        assert!(!text.contains("hostname"));
        assert!(text.contains("\"for\": [\n      \"size\"\n    ]"), "{text}");
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(json["rays"]["total"]["rays"], 12);
        assert_eq!(json["rays"]["total"]["rays_per_second"], 6.0);
        // Each kind over its own thread-time, not over the frame's 2 s.
        assert_eq!(json["rays"]["camera"]["rays_per_thread_second"], 8.0);
        assert_eq!(json["rays"]["shadow"]["rays_per_thread_second"], 4.0);
        assert_eq!(json["rays"]["shadow"]["thread_seconds"], 1.5);
        // Rays, but no time measured for them: no rate.
        assert!(json["rays"]["reflection"]["rays_per_thread_second"].is_null());
        assert_eq!(json["format"], FORMAT);
        assert_eq!(json["engine"], "reference");
        assert!(json["stages"].is_null() && json["scene"]["bvh"].is_null());
    }
}
