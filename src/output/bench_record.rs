//! A bench record: what was measured (medians and every run) and under which conditions
//! (machine, build, scene, settings), as it is saved to `.raywave-bench/NAME.json`.

use crate::output::machine::Machine;
use crate::render::per_kind::PerKind;
use crate::render::settings::RenderSettings;
use crate::render::wavefront::stats::{RenderStats, StageFigure};
use crate::stats::median;
use anyhow::{Context, Result, bail};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The layout version of bench records and `--stats-json` files (both carry it as `format`),
/// bumped when either layout changes; records of another version are refused with a message.
/// docs/SCHEMA.md has the rule and the history of each version.
pub const FORMAT: u32 = 3;

/// One `raywave bench` invocation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BenchRecord {
    /// Layout version ([`FORMAT`]).
    #[schemars(extend("const" = FORMAT))]
    pub format: u32,
    /// raywave's version.
    pub raywave: String,
    /// `git rev-parse HEAD` of the source tree at build time, or "unknown" (= `build.commit`).
    pub git_commit: String,
    /// Whether tracked files had uncommitted changes at build time (None when unknown).
    pub git_dirty: Option<bool>,
    /// The build: commit, profile, target, target features, RUSTFLAGS (`build.rs`).
    pub build: crate::output::build_info::BuildInfo,
    /// When the bench ran, UTC, RFC 3339.
    pub timestamp: String,
    /// Where it ran.
    pub machine: Machine,
    /// The SIMD path the wavefront engine ran on (`raywave::simd_path_for` its `--lanes`).
    pub simd: String,
    /// What was measured: two records compare only when these are equal.
    pub setup: Setup,
    /// Timed runs per engine.
    pub runs: u32,
    /// Untimed runs per engine before the timed ones.
    pub warmup: u32,
    /// One entry per engine measured: reference, then wavefront.
    pub engines: Vec<EngineRecord>,
}

/// Scene, settings and threads: the work and the resources it was given.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Setup {
    /// The scene.
    pub scene: SceneId,
    /// The render settings.
    pub settings: RenderSettings,
    /// Worker threads.
    pub threads: usize,
    /// Wavefront camera samples per tile.
    pub batch_size: usize,
}

/// Which scene: its name and a hash of its text, so a renamed copy still compares and an
/// edited file does not.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SceneId {
    /// File path, or `<built-in ...>` (informative only; not compared).
    pub source: String,
    /// FNV-1a of the scene text, hex.
    pub text_hash: String,
    /// Triangles after parsing.
    pub triangles: usize,
    /// Spheres.
    pub spheres: usize,
    /// Lights.
    pub lights: usize,
}

/// One engine's figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct EngineRecord {
    /// "reference" or "wavefront".
    pub engine: String,
    /// Median over the runs of every figure, each taken separately.
    pub median: Measurement,
    /// Every timed run, in order.
    pub runs: Vec<Measurement>,
    /// The headline figures over the runs (total, then each stage that handled rays): min,
    /// median, its 95% interval, max, outliers. Verdicts are decided on these.
    pub summary: Vec<FigureSummary>,
}

/// One headline figure over the timed runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct FigureSummary {
    /// "total" (rays per wall-clock second) or "stage NAME" (rays per thread-second).
    pub figure: String,
    /// "rays/s" or "rays/thread-s".
    pub unit: String,
    /// How many runs it summarises.
    pub runs: usize,
    /// The slowest run.
    pub min: f64,
    /// The median run.
    pub median: f64,
    /// Lower end of the median's 95% interval (`stats::median_with_interval`); null
    /// with fewer than 6 runs.
    pub low: Option<f64>,
    /// Upper end of that interval; null with fewer than 6 runs.
    pub high: Option<f64>,
    /// The fastest run.
    pub max: f64,
    /// Runs (0-based) whose modified Z-score exceeds `stats::OUTLIER_Z`.
    pub outliers: Vec<usize>,
}

impl FigureSummary {
    /// The summary of `values`, one per run.
    pub fn of(figure: &str, unit: &str, values: &[f64]) -> FigureSummary {
        let (median, low, high) = crate::stats::median_with_interval(values);
        let finite = |x: f64| x.is_finite().then_some(x);
        FigureSummary {
            figure: figure.to_string(),
            unit: unit.to_string(),
            runs: values.len(),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            median,
            low: finite(low),
            high: finite(high),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            outliers: crate::stats::outliers(values),
        }
    }

    /// (high − low) / median, in percent; None without an interval.
    pub fn relative_width_pct(&self) -> Option<f64> {
        match (self.low, self.high) {
            (Some(l), Some(h)) if self.median > 0.0 => Some((h - l) / self.median * 100.0),
            _ => None,
        }
    }

    /// The interval as `[low, high]` scaled by `scale`, or `[no interval: n < 6]`.
    pub fn interval_text(&self, scale: f64, decimals: usize) -> String {
        match (self.low, self.high) {
            (Some(l), Some(h)) => format!("[{:.d$}, {:.d$}]", l * scale, h * scale, d = decimals),
            _ => format!(
                "[none: {} run(s) < {}]",
                self.runs,
                crate::stats::MIN_FOR_INTERVAL
            ),
        }
    }
}

/// The headline figures of an engine's runs: the total rate, then each stage that handled
/// rays in the first run (by name), each over every run.
pub fn summarise(runs: &[Measurement]) -> Vec<FigureSummary> {
    let mut out = Vec::new();
    let Some(first) = runs.first() else {
        return out;
    };
    let totals: Vec<f64> = runs.iter().map(|r| r.rays.total.rays_per_second).collect();
    out.push(FigureSummary::of("total", "rays/s", &totals));
    for st in first.stages.iter().filter(|st| st.rays > 0) {
        let values: Vec<f64> = runs
            .iter()
            .filter_map(|r| r.stages.iter().find(|s| s.stage == st.stage))
            .map(|s| s.rays_per_thread_second)
            .collect();
        out.push(FigureSummary::of(
            &format!("stage {}", st.stage),
            "rays/thread-s",
            &values,
        ));
    }
    out
}

/// What one render measured (or the medians of several).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Measurement {
    /// Rays by kind with each kind's thread-seconds and rate, and the total over the
    /// wall-clock seconds of the render: the `rays` of `--stats-json`.
    pub rays: KindFigures,
    /// Per stage (wavefront only; empty for the reference, which has no stages).
    pub stages: Vec<StageFigure>,
}

/// One kind's rays, the thread-time of its work, and its rate over that time. The time is
/// `RenderStats::kind_time` (for the wavefront engine from its stage timers), so the rate
/// says how fast that work went whatever else the frame did. Both are null when the time was
/// not measured (the reference in `raywave bench`, which times it without timers), the rate
/// also without rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct KindFigure {
    /// Rays cast.
    pub rays: u64,
    /// Thread-seconds of this kind's work, summed over worker threads (null: not measured).
    pub thread_seconds: Option<f64>,
    /// rays / thread_seconds (null: not measured, or no rays).
    pub rays_per_thread_second: Option<f64>,
}

/// All rays over the frame's wall-clock time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TotalFigure {
    /// Rays cast, all kinds.
    pub rays: u64,
    /// Wall-clock seconds of the render.
    pub seconds: f64,
    /// rays / seconds: the headline figure.
    pub rays_per_second: f64,
}

/// [`KindFigure`] for each kind, and the total: how many rays of each kind a render cast and
/// how fast, in `--stats-json`, in bench records and on the viewer's page.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct KindFigures {
    /// Each kind: camera rays (making them and their closest hits), shadow rays (spawning
    /// them, the occlusion tests and the Shade sums), mirror rays (making them and their
    /// closest hits).
    #[serde(flatten)]
    pub kinds: PerKind<KindFigure>,
    /// All rays per wall-clock second.
    pub total: TotalFigure,
}

impl KindFigures {
    /// The counts of `stats`, each kind over its thread-time when `stats` measured it, the
    /// total over wall-clock `seconds`.
    pub fn new(stats: &RenderStats, seconds: f64) -> KindFigures {
        KindFigures {
            kinds: PerKind::from_fn(|kind| {
                let rays = stats.counts[kind];
                let seconds = stats.kind_time.map(|t| t[kind].as_secs_f64());
                KindFigure {
                    rays,
                    thread_seconds: seconds,
                    rays_per_thread_second: seconds
                        .filter(|&s| rays > 0 && s > 0.0)
                        .map(|s| rays as f64 / s),
                }
            }),
            total: TotalFigure {
                rays: stats.counts.total(),
                seconds,
                rays_per_second: stats.counts.total() as f64 / seconds.max(1e-9),
            },
        }
    }

    /// Each figure's median over `runs`, taken separately (a kind's time and rate only when
    /// every run measured it; ray counts from the first run: they do not vary).
    pub fn median_of(runs: &[KindFigures]) -> KindFigures {
        let Some(first) = runs.first() else {
            return KindFigures::default();
        };
        let col = |f: &dyn Fn(&KindFigures) -> Option<f64>| {
            let v: Option<Vec<f64>> = runs.iter().map(f).collect();
            v.map(|v| median(&v))
        };
        KindFigures {
            kinds: PerKind::from_fn(|kind| KindFigure {
                rays: first.kinds[kind].rays,
                thread_seconds: col(&|r| r.kinds[kind].thread_seconds),
                rays_per_thread_second: col(&|r| r.kinds[kind].rays_per_thread_second),
            }),
            total: TotalFigure {
                rays: first.total.rays,
                seconds: col(&|r| Some(r.total.seconds)).unwrap_or_default(),
                rays_per_second: col(&|r| Some(r.total.rays_per_second)).unwrap_or_default(),
            },
        }
    }
}

impl Measurement {
    /// Each figure's median over `runs` (ray counts from the first run: they do not vary).
    pub fn median_of(runs: &[Measurement]) -> Measurement {
        let Some(first) = runs.first() else {
            return Measurement::default();
        };
        let stages = (first.stages.iter().enumerate())
            .map(|(i, s)| {
                let of_runs: Vec<&StageFigure> =
                    runs.iter().filter_map(|r| r.stages.get(i)).collect();
                let col = |f: fn(&StageFigure) -> f64| {
                    median(&of_runs.iter().map(|s| f(s)).collect::<Vec<_>>())
                };
                StageFigure {
                    stage: s.stage.clone(),
                    rays: s.rays,
                    thread_seconds: col(|s| s.thread_seconds),
                    rays_per_thread_second: col(|s| s.rays_per_thread_second),
                }
            })
            .collect();
        Measurement {
            rays: KindFigures::median_of(&runs.iter().map(|r| r.rays).collect::<Vec<_>>()),
            stages,
        }
    }
}

/// Where `--save NAME` / `--compare NAME` keep a record. A name is plain: ASCII letters,
/// digits, `-`, `_`, `.` and `+`, not starting with `.` or `-`, at most 100 characters; any
/// other name (a path, `..`, a control character) is a usage error (exit 2).
pub fn record_path(dir: &Path, name: &str) -> Result<std::path::PathBuf> {
    let plain = !name.is_empty()
        && name.len() <= 100
        && !name.starts_with(['.', '-'])
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.' | '+'));
    if !plain {
        bail!(crate::render::error::UsageError(format!(
            "bench record name `{}` is not usable: expected a plain name like `before` \
             (letters, digits, - _ . +; no path separators, not starting with '.' or '-'); \
             use --dir to choose the directory",
            name.escape_debug()
        )));
    }
    Ok(dir.join(format!("{name}.json")))
}

/// The largest record file `load` reads (a record of 1000 runs is about 1 MiB).
const MAX_RECORD_BYTES: u64 = 64 << 20;

/// Reads a saved record; a missing file says how to make one.
pub fn load(path: &Path, name: &str) -> Result<BenchRecord> {
    let what = "a bench record (a regular JSON file)";
    let bytes = super::read_bounded(path, what, MAX_RECORD_BYTES).map_err(|e| {
        let kind = e.downcast_ref::<std::io::Error>().map(std::io::Error::kind);
        match kind {
            Some(std::io::ErrorKind::NotFound) => anyhow::anyhow!(
                "no bench record {}: create it first with `raywave bench --save {name}` \
                 (same scene and flags; --dir if it lives elsewhere)",
                path.display()
            ),
            _ => e,
        }
    })?;
    let value: serde_json::Value = serde_json::from_slice(&bytes)
        .with_context(|| format!("{}: not a JSON bench record", path.display()))?;
    let format = value.get("format").and_then(|f| f.as_u64());
    if format != Some(FORMAT.into()) {
        let by = match format {
            Some(f) if f < FORMAT.into() => ": written by an earlier raywave",
            Some(_) => ": written by a later raywave",
            None => "",
        };
        bail!(
            "{}: bench record format {}, expected {FORMAT}{by}; its figures are laid out or \
             mean other things (docs/SCHEMA.md): re-record it with this build, \
             `raywave bench --save {name}`",
            path.display(),
            format.map_or("missing".to_string(), |f| f.to_string())
        );
    }
    serde_json::from_value(value)
        .with_context(|| format!("{}: not a valid bench record", path.display()))
}

/// Writes `record` to `path` atomically, creating its directory.
pub fn save(path: &Path, record: &BenchRecord) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create directory {}", dir.display()))?;
    }
    crate::output::image_file::write_json(path, record)
}

/// Seconds since the Unix epoch as RFC 3339 UTC (`2026-11-22T20:13:01Z`), by `humantime`.
#[cfg(test)]
fn rfc3339_utc(unix_seconds: u64) -> String {
    let t = std::time::UNIX_EPOCH + std::time::Duration::from_secs(unix_seconds);
    humantime::format_rfc3339_seconds(t).to_string()
}

/// Now, as [`rfc3339_utc`].
pub fn now_utc() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps() {
        assert_eq!(rfc3339_utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(rfc3339_utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(rfc3339_utc(1_795_378_381), "2026-11-22T20:13:01Z");
    }

    #[test]
    fn record_names() {
        let dir = Path::new("d");
        assert_eq!(
            record_path(dir, "before").unwrap(),
            Path::new("d/before.json")
        );
        for bad in ["", "../x", "a/b", ".hidden", "-x", "a\\b", "a\nb", "é"] {
            let e = record_path(dir, bad).unwrap_err();
            assert!(
                e.downcast_ref::<crate::render::error::UsageError>()
                    .is_some()
            );
            assert!(e.to_string().contains("not usable"), "{e}");
        }
    }

    #[test]
    fn loading_names_the_file_and_what_was_expected() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.json");
        let e = format!("{:#}", load(&path, "a").unwrap_err());
        assert!(
            e.contains("no bench record") && e.contains("--save a"),
            "{e}"
        );
        std::fs::write(&path, "not json").unwrap();
        let e = format!("{:#}", load(&path, "a").unwrap_err());
        assert!(e.contains("a.json: not a JSON bench record"), "{e}");
        std::fs::write(&path, r#"{"format": 99}"#).unwrap();
        let e = format!("{:#}", load(&path, "a").unwrap_err());
        assert!(
            e.contains("format 99, expected 3: written by a later"),
            "{e}"
        );
        std::fs::write(&path, r#"{"format": 2}"#).unwrap();
        let e = format!("{:#}", load(&path, "a").unwrap_err());
        assert!(
            e.contains("format 2, expected 3: written by an earlier raywave"),
            "{e}"
        );
        assert!(
            e.contains("re-record it with this build, `raywave bench --save a`"),
            "{e}"
        );
        std::fs::write(&path, r#"{"format": 3}"#).unwrap();
        let e = format!("{:#}", load(&path, "a").unwrap_err());
        assert!(e.contains("a.json: not a valid bench record"), "{e}");
    }
}
