//! `raywave bench` flags, turned into `raywave::bench::BenchOptions`.

use super::image::ImageArgs;
use super::values::EngineArg;
use anyhow::Result;
use clap::Args;
use raywave::bench::ab::{self, AbOptions, MIN_ROUNDS};
use raywave::bench::record::record_path;
use raywave::bench::{BenchOptions, DEFAULT_THRESHOLD_PCT, EXIT_REGRESSION};
use raywave::output::OutputPlan;
use raywave::output::memory::{self, RenderFootprint};
use std::path::PathBuf;

/// Flags of `raywave bench`.
#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Scene file (.obj); without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// The lab's `-input FILE` (same as the positional SCENE).
    #[arg(long = "input", hide = true, conflicts_with = "scene")]
    pub input: Option<PathBuf>,
    /// Size, bounces, shadows and sampling, as for `raywave render`.
    #[command(flatten)]
    pub image: ImageArgs,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Timed runs per engine (medians are reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub runs: u32,
    /// Save the record as DIR/NAME.json.
    #[arg(long, value_name = "NAME")]
    pub save: Option<String>,
    /// Compare with the record DIR/NAME.json; exit 3 if a headline figure regressed.
    #[arg(long, value_name = "NAME")]
    pub compare: Option<String>,
    /// Directory of saved records.
    #[arg(long, default_value = ".raywave-bench")]
    pub dir: PathBuf,
    /// Regression threshold in percent: a headline figure that falls by more fails --compare;
    /// with --against, a ratio whose whole 95% interval lies above 1 + PCT% fails [default: 40;
    /// 5 with --against].
    #[arg(long, value_name = "PCT", value_parser = parse_threshold)]
    pub threshold: Option<f64>,
    /// Time this build against another raywave binary on the same flags: the two alternate,
    /// round after round, and each engine's time ratio (this / OTHER) gets a median and a 95%
    /// interval from the paired rounds; exit 3 when the whole interval lies above the threshold.
    #[arg(long, value_name = "OTHER", conflicts_with_all = ["save", "compare", "json", "runs"])]
    pub against: Option<PathBuf>,
    /// Timed rounds with --against (each runs both builds once).
    #[arg(long, default_value_t = 20, requires = "against",
          value_parser = clap::value_parser!(u32).range(i64::from(MIN_ROUNDS)..=10_000))]
    pub rounds: u32,
    /// Untimed rounds before the timed ones with --against.
    #[arg(long, default_value_t = 1, requires = "against",
          value_parser = clap::value_parser!(u32).range(0..=1000))]
    pub warmup: u32,
    /// Which engine --against times [default: both].
    #[arg(long, value_enum, requires = "against")]
    pub engine: Option<EngineArg>,
    /// Also write the record as JSON to FILE (`-` for stdout).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Print only the comparison (or nothing but errors without --compare).
    #[arg(short, long)]
    pub quiet: bool,
}

fn parse_threshold(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && (0.0..1000.0).contains(&x) => Ok(x),
        _ => Err(format!(
            "expected a percentage between 0 and 1000, found `{s}`"
        )),
    }
}

impl BenchArgs {
    /// The flags as the library's options.
    pub fn options(&self) -> BenchOptions {
        BenchOptions {
            scene: self.scene.clone().or_else(|| self.input.clone()),
            image: self.image.options(),
            threads: self.threads,
            runs: self.runs,
            save: self.save.clone(),
            compare: self.compare.clone(),
            dir: self.dir.clone(),
            threshold: self.threshold.unwrap_or(DEFAULT_THRESHOLD_PCT),
            json: self.json.clone(),
            quiet: self.quiet,
        }
    }
}

/// The threshold of `--against` when none is given, in percent.
const AB_THRESHOLD_PCT: f64 = 5.0;

/// The scene and the `--compare` record (inputs), the `--save` record and `--json` (outputs).
/// `--save` may name the `--compare` record (see below), no other input.
/// Names `record_path` refuses are left to the bench, which reports them.
fn output_plan(args: &BenchArgs) -> OutputPlan {
    let mut plan = OutputPlan::new();
    if let Some(scene) = args.scene.as_ref().or(args.input.as_ref()) {
        plan = plan.input("SCENE", scene);
    }
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
    if let Some(Ok(path)) = args.save.as_ref().map(|n| record_path(&args.dir, n)) {
        plan = plan.output_in_new_dir("--save", &path);
    }
    if let Some(json) = &args.json {
        plan = plan.output("--json", json);
    }
    plan
}

/// Runs the bench; the exit code is 3 (`raywave::bench::EXIT_REGRESSION`) when `--compare`
/// or `--against` finds a regression, else 0.
pub fn run(args: &BenchArgs) -> Result<u8> {
    output_plan(args).check()?;
    // Each timed run holds one film; refuse a size the machine cannot hold before any timing.
    let settings = args.image.options().resolve(None).settings;
    let threads = args.threads.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get() as u64),
        u64::from,
    );
    memory::check(
        &RenderFootprint {
            pixels: settings.width as u64 * settings.height as u64,
            primitives: 0,
            threads,
            batch_size: raywave::wavefront::DEFAULT_BATCH_SIZE as u64,
            rgb8: false,
            exr_in_memory: false,
        },
        None,
    )?;
    let Some(other) = &args.against else {
        return Ok(raywave::bench::run(&args.options())?.exit_code());
    };
    let options = AbOptions {
        other: other.clone(),
        scene: args.scene.clone().or_else(|| args.input.clone()),
        render_flags: args.image.flags(),
        engines: match args.engine {
            Some(e) => vec![e.into()],
            None => vec![
                raywave::engine::Engine::Wavefront,
                raywave::engine::Engine::Reference,
            ],
        },
        threads: args.threads,
        rounds: args.rounds,
        warmup: args.warmup,
        threshold_pct: args.threshold.unwrap_or(AB_THRESHOLD_PCT),
        quiet: args.quiet,
    };
    let bar = raywave::terminal::progress_bar(
        0,
        "{elapsed_precise} [{bar:40}] {pos}/{len} runs, both builds alternating",
        args.quiet,
    );
    let results = ab::run(&options, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    raywave::terminal::print(&ab::report(&options, &results))?;
    Ok(if ab::regressed(&options, &results) {
        EXIT_REGRESSION
    } else {
        0
    })
}
