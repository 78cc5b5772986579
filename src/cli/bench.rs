//! `raywave bench` flags, turned into `raywave::bench::BenchOptions`.

use super::image::ImageArgs;
use anyhow::Result;
use clap::Args;
use raywave::bench::record::record_path;
use raywave::bench::{BenchOptions, DEFAULT_THRESHOLD_PCT};
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
    /// Regression threshold in percent: a headline figure that falls by more fails --compare.
    #[arg(long, value_name = "PCT", default_value_t = DEFAULT_THRESHOLD_PCT,
          value_parser = parse_threshold)]
    pub threshold: f64,
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
            threshold: self.threshold,
            json: self.json.clone(),
            quiet: self.quiet,
        }
    }
}

/// The scene and the `--compare` record (inputs), the `--save` record and `--json` (outputs).
/// Names `record_path` refuses are left to the bench, which reports them.
fn output_plan(args: &BenchArgs) -> OutputPlan {
    let mut plan = OutputPlan::new();
    if let Some(scene) = args.scene.as_ref().or(args.input.as_ref()) {
        plan = plan.input("SCENE", scene);
    }
    if let Some(Ok(path)) = args.compare.as_ref().map(|n| record_path(&args.dir, n)) {
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
/// finds a regression, else 0.
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
    Ok(raywave::bench::run(&args.options())?.exit_code())
}
