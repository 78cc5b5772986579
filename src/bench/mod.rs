//! `raywave bench`: times the engines on one scene (or on each point of a sweep), summarises
//! every headline figure (min, median, 95% interval, max), warns when the figures are noisy, and
//! keeps and compares records for regression checks. It returns what it found; the command
//! line prints it (`Outcome::text`).
//!
//! ```text
//! --compare's record: load; adopt its settings, threads and engines unless a flag was given;
//!   refuse if its setup then differs, or if it lacks an engine, a stage or an interval
//! for each point of the sweep (sizes × shadow samples × threads):
//!     warm-up: --warmup untimed runs per engine
//!     timed:   --runs rounds, each running every engine once, the first engine alternating
//!     summary: per headline figure min, median, 95% interval, max, outlier runs; warnings
//! compare -> verdict (median change past the threshold AND intervals apart); write --save
//!   (never over the record it regressed against), --json and the exports; return the outcome
//! ```
//!
//! With `--shard I/N` only this shard's points of the sweep are timed (split by estimated
//! cost, shard.rs) and written to one part file; `raywave bench merge` (merge.rs) puts the
//! parts back together.

pub mod ab;
mod ab_report;
pub(crate) mod adopt;
pub mod compare;
pub mod export;
pub mod list;
pub mod merge;
pub(crate) mod report;
pub mod running;
pub mod shard;
pub mod verdict;

use running::{measure, sweep};

use crate::output::bench_record::{self as record, BenchRecord, SceneId, Setup};
use crate::output::machine::Machine;
use crate::render::engine::{Engine, thread_pool};
use crate::render::error::UsageError;
use crate::render::progress::Progress;
use crate::render::scene::{SceneFile, load_scene};
use crate::render::settings::options::ImageOptions;
use crate::render::wavefront::DEFAULT_BATCH_SIZE;
use anyhow::{Result, bail};
use std::path::PathBuf;

pub use report::report;

/// Exit code of `raywave bench --compare` when a headline figure regressed, and of `--against`
/// when an engine's verdict is a regression.
pub const EXIT_REGRESSION: u8 = 3;

/// Exit code of `raywave bench --against OTHER --until-decided` when no engine regressed but
/// one was still undecided at the budget (`--max-rounds` or `--max-time`).
pub const EXIT_UNDECIDED: u8 = 4;

/// Default `--threshold`, in percent: see docs/BENCHMARKING.md for the noise it is chosen from.
pub const DEFAULT_THRESHOLD_PCT: f64 = 40.0;

/// Default `--runs`: the fewest that give the median a 95% interval narrower than the
/// extremes (the 2nd and 9th of 10 runs), at about 1 s per round on the default bench.
pub const DEFAULT_RUNS: u32 = 10;

/// What `raywave bench` is asked to do (its flags, as plain values).
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Scene file; `None` for the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// Size, bounces, shadows and sampling, defaulted as for `raywave render` (a sweep's
    /// values replace size and shadow samples point by point).
    pub image: ImageOptions,
    /// Swept sizes, shadow samples and thread counts (empty: not given; threads: all cores).
    pub sweep: sweep::Sweep,
    /// The engines to time, in record order (reference, then wavefront).
    pub engines: Vec<Engine>,
    /// The wavefront engine's lane width (`--lanes`; speed only).
    pub lanes: crate::render::wavefront::lanes::LaneWidth,
    /// Timed runs per engine.
    pub runs: u32,
    /// Untimed runs per engine before the timed ones.
    pub warmup: u32,
    /// Save the record as DIR/NAME.json (DIR/NAME+POINT.json per point of a sweep).
    pub save: Option<String>,
    /// Compare with the record DIR/NAME.json.
    pub compare: Option<String>,
    /// Directory of saved records.
    pub dir: PathBuf,
    /// Regression threshold in percent.
    pub threshold: f64,
    /// Also write the record as JSON to this file (`-` for stdout); one point only.
    pub json: Option<PathBuf>,
    /// The `--export-*` files.
    pub exports: export::Exports,
    /// Time only this shard's points and write them to a part file in this directory.
    pub shard: Option<(crate::shard::Shard, PathBuf)>,
    /// The flags given on the command line (clap ids: `size`, `threads`, `engine`, ...):
    /// with `--compare`, every other setting comes from the record.
    pub explicit: Vec<String>,
    /// The command's inputs and outputs, checked before the call; held again against the
    /// scene's textures once it is read.
    pub plan: crate::output::OutputPlan,
}

/// What `run` measured and did: the records, where they were saved, and with `--compare` the
/// comparison with the record it read.
pub struct Outcome {
    /// One record per point.
    pub records: Vec<BenchRecord>,
    /// Each point's label ("" for a run of one point).
    pub labels: Vec<String>,
    /// The records saved, in order.
    pub saved: Vec<PathBuf>,
    /// The comparison and the record compared with, if asked for.
    pub comparison: Option<(compare::Comparison, BenchRecord)>,
    /// With `--shard`: the part file written, and the shard and point count of the sweep.
    pub part: Option<(PathBuf, crate::shard::Shard, usize)>,
}

/// One point, ready to time: everything refusable was checked.
struct Plan {
    point: sweep::Point,
    pool: rayon::ThreadPool,
    setup: Setup,
    engines: Vec<Engine>,
    save: Option<PathBuf>,
}

/// Runs the bench as the flags say and writes its files; errors name the file or flag.
pub fn run(args: &BenchOptions, progress: &Progress) -> Result<Outcome> {
    // Everything that can fail cheaply happens before the timed part.
    let points = args.sweep.points();
    if points.len() > 1 && (args.compare.is_some() || args.json.is_some()) {
        bail!(UsageError(format!(
            "{} takes one point, but the sweep has {}: compare or write points one at a time \
             (`raywave bench compare A B` compares saved points; --export-json writes them all)",
            args.compare.as_ref().map_or("--json", |_| "--compare"),
            points.len()
        )));
    }
    if let Some(p) = args.json.as_ref().filter(|p| p.as_os_str() != "-") {
        crate::output::image_file::check_output_dir(p)?;
    }
    let SceneFile { scene, bytes } =
        load_scene(args.scene.as_deref(), &args.image.parse_options())?;
    for w in &scene.warnings {
        (progress.notice)(&w.to_string());
    }
    args.plan.check_scene_files("SCENE", &scene)?;
    let baseline = match &args.compare {
        Some(name) => {
            let path = record::record_path(&args.dir, name)?;
            Some((record::load(&path, name)?, path))
        }
        None => None,
    };
    let given = |flag: &str| args.explicit.iter().any(|e| e == flag);
    let mut plans = Vec::new();
    for point in points {
        let mut image = args.image.clone();
        image.size = point.size.or(image.size);
        image.shadow_samples = point.shadow_samples.or(image.shadow_samples);
        let mut settings = image
            .resolve(scene.background.map(|c| c.to_array()))
            .settings;
        let mut threads = point.threads;
        let mut engines = args.engines.clone();
        if let Some((before, _)) = &baseline {
            settings = adopt::adopt_settings(&settings, &before.setup.settings, &args.explicit);
            if !given("threads") {
                threads = u32::try_from(before.setup.threads).ok();
            }
            if !given("engine") {
                engines = [Engine::Reference, Engine::Wavefront]
                    .into_iter()
                    .filter(|e| before.engines.iter().any(|b| b.engine == e.name()))
                    .collect();
                if engines.is_empty() {
                    engines = args.engines.clone();
                }
            }
        }
        settings
            .check_sampler()
            .map_err(|e| UsageError(e.to_string()))?;
        let pool = thread_pool(threads)?;
        let setup = Setup {
            scene: SceneId {
                source: scene.source.clone(),
                text_hash: crate::render::digest::hex(&bytes),
                triangles: scene.triangles.len(),
                spheres: scene.spheres.len(),
                lights: scene.lights.len(),
            },
            settings,
            threads: pool.current_num_threads(),
            batch_size: DEFAULT_BATCH_SIZE,
        };
        if let Some((before, path)) = &baseline {
            let differences =
                compare::setup_differences(&before.setup, &setup, "in the record", "now");
            if !differences.is_empty() {
                bail!(
                    "cannot compare with {}: it was measured with a different setup, so the \
                     figures would not describe the same work:\n  {}\nleave out the flags \
                     that differ (the record's values are used), or save a new record with \
                     --save",
                    path.display(),
                    differences.join("\n  ")
                );
            }
            let names: Vec<&str> = engines.iter().map(|e| e.name()).collect();
            let problems = compare::record_problems(before, &names);
            if !problems.is_empty() {
                bail!(incomparable(path, &problems));
            }
            if args.runs < crate::stats::MIN_FOR_INTERVAL as u32 {
                bail!(UsageError(format!(
                    "--compare needs --runs {} or more: with {} run(s) the median has no 95% \
                     interval, and the verdict needs one",
                    crate::stats::MIN_FOR_INTERVAL,
                    args.runs
                )));
            }
        }
        let save = args
            .save
            .as_ref()
            .map(|name| record::record_path(&args.dir, &sweep::record_name(name, &point.label)))
            .transpose()?;
        plans.push(Plan {
            point,
            pool,
            setup,
            engines,
            save,
        });
    }

    // A shard times only its share of the sweep, split by every point's estimated cost.
    let build = crate::output::build_info::current();
    let simd = crate::simd_path_for(args.lanes).to_string();
    let sweep_points = plans.len();
    let shard_run = args.shard.as_ref().map(|(which, dir)| {
        let sweep = shard::SweepPoints {
            engines: args.engines.iter().map(|e| e.name().to_string()).collect(),
            runs: args.runs,
            warmup: args.warmup,
            points: plans
                .iter()
                .map(|p| shard::SweepPoint {
                    label: p.point.label.clone(),
                    setup: p.setup.clone(),
                    cost: shard::cost(&p.setup, args.runs, args.warmup),
                })
                .collect(),
        };
        let identity = crate::shard::Identity::current(&simd, sweep);
        let mine = which.items(&crate::shard::Work::costs(&identity.work));
        plans = std::mem::take(&mut plans)
            .into_iter()
            .enumerate()
            .filter(|(i, _)| mine.contains(i))
            .map(|(_, p)| p)
            .collect();
        (*which, dir, identity, mine)
    });
    let host = crate::shard::Host::start(rayon::current_num_threads());

    if let Some(w) = report::load_warning() {
        (progress.notice)(&format!("warning: {w}"));
    }
    let total: u64 = plans
        .iter()
        .map(|p| u64::from(args.warmup + args.runs) * p.engines.len() as u64)
        .sum();
    let runs = progress.steps(total, "runs");
    let mut records = Vec::new();
    for plan in &plans {
        let engines = measure::measure(plan, &scene, args, &runs, progress.notice);
        let record = BenchRecord {
            format: record::FORMAT,
            raywave: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: build.commit.clone(),
            git_dirty: build.dirty,
            build: build.clone(),
            timestamp: record::now_utc(),
            machine: Machine::current(),
            simd: simd.clone(),
            setup: plan.setup.clone(),
            runs: args.runs,
            warmup: args.warmup,
            engines,
        };
        for w in report::warnings(&record, &plan.point.label) {
            (progress.notice)(&format!("warning: {w}"));
        }
        records.push(record);
    }

    // The verdict is reached before anything is written, so that a run that cannot be
    // compared, or that regressed, does not replace the record it was compared with.
    let comparison = match (&baseline, records.first()) {
        (Some((before, path)), Some(after)) => Some(
            compare::compare(before, after, args.threshold).map_err(|r| match r {
                compare::Refusal::Setup(d) => anyhow::anyhow!(
                    "cannot compare with {}: setups differ: {}",
                    path.display(),
                    d.join("; ")
                ),
                compare::Refusal::Incomparable(p) => anyhow::anyhow!(incomparable(path, &p)),
            })?,
        ),
        _ => None,
    };
    let regressed = comparison.as_ref().is_some_and(|c| c.regressed());
    let mut saved = Vec::new();
    for (plan, record) in plans.iter().zip(&records) {
        let Some(path) = &plan.save else { continue };
        if regressed && args.save == args.compare {
            (progress.notice)(&format!(
                "warning: not saved: this run regressed against {}, which is kept as it was; \
                 save under another name to keep this run",
                path.display()
            ));
        } else {
            record::save(path, record)?;
            saved.push(path.clone());
        }
    }
    if let (Some(p), Some(record)) = (&args.json, records.first()) {
        export::write(p, &format!("{}\n", serde_json::to_string_pretty(record)?))?;
    }
    let labels: Vec<String> = plans.iter().map(|p| p.point.label.clone()).collect();
    args.exports.write(&records, &labels, false)?;
    let part = shard_run
        .map(|(which, dir, identity, items)| -> Result<_> {
            let mut part = crate::shard::Part {
                identity,
                shard: which,
                items,
                host,
                extra: (),
                results: records.clone(),
            };
            part.host.finish();
            Ok((crate::shard::write_part(dir, &part)?, which, sweep_points))
        })
        .transpose()?;
    Ok(Outcome {
        records,
        labels,
        saved,
        comparison: comparison.zip(baseline.map(|(before, _)| before)),
        part,
    })
}

impl Outcome {
    /// The process exit code: [`EXIT_REGRESSION`] when the comparison regressed, else 0.
    pub fn exit_code(&self) -> u8 {
        match &self.comparison {
            Some((c, _)) if c.regressed() => EXIT_REGRESSION,
            _ => 0,
        }
    }

    /// The text a run prints: each point's report (unless `quiet`), the records saved, then
    /// the comparison with the record named `compared_with`.
    pub fn text(&self, quiet: bool, compared_with: Option<&str>) -> String {
        let mut out = String::new();
        if !quiet {
            for (label, record) in self.labels.iter().zip(&self.records) {
                if !label.is_empty() {
                    out.push_str(&format!("\npoint   {label}\n"));
                }
                out.push_str(&report(record));
            }
            for path in &self.saved {
                out.push_str(&format!("saved   {}\n", path.display()));
            }
        }
        if let (false, Some((path, which, of))) = (quiet, &self.part) {
            out.push_str(&format!(
                "shard   {which}: {} of the sweep's {of} point(s), split by estimated cost\n\
                 wrote   {}\n",
                points_text(&self.labels, "none"),
                path.display()
            ));
        }
        if let Some((c, before)) = &self.comparison {
            if !quiet {
                out.push('\n');
            }
            out.push_str(&format!(
                "compared with {} ({}, commit {}):\n{}",
                compared_with.unwrap_or_default(),
                before.timestamp,
                before.build.short_commit(),
                c.table("before", "after")
            ));
        }
        out
    }
}

/// Points by their labels, counted when a sweep of one point has none, `none` when there are
/// no points.
fn points_text<S: std::borrow::Borrow<str>>(labels: &[S], none: &str) -> String {
    if labels.is_empty() {
        none.to_string()
    } else if labels.iter().all(|l| l.borrow().is_empty()) {
        format!("{} point(s)", labels.len())
    } else {
        labels.join(", ")
    }
}

/// The error for a record that holds nothing this run can be compared with.
fn incomparable(path: &std::path::Path, problems: &[String]) -> String {
    format!(
        "cannot compare with {}: expected figures for every engine and stage this run \
         measures, each a positive rate with a 95% interval, but:\n  {}\nsave a new record \
         with --save",
        path.display(),
        problems.join("\n  ")
    )
}
