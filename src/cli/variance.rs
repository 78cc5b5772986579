//! `raywave variance` flags, turned into `raywave::variance::command::VarianceOptions`.

use super::image::ThreadsArg;
use super::values::{EngineArg, LightModelArg, SamplerArg};
use anyhow::Result;
use clap::Args;
use raywave::output::OutputPlan;
use raywave::output::terminal::{print, progress_bar};
use raywave::render::engine::{Hooks, clamped_warning};
use raywave::render::scene::{ParseOptions, Scene, SceneFile, load_scene};
use raywave::render::settings::RenderSettings;
use raywave::render::wavefront::DEFAULT_BATCH_SIZE;
use raywave::variance::command::{Outcome, VarianceOptions, study};
use std::path::PathBuf;

/// Flags of `raywave variance`.
#[derive(Args, Debug, Clone)]
pub struct VarianceArgs {
    /// Scene file; without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// Light-sample budgets N: comma- or space-separated (`1,4,16` or `1 4 16`; with spaces,
    /// give SCENE before this flag).
    #[arg(long, num_args = 1.., value_delimiter = ',', default_values_t = [1u32, 4, 16, 64, 256], value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub budgets: Vec<u32>,
    /// Samplers to compare: comma- or space-separated (`random,sobol` or `random sobol`; with
    /// spaces, give SCENE before this flag).
    #[arg(long, value_enum, num_args = 1.., value_delimiter = ',', default_values_t = SamplerArg::ALL)]
    pub samplers: Vec<SamplerArg>,
    /// Seeds (independent renders) per sampler and budget; at least 2, for the variance.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(2..=1024))]
    pub seeds: u32,
    /// Image size.
    #[arg(long, num_args = 2, action = clap::ArgAction::Set, value_names = ["W", "H"], default_values_t = [128u32, 128], value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub size: Vec<u32>,
    /// Mirror bounces.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub bounces: u32,
    /// Stratified points per light in each half of the converged reference.
    #[arg(long, default_value_t = 4096, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub reference_samples: u32,
    /// Points per light per hit for the penumbra mask.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub mask_samples: u32,
    /// The budget whose per-pixel error maps are drawn; a value that is not one of --budgets
    /// picks the nearest of them on a log scale (with a note on standard error).
    #[arg(long, default_value_t = 16)]
    pub heatmap_n: u32,
    /// Directory for table.txt, results.csv, seeds.csv, perceived.csv, spectra.csv,
    /// results.json, mse.png, contact_sheet.png, the heat maps and the spectra.
    #[arg(long, default_value = "variance-report")]
    pub out: PathBuf,
    /// Directory caching converged references (keyed by the scene bytes parsed, the settings
    /// and the executable; every entry is checked when read and rendered again if it fails).
    #[arg(long, default_value = ".raywave-cache")]
    pub cache: PathBuf,
    /// Always render the converged reference, ignoring and not writing the cache.
    #[arg(long, conflicts_with_all = ["cache", "cache_limit", "clean_cache"])]
    pub no_cache: bool,
    /// Bound on the cache's total size in MiB; the least recently used entries are removed
    /// above it.
    #[arg(long, value_name = "MIB",
          default_value_t = raywave::variance::cache::DEFAULT_LIMIT_MIB,
          value_parser = clap::value_parser!(u64).range(1..=1 << 30))]
    pub cache_limit: u64,
    /// Remove every converged reference from the --cache directory (other files are left
    /// alone) and exit, without running a study.
    #[arg(long, conflicts_with = "scene")]
    pub clean_cache: bool,
    /// How a light's colour reaches a point: lab (no fall-off) or rpi (divided by π·d², as
    /// RPI's framework does).
    #[arg(long, value_enum, default_value = "lab")]
    pub light_model: LightModelArg,
    /// The engine that renders the images (both draw the same samples).
    #[arg(long, value_enum, default_value = "wavefront")]
    pub engine: EngineArg,
    #[command(flatten)]
    pub workers: ThreadsArg,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

impl VarianceArgs {
    /// The flags as the library's options.
    pub fn options(&self) -> VarianceOptions {
        VarianceOptions {
            scene: self.scene.clone(),
            budgets: self.budgets.clone(),
            samplers: self.samplers.iter().map(|&s| s.into()).collect(),
            seeds: self.seeds,
            size: [self.size[0], self.size[1]],
            bounces: self.bounces,
            reference_samples: self.reference_samples,
            mask_samples: self.mask_samples,
            heatmap_n: self.heatmap_n,
            out: self.out.clone(),
            cache: self.cache.clone(),
            no_cache: self.no_cache,
            cache_limit_mib: self.cache_limit,
            clean_cache: self.clean_cache,
            light_model: self.light_model.into(),
            engine: self.engine.into(),
            quiet: self.quiet,
        }
    }
}

/// The scene (an input) and the files the study writes into `--out` (outputs).
fn output_plan(options: &VarianceOptions) -> OutputPlan {
    let mut plan = OutputPlan::new();
    if let Some(scene) = &options.scene {
        plan = plan.input("SCENE", scene);
    }
    let names = raywave::variance::report::file_names(
        &options.samplers,
        &options.budgets,
        options.heatmap_budget(),
    );
    for name in names {
        plan = plan.output_in_new_dir("--out", &options.out.join(name));
    }
    plan
}

/// Runs the study on `--threads` worker threads, with a progress bar, then prints its table.
pub fn run(args: &VarianceArgs) -> Result<()> {
    let options = args.options();
    if options.clean_cache {
        let (files, bytes) = raywave::variance::cache::clean(&options.cache)?;
        return print(&format!(
            "removed {files} cache entr{} ({:.1} MiB) from {}\n",
            if files == 1 { "y" } else { "ies" },
            bytes as f64 / (1u64 << 20) as f64,
            options.cache.display()
        ));
    }
    // The flags' own errors first, with their own messages; then the outputs.
    options.validate()?;
    output_plan(&options).check()?;
    let pool = args.workers.pool()?;
    let SceneFile { scene, bytes } =
        load_scene(options.scene.as_deref(), &ParseOptions::default())?;
    for w in &scene.warnings {
        eprintln!("{w}");
    }
    let heatmap_n = options.heatmap_budget();
    if heatmap_n != options.heatmap_n {
        eprintln!(
            "note: --heatmap-n {} is not one of --budgets; drawing the heat maps at the nearest budget, N = {heatmap_n}",
            options.heatmap_n
        );
    }
    let bar = progress_bar(
        0,
        "{spinner} variance [{bar:30}] {pos}/{len} {msg} ({elapsed}, eta {eta})",
        options.quiet,
    );
    let progress = |done: u64, total: u64, label: &str| {
        bar.set_length(total);
        bar.set_position(done);
        bar.set_message(label.to_string());
    };
    let notice = |line: &str| bar.suspend(|| eprintln!("{line}"));
    let render = |scene: &Scene, settings: &RenderSettings| {
        let (film, stats) = options
            .engine
            .render(scene, settings, DEFAULT_BATCH_SIZE, &|| {});
        if let Some(w) = clamped_warning(&stats) {
            notice(&w);
        }
        (film, stats.counts)
    };
    let hooks = Hooks {
        progress: &progress,
        notice: &notice,
    };
    let outcome = pool.install(|| study(&options, &scene, &bytes, &render, &hooks));
    bar.finish_and_clear();
    let Outcome { result, written } = outcome?;
    print(&format!(
        "{}\nconverged reference: {}\nwrote   {}\n",
        result.table(),
        if result.reference_cached {
            "from the cache"
        } else {
            "rendered"
        },
        written
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}
