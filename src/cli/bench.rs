//! `raywave bench` flags, turned into `raywave::bench::BenchOptions`, and its subcommands:
//! `compare` and `list` on saved records, `merge` on the part files of `--shard`.

use super::image::{ImageArgs, say};
use super::values::{EngineArg, float};
use anyhow::{Result, bail};
use clap::parser::ValueSource;
use clap::{ArgAction, ArgMatches, Args, Subcommand};
use raywave::bench::ab::{self, AbOptions, MIN_ROUNDS};
use raywave::bench::export::Exports;
use raywave::bench::merge::{self, MergeOptions};
use raywave::bench::running::sequential;
use raywave::bench::running::sweep::{Sweep, record_name};
use raywave::bench::shard::SweepPoints;
use raywave::bench::{BenchOptions, DEFAULT_RUNS, DEFAULT_THRESHOLD_PCT, EXIT_REGRESSION, list};
use raywave::output::OutputPlan;
use raywave::output::bench_record::record_path;
use raywave::output::machine::logical_cpus;
use raywave::output::memory::{self, RenderFootprint};
use raywave::output::terminal::with_bar;
use raywave::render::engine::Engine;
use raywave::render::error::UsageError;
use raywave::shard::{Shard, part_name};
use std::path::PathBuf;

/// Flags of `raywave bench`. A scene file literally named `compare` or `list` is given as
/// `./compare` or `./list` (the bare words are the subcommands).
#[derive(Args, Debug, Clone)]
#[command(
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    mut_arg("size", |a| a.action(ArgAction::Append)
        .help("Image size in pixels; repeat to sweep sizes (--size 256 256 --size 512 512) \
               [default: 512 512; the lab's 100 100; RPI's 500 500]")),
    mut_arg("shadow_samples", |a| a.action(ArgAction::Append).value_delimiter(',')
        .help("Points per light with soft shadows; a comma-separated list sweeps them \
               (16,64) [default: 16]")),
)]
pub struct BenchArgs {
    /// Offline commands on saved records.
    #[command(subcommand)]
    pub action: Option<BenchAction>,
    /// Scene file (.obj); without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// The lab's `-input FILE` (same as the positional SCENE).
    #[arg(long = "input", hide = true, conflicts_with = "scene")]
    pub input: Option<PathBuf>,
    /// Size, bounces, shadows and sampling, as for `raywave render`.
    #[command(flatten)]
    pub image: ImageArgs,
    /// Worker threads; a comma-separated list sweeps them (1,2) [default: all cores].
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Vec<u32>,
    /// Which engines to time: a comma-separated list or the flag repeated (wavefront,reference).
    #[arg(long, value_enum, value_delimiter = ',',
          default_values_t = [EngineArg::Reference, EngineArg::Wavefront])]
    pub engine: Vec<EngineArg>,
    /// Lanes of the wavefront engine's kernels: auto (16 on an AVX-512 build, else 8), 8 or 16;
    /// the record's `simd` names the path that ran.
    #[arg(long, value_enum, default_value = "auto")]
    pub lanes: super::values::LanesArg,
    /// Timed runs per engine (at least 6 for a 95% interval of the median).
    #[arg(long, default_value_t = DEFAULT_RUNS, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub runs: u32,
    /// Untimed runs per engine (rounds with --against) before the timed ones.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=1000))]
    pub warmup: u32,
    /// Save the record as DIR/NAME.json (each point of a sweep as DIR/NAME+POINT.json).
    #[arg(long, value_name = "NAME")]
    pub save: Option<String>,
    /// Compare with the record DIR/NAME.json, measured with its settings, threads and engines
    /// unless a flag says otherwise; exit 3 if a headline figure regressed.
    #[arg(long, value_name = "NAME")]
    pub compare: Option<String>,
    /// Directory of saved records.
    #[arg(long, default_value = ".raywave-bench")]
    pub dir: PathBuf,
    /// Regression threshold in percent: with --compare, a headline figure whose median fell
    /// by more and whose 95% interval lies wholly below the record's regressed; with
    /// --against, a ratio whose whole 95% interval lies above 1 + PCT% (and, one-sided, not a
    /// regression when it lies wholly at or below) [default: 40; 5 with --against].
    #[arg(long, value_name = "PCT", value_parser = float("a percentage between 0 and 1000", |x: f64| (0.0..1000.0).contains(&x)))]
    pub threshold: Option<f64>,
    /// Time this build against another raywave binary on the same flags: the two alternate,
    /// round after round, and each engine's time ratio (this / OTHER) gets a median and a 95%
    /// interval from the paired rounds; exit 3 when the whole interval lies above the threshold
    /// (a regression), "not slower" when it lies wholly at or below it.
    #[arg(long, value_name = "OTHER", conflicts_with_all = ["save", "compare", "json", "runs",
          "export_json", "export_csv", "export_markdown", "export_bmf",
          "export_github_action_benchmark"])]
    pub against: Option<PathBuf>,
    /// Timed rounds with --against (each runs both builds once).
    #[arg(long, default_value_t = 20, requires = "against",
          value_parser = clap::value_parser!(u32).range(i64::from(MIN_ROUNDS)..=10_000))]
    pub rounds: u32,
    /// With --against: instead of --rounds, keep alternating until each engine's verdict is
    /// decided (by default: a regression, or not), judged at planned looks (by default after
    /// 9, 14, 21, ..., 200 rounds) with each look's interval widened so that the looks together
    /// keep the 5% error of one 95% interval; exit 3 as above, 0 when decided otherwise, 4
    /// (undecided at the budget) when --max-rounds or --max-time runs out first.
    #[arg(long, requires = "against", conflicts_with = "rounds")]
    pub until_decided: bool,
    /// The verdicts of --against: `regression` asks only whether this build is slower than
    /// OTHER by more than --threshold; `three-way` also tells faster from no change, and with
    /// --until-decided goes on until it can (a build about --threshold faster may never).
    #[arg(long, value_enum, default_value = "regression", requires = "against")]
    pub verdict: super::values::VerdictArg,
    /// The last look's rounds with --until-decided, per engine.
    #[arg(long, value_name = "N", default_value_t = sequential::DEFAULT_MAX_ROUNDS,
          requires = "until_decided",
          value_parser = clap::value_parser!(u32).range(i64::from(MIN_ROUNDS)..=10_000))]
    pub max_rounds: u32,
    /// Time limit of --until-decided, warm-up included (10m, 90s, 1h30m): no look is started
    /// that the pace so far says cannot end in time [default: none].
    #[arg(long, value_name = "DURATION", requires = "until_decided",
          value_parser = super::values::duration)]
    pub max_time: Option<std::time::Duration>,
    /// Also write the record as JSON to FILE (`-` for stdout); one point only.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    #[command(flatten)]
    pub exports: ExportArgs,
    /// Time only shard I of N of the sweep's points (0-based; split by estimated cost) and
    /// write them to DIR/bench-shard-I-of-N.part for `raywave bench merge`.
    #[arg(long, value_name = "I/N", requires = "out",
          conflicts_with_all = ["against", "save", "compare", "json", "export_json", "export_csv",
          "export_markdown", "export_bmf", "export_github_action_benchmark"])]
    pub shard: Option<Shard>,
    /// The directory of --shard's part file (created if missing).
    #[arg(long, value_name = "DIR", requires = "shard")]
    pub out: Option<PathBuf>,
    /// Print only the comparison (or nothing but errors without --compare); no progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The subcommands of `raywave bench`.
#[derive(Subcommand, Debug, Clone)]
pub(crate) enum BenchAction {
    /// Compare two saved records (B against A) by the verdict rule; exit 3 if B regressed.
    Compare(CompareArgs),
    /// List the saved records: name, date, commit, scene, settings, threads, total medians.
    List(ListArgs),
    /// Merge the part files of `raywave bench --shard I/N` into the sweep's reports, exports
    /// and records; refuses missing, duplicated, damaged or mismatched parts.
    Merge(MergeArgs),
}

/// The `--export-*` flags of `raywave bench` and `raywave bench merge`.
#[derive(Args, Debug, Clone)]
pub struct ExportArgs {
    /// Write every point's record to FILE as a JSON array (`-` for stdout).
    #[arg(long, value_name = "FILE")]
    pub export_json: Option<PathBuf>,
    /// Write every point's headline figures to FILE as CSV (`-` for stdout).
    #[arg(long, value_name = "FILE")]
    pub export_csv: Option<PathBuf>,
    /// Write every point's headline figures to FILE as a Markdown table (`-` for stdout).
    #[arg(long, value_name = "FILE")]
    pub export_markdown: Option<PathBuf>,
    /// Write every point's headline figures to FILE in Bencher Metric Format (`-` for stdout).
    #[arg(long, value_name = "FILE")]
    pub export_bmf: Option<PathBuf>,
    /// Write every point's headline figures to FILE as github-action-benchmark's
    /// `customBiggerIsBetter` JSON (`-` for stdout).
    #[arg(long, value_name = "FILE")]
    pub export_github_action_benchmark: Option<PathBuf>,
}

impl ExportArgs {
    /// The flags as the library's exports.
    fn exports(&self) -> Exports {
        Exports {
            json: self.export_json.clone(),
            csv: self.export_csv.clone(),
            markdown: self.export_markdown.clone(),
            bmf: self.export_bmf.clone(),
            github_action_benchmark: self.export_github_action_benchmark.clone(),
        }
    }
}

/// Flags of `raywave bench merge`.
#[derive(Args, Debug, Clone)]
pub struct MergeArgs {
    /// The part files (DIR/bench-shard-I-of-N.part), or directories holding them: every shard
    /// of one sweep once.
    #[arg(required = true, value_name = "PARTS")]
    pub parts: Vec<PathBuf>,
    /// Accept parts measured on different machines: every report, row and exported name
    /// then carries its host, the points grouped by host.
    #[arg(long)]
    pub across_machines: bool,
    /// Save each point as DIR/NAME+POINT.json (DIR/NAME.json for a sweep of one point).
    #[arg(long, value_name = "NAME")]
    pub save: Option<String>,
    /// Directory of saved records.
    #[arg(long, default_value = ".raywave-bench")]
    pub dir: PathBuf,
    #[command(flatten)]
    pub exports: ExportArgs,
    /// Print only what was merged, not every point's report.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Flags of `raywave bench compare`.
#[derive(Args, Debug, Clone)]
pub(crate) struct CompareArgs {
    /// The earlier record: a name in --dir, or a path ending in .json.
    pub a: String,
    /// The later record, judged against A.
    pub b: String,
    /// Directory of saved records.
    #[arg(long, default_value = ".raywave-bench")]
    pub dir: PathBuf,
    /// Regression threshold in percent (the rule of --compare).
    #[arg(long, value_name = "PCT", value_parser = float("a percentage between 0 and 1000", |x: f64| (0.0..1000.0).contains(&x)), default_value_t = DEFAULT_THRESHOLD_PCT)]
    pub threshold: f64,
}

/// Flags of `raywave bench list`.
#[derive(Args, Debug, Clone)]
pub(crate) struct ListArgs {
    /// Directory of saved records.
    #[arg(long, default_value = ".raywave-bench")]
    pub dir: PathBuf,
}

/// The flags whose values `--compare` must not replace with the record's: those given on the
/// command line.
const ADOPTABLE: [&str; 12] = [
    "size",
    "bounces",
    "shadows",
    "shadow_samples",
    "sampler",
    "aa",
    "background",
    "ambient",
    "light_model",
    "defaults",
    "threads",
    "engine",
];

impl BenchArgs {
    /// The engines `--engine` names, each once, in record order (reference, then wavefront).
    fn engines(&self) -> Vec<Engine> {
        [EngineArg::Reference, EngineArg::Wavefront]
            .into_iter()
            .filter(|e| self.engine.contains(e))
            .map(Engine::from)
            .collect()
    }

    /// The flags as the library's options; `matches` are bench's own (for the shadow-sample
    /// list and which flags were given).
    pub fn options(&self, matches: Option<&ArgMatches>) -> BenchOptions {
        let sizes = self.image.size.as_deref().unwrap_or_default();
        let sweep = Sweep {
            sizes: sizes.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
            shadow_samples: (matches.and_then(|m| m.get_many::<u32>("shadow_samples")))
                .map_or_else(Vec::new, |v| v.copied().collect()),
            threads: self.threads.clone(),
        };
        let given = |id: &&str| {
            matches.is_some_and(|m| m.value_source(id) == Some(ValueSource::CommandLine))
        };
        let explicit = ADOPTABLE
            .into_iter()
            .filter(given)
            .map(|id| id.to_string())
            .collect();
        let sweep_points = sweep.points();
        BenchOptions {
            scene: self.scene.clone().or_else(|| self.input.clone()),
            image: self.image.options(),
            sweep,
            engines: self.engines(),
            lanes: self.lanes.into(),
            runs: self.runs,
            warmup: self.warmup,
            save: self.save.clone(),
            compare: self.compare.clone(),
            dir: self.dir.clone(),
            threshold: self.threshold.unwrap_or(DEFAULT_THRESHOLD_PCT),
            json: self.json.clone(),
            exports: self.exports.exports(),
            shard: self.shard.zip(self.out.clone()),
            explicit,
            plan: output_plan(self, &sweep_points),
        }
    }
}

/// The threshold of `--against` when none is given, in percent.
const AB_THRESHOLD_PCT: f64 = 5.0;

/// The scene and the `--compare` record (inputs), the `--save` records (one per point),
/// `--json` and the exports (outputs). `--save` may name the `--compare` record (see below), no
/// other input. Names `record_path` refuses are left to the bench, which reports them.
fn output_plan(args: &BenchArgs, points: &[raywave::bench::running::sweep::Point]) -> OutputPlan {
    let scene = args.scene.as_deref().or(args.input.as_deref());
    let mut plan = OutputPlan::new().input_if("SCENE", scene);
    // `--compare X --save X` is the rolling baseline, by design: X is read whole before any
    // timing, and replaced only when this run did not regress against it.
    if let Some(Ok(path)) = args
        .compare
        .as_ref()
        .filter(|c| args.save.as_ref() != Some(*c))
        .map(|n| record_path(&args.dir, n))
    {
        plan = plan.input("--compare", &path);
    }
    if let Some(name) = &args.save {
        for point in points {
            if let Ok(path) = record_path(&args.dir, &record_name(name, &point.label)) {
                plan = plan.output_in_new_dir("--save", &path);
            }
        }
    }
    plan = plan.output_if("--json", args.json.as_deref());
    plan = args.exports.exports().plan(plan);
    if let (Some(shard), Some(dir)) = (args.shard, &args.out) {
        plan = plan.output_in_new_dir("--out", &dir.join(part_name::<SweepPoints>(shard)));
    }
    plan
}

/// Runs the bench or one of its subcommands and returns the exit code (3 for a regression, 4
/// when `--until-decided` ends undecided; main.rs has the details). `matches` are bench's own.
pub fn run(args: &BenchArgs, matches: Option<&ArgMatches>) -> Result<u8> {
    match &args.action {
        Some(BenchAction::Compare(c)) => {
            let (table, regressed) = list::compare_saved(&c.dir, &c.a, &c.b, c.threshold)?;
            raywave::output::terminal::print(&table)?;
            return Ok(if regressed { EXIT_REGRESSION } else { 0 });
        }
        Some(BenchAction::List(l)) => {
            let (table, warnings) = list::list(&l.dir)?;
            for w in warnings {
                eprintln!("warning: {w}");
            }
            raywave::output::terminal::print(&table)?;
            return Ok(0);
        }
        Some(BenchAction::Merge(m)) => {
            let options = MergeOptions {
                parts: m.parts.clone(),
                exports: m.exports.exports(),
                save: m.save.clone(),
                dir: m.dir.clone(),
                across_machines: m.across_machines,
            };
            let text = merge::merge(&options)?.text(m.quiet);
            say(&options.exports.plan(OutputPlan::new()), &text)?;
            return Ok(0);
        }
        None => {}
    }
    let options = args.options(matches);
    options.plan.check()?;
    // Each timed run holds one film; refuse a size the machine cannot hold before any timing.
    let settings = args.image.options().resolve(None).settings;
    let pixels = (options.sweep.sizes.iter())
        .map(|&[w, h]| u64::from(w) * u64::from(h))
        .max();
    let threads = options.sweep.threads.iter().max();
    memory::check(
        &RenderFootprint {
            pixels: pixels.unwrap_or(settings.width as u64 * settings.height as u64),
            primitives: 0,
            threads: threads.map_or(logical_cpus() as u64, |&t| t.into()),
            batch_size: raywave::render::wavefront::DEFAULT_BATCH_SIZE as u64,
            rgb8: false,
            exr_in_memory: false,
            cost_map: false,
        },
        None,
    )?;
    let Some(other) = &args.against else {
        let outcome = with_bar(
            "{elapsed_precise} [{bar:40}] {pos}/{len} runs (warm-up included), engines alternating",
            args.quiet,
            |progress| raywave::bench::run(&options, progress),
        )?;
        let text = outcome.text(args.quiet, options.compare.as_deref());
        say(&options.plan, &text)?;
        return Ok(outcome.exit_code());
    };
    let points = options.sweep.points().len();
    if points > 1 || options.sweep.threads.len() > 1 {
        bail!(UsageError(format!(
            "--against times one point, but the flags sweep {points}: give one --size, one \
             --shadow-samples and one --threads"
        )));
    }
    let options = AbOptions {
        other: other.clone(),
        scene: args.scene.clone().or_else(|| args.input.clone()),
        render_flags: args.image.flags(),
        // The wavefront engine first: it gets its share of --max-time before the reference.
        engines: args.engines().into_iter().rev().collect(),
        threads: args.threads.first().copied(),
        rounds: args.rounds,
        until_decided: args.until_decided.then_some(sequential::Budget {
            max_rounds: args.max_rounds,
            max_time: args.max_time,
        }),
        warmup: args.warmup,
        rule: raywave::bench::verdict::Rule {
            threshold_pct: args.threshold.unwrap_or(AB_THRESHOLD_PCT),
            form: args.verdict.into(),
        },
        quiet: args.quiet,
    };
    let results = with_bar(
        "{elapsed_precise} [{bar:40}] {pos}/{len} runs, both builds alternating",
        args.quiet,
        |progress| ab::run(&options, progress),
    )?;
    raywave::output::terminal::print(&ab::report(&options, &results))?;
    Ok(ab::exit_code(&options, &results))
}
