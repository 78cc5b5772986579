//! `raywave bench`: times both engines on one scene over several runs, prints rays/s per kind
//! and per stage (medians), and keeps and compares records for regression checks.
//!
//! ```text
//! load --compare's record; refuse if its setup (scene, settings, threads) differs or if it
//!   lacks an engine or stage, or a headline figure is not a positive rate (no verdict that
//!   cannot fail)
//! warm-up: one untimed render per engine
//! for run in 1..=runs: reference, then wavefront (interleaved, so both see the same load)
//! medians per figure; compare -> verdict; print; write --save (never over the record it
//!   regressed against) / --json; table, verdict (exit 3)
//! ```

pub mod ab;
pub mod compare;
pub mod record;

use crate::engine::{Engine, Prepared, thread_pool};
use crate::film::Film;
use crate::options::ImageOptions;
use crate::scene::{Scene, SceneFile, load_scene};
use crate::settings::{RenderSettings, ShadowMode};
use crate::wavefront::DEFAULT_BATCH_SIZE;
use anyhow::{Context, Result, bail};
use record::{
    BenchRecord, EngineRecord, KindRates, Machine, Measurement, SceneId, Setup, StageFigure,
};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// Exit code of `raywave bench --compare` when a headline figure regressed past the threshold.
pub const EXIT_REGRESSION: u8 = 3;

/// Default `--threshold`, in percent: see docs/BENCHMARKING.md for the noise it is chosen from.
pub const DEFAULT_THRESHOLD_PCT: f64 = 40.0;

/// What `raywave bench` is asked to do (its flags, as plain values).
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Scene file; `None` for the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// Size, bounces, shadows and sampling, defaulted as for `raywave render`.
    pub image: ImageOptions,
    /// Worker threads (`None`: all cores).
    pub threads: Option<u32>,
    /// Timed runs per engine (medians are reported).
    pub runs: u32,
    /// Save the record as DIR/NAME.json.
    pub save: Option<String>,
    /// Compare with the record DIR/NAME.json.
    pub compare: Option<String>,
    /// Directory of saved records.
    pub dir: PathBuf,
    /// Regression threshold in percent.
    pub threshold: f64,
    /// Also write the record as JSON to this file (`-` for stdout).
    pub json: Option<PathBuf>,
    /// Print only the comparison (or nothing but errors without `compare`).
    pub quiet: bool,
}

/// What `run` found: `Some(comparison)` with `--compare`.
pub struct Outcome {
    /// The record of this run.
    pub record: BenchRecord,
    /// The comparison, if asked for.
    pub comparison: Option<compare::Comparison>,
}

impl Outcome {
    /// The process exit code: [`EXIT_REGRESSION`] when the comparison regressed, else 0.
    pub fn exit_code(&self) -> u8 {
        match &self.comparison {
            Some(c) if c.regressed() => EXIT_REGRESSION,
            _ => 0,
        }
    }
}

/// Runs the bench as the flags say, printing the tables; errors name the file or flag.
pub fn run(args: &BenchOptions) -> Result<Outcome> {
    // Everything that can fail cheaply happens before the timed part.
    let save_path = args
        .save
        .as_deref()
        .map(|n| record::record_path(&args.dir, n))
        .transpose()?;
    if let Some(p) = args.json.as_ref().filter(|p| p.as_os_str() != "-") {
        crate::film::check_output_dir(p)?;
    }
    let SceneFile { scene, bytes } =
        load_scene(args.scene.as_deref(), &args.image.parse_options())?;
    for w in &scene.warnings {
        eprintln!("{w}");
    }
    let settings = args
        .image
        .resolve(scene.background.map(|c| c.to_array()))
        .settings;
    let pool = thread_pool(args.threads)?;
    let setup = Setup {
        scene: SceneId {
            source: scene.source.clone(),
            text_hash: record::text_hash(&bytes),
            triangles: scene.triangles.len(),
            spheres: scene.spheres.len(),
            lights: scene.lights.len(),
        },
        settings: settings.clone(),
        threads: pool.current_num_threads(),
        batch_size: DEFAULT_BATCH_SIZE,
    };
    let baseline = match &args.compare {
        Some(name) => {
            let path = record::record_path(&args.dir, name)?;
            let before = record::load(&path, name)?;
            let differences = compare::setup_differences(&before.setup, &setup);
            if !differences.is_empty() {
                bail!(
                    "cannot compare with {}: it was measured with a different setup, so the \
                     figures would not describe the same work:\n  {}\nrun with the record's \
                     flags, or save a new record with --save",
                    path.display(),
                    differences.join("\n  ")
                );
            }
            let problems = compare::record_problems(&before, &ENGINES.map(|e| e.name()));
            if !problems.is_empty() {
                bail!(incomparable(&path, &problems));
            }
            Some((path, before))
        }
        None => None,
    };

    let engines = pool.install(|| measure(&scene, &settings, args.runs));
    let (git_commit, git_dirty) = record::git_commit();
    let record = BenchRecord {
        format: record::FORMAT,
        raywave: env!("CARGO_PKG_VERSION").to_string(),
        git_commit,
        git_dirty,
        timestamp: record::now_utc(),
        machine: Machine {
            hostname: crate::machine::hostname(),
            cpu: crate::machine::cpu_model(),
            logical_cpus: crate::machine::logical_cpus(),
            os: std::env::consts::OS.to_string(),
            arch: std::env::consts::ARCH.to_string(),
        },
        simd: crate::simd_path().to_string(),
        setup,
        runs: args.runs,
        engines,
    };
    // The verdict is reached before anything is written, so that a run that cannot be
    // compared, or that regressed, does not replace the record it was compared with.
    let comparison = match &baseline {
        Some((path, before)) => Some(compare::compare(before, &record, args.threshold).map_err(
            |r| match r {
                compare::Refusal::Setup(d) => anyhow::anyhow!(
                    "cannot compare with {}: setups differ: {}",
                    path.display(),
                    d.join("; ")
                ),
                compare::Refusal::Incomparable(p) => anyhow::anyhow!(incomparable(path, &p)),
            },
        )?),
        None => None,
    };
    if !args.quiet {
        emit(&report(&record))?;
    }
    let regressed = comparison.as_ref().is_some_and(|c| c.regressed());
    if let Some(path) = &save_path {
        if regressed && args.save == args.compare {
            eprintln!(
                "warning: not saved: this run regressed against {}, which is kept as it was; \
                 save under another name to keep this run",
                path.display()
            );
        } else {
            record::save(path, &record)?;
            if !args.quiet {
                emit(&format!("saved   {}\n", path.display()))?;
            }
        }
    }
    match &args.json {
        Some(p) if p.as_os_str() == "-" => {
            emit(&format!("{}\n", serde_json::to_string_pretty(&record)?))?;
        }
        Some(p) => crate::film::write_atomically(p, |w| {
            serde_json::to_writer_pretty(&mut *w, &record)?;
            Ok(writeln!(w)?)
        })?,
        None => {}
    }
    if let (Some(c), Some((_, before))) = (&comparison, &baseline) {
        if !args.quiet {
            emit("\n")?;
        }
        emit(&format!(
            "compared with {} ({}, commit {}):\n{}",
            args.compare.as_deref().unwrap_or_default(),
            before.timestamp,
            short(&before.git_commit),
            c.table()
        ))?;
    }
    Ok(Outcome { record, comparison })
}

/// The engines `raywave bench` measures, in record order.
const ENGINES: [Engine; 2] = [Engine::Reference, Engine::Wavefront];

/// The error for a record that holds nothing this run can be compared with.
fn incomparable(path: &std::path::Path, problems: &[String]) -> String {
    format!(
        "cannot compare with {}: expected figures for every engine and stage this run \
         measures, each a positive rate, but:\n  {}\nsave a new record with --save",
        path.display(),
        problems.join("\n  ")
    )
}

/// Writes to stdout; a closed pipe (`raywave bench | head`) is an error, not a panic.
fn emit(text: &str) -> Result<()> {
    crate::terminal::write_stdout(text).context("cannot write to stdout")
}

fn short(commit: &str) -> &str {
    commit.get(..12).unwrap_or(commit)
}

/// One untimed render per engine, then `runs` interleaved timed renders of each.
fn measure(scene: &Scene, settings: &RenderSettings, runs: u32) -> Vec<EngineRecord> {
    let engines = ENGINES.map(|engine| engine.prepare(scene, settings, DEFAULT_BATCH_SIZE));
    let time = |engine: &Prepared| {
        let start = Instant::now();
        let (film, stats) = engine.render(&|| {});
        let seconds = start.elapsed().as_secs_f64();
        drop::<Film>(film);
        let stages = match engine.engine() {
            Engine::Wavefront => stats.stage_rows().iter().map(StageFigure::from).collect(),
            Engine::Reference => Vec::new(),
        };
        Measurement {
            seconds,
            rays: stats.counts,
            rays_per_second: KindRates::measured(&stats, seconds),
            stages,
        }
    };
    for engine in &engines {
        time(engine);
    }
    let mut measured = [Vec::new(), Vec::new()];
    for _ in 0..runs {
        for (engine, runs) in engines.iter().zip(&mut measured) {
            runs.push(time(engine));
        }
    }
    engines
        .iter()
        .zip(measured)
        .map(|(engine, runs)| EngineRecord {
            engine: engine.engine().name().to_string(),
            median: Measurement::median_of(&runs),
            runs,
        })
        .collect()
}

/// The printed report of one record: header, then per engine its kinds and stages.
pub fn report(r: &BenchRecord) -> String {
    use std::fmt::Write as _;
    let s = &r.setup.settings;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "raywave {} · commit {}{} · simd {} · {} thread(s) · {}",
        r.raywave,
        short(&r.git_commit),
        if r.git_dirty == Some(true) {
            " (dirty)"
        } else {
            ""
        },
        r.simd,
        r.setup.threads,
        r.machine.cpu
    );
    let shadows = match s.shadows {
        ShadowMode::Soft => format!("soft, {} {} points", s.shadow_samples, s.sampler.name()),
        ShadowMode::Hard => "hard".to_string(),
        ShadowMode::Off => "off".to_string(),
    };
    // The lighting is named only when it is not the lab's (the records of before it existed).
    let lab = RenderSettings::default();
    let lighting = if (s.light_model, s.ambient) == (lab.light_model, lab.ambient) {
        String::new()
    } else {
        let [r, g, b] = s.ambient;
        format!(", light model {:?}, ambient {r} {g} {b}", s.light_model).to_lowercase()
    };
    let _ = writeln!(
        out,
        "scene   {} · {}×{}, {} bounces, shadows {shadows}, {} aa{lighting} · medians of {} run(s)",
        r.setup.scene.source, s.width, s.height, s.bounces, s.aa_samples, r.runs
    );
    // Each kind over the thread-time of its own work (`-`: not measured, as for the reference,
    // timed without timers), the total over the wall clock.
    let _ = writeln!(
        out,
        "{:<10} {:<12} {:>12} {:>10} {:>16}",
        "engine", "kind", "rays", "seconds", "Mrays/thread-s"
    );
    for e in &r.engines {
        let m = &e.median;
        let k = &m.rays_per_second;
        for (kind, rays, rate) in [
            ("camera", m.rays.camera, k.camera),
            ("shadow", m.rays.shadow, k.shadow),
            ("reflection", m.rays.reflection, k.reflection),
        ] {
            let rate = rate.map_or("-".to_string(), |r| format!("{:.2}", r / 1e6));
            let _ = writeln!(
                out,
                "{:<10} {kind:<12} {rays:>12} {:>10} {rate:>16}",
                e.engine, ""
            );
        }
        let _ = writeln!(
            out,
            "{:<10} {:<12} {:>12} {:>10.3} {:>16.2}  (Mrays/s, wall clock)",
            e.engine,
            "total",
            m.rays.total(),
            m.seconds,
            k.total / 1e6
        );
    }
    let _ = writeln!(
        out,
        "{:<10} {:<12} {:>12} {:>10} {:>16}",
        "engine", "stage", "rays", "thread-s", "Mrays/thread-s"
    );
    for e in &r.engines {
        if e.median.stages.is_empty() {
            let _ = writeln!(
                out,
                "{:<10} (no stages: one recursive trace per pixel)",
                e.engine
            );
        }
        for st in &e.median.stages {
            let _ = writeln!(
                out,
                "{:<10} {:<12} {:>12} {:>10.4} {:>16.2}",
                e.engine,
                st.stage,
                st.rays,
                st.thread_seconds,
                st.rays_per_thread_second / 1e6
            );
        }
    }
    out
}
