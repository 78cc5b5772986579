//! `raywave variance`: the command-line face of the study (flags, progress, outputs).

use super::{Region, RenderFn, StudyConfig, run_study};
use crate::sampling::LightSampler;
use crate::scene::{BUILTIN_CORNELL_BOX, Scene};
use crate::settings::RenderSettings;
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::Write;
use std::path::PathBuf;

/// Flags of `raywave variance`.
#[derive(Args, Debug, Clone)]
pub struct VarianceArgs {
    /// Scene file; without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// Light-sample budgets N, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1u32, 4, 16, 64, 256], value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub budgets: Vec<u32>,
    /// Samplers to compare, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = LightSampler::ALL)]
    pub samplers: Vec<LightSampler>,
    /// Seeds (independent renders) per sampler and budget; at least 2, for the variance.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(2..=1024))]
    pub seeds: u32,
    /// Image size.
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [128u32, 128], value_parser = clap::value_parser!(u32).range(1..=4096))]
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
    /// The budget whose per-pixel error maps are drawn (must be one of --budgets).
    #[arg(long, default_value_t = 16)]
    pub heatmap_n: u32,
    /// Directory for table.txt, results.csv, results.json, mse.png and the heat maps.
    #[arg(long, default_value = "variance-report")]
    pub out: PathBuf,
    /// Directory caching converged references (keyed by scene bytes and settings).
    #[arg(long, default_value = ".raywave-cache")]
    pub cache: PathBuf,
    /// Always render the converged reference, ignoring and not writing the cache.
    #[arg(long)]
    pub no_cache: bool,
    /// How a light's colour reaches a point: lab (no fall-off) or rpi (divided by π·d², as
    /// RPI's framework does).
    #[arg(long, value_enum, default_value = "lab")]
    pub light_model: crate::settings::LightModel,
    /// The engine that renders the images (both draw the same samples).
    #[arg(long, value_enum, default_value = "wavefront")]
    pub engine: crate::cli::Engine,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

impl VarianceArgs {
    /// Checks the flags against each other; errors name the flag.
    pub fn validate(&self) -> Result<()> {
        // Every seed's image is kept until its statistics are taken.
        let bytes = self.seeds as u64 * self.size[0] as u64 * self.size[1] as u64 * 12;
        if bytes > MAX_STUDY_BYTES {
            bail!(
                "--seeds {} at --size {} {} would hold {:.1} GiB of images at once: expected at most {} GiB; use fewer seeds or a smaller size",
                self.seeds,
                self.size[0],
                self.size[1],
                bytes as f64 / (1u64 << 30) as f64,
                MAX_STUDY_BYTES >> 30
            );
        }
        if self.out.exists() && !self.out.is_dir() {
            bail!(
                "--out {}: expected a directory, found a file",
                self.out.display()
            );
        }
        if !self.budgets.contains(&self.heatmap_n) {
            return Err(crate::cli::UsageError(format!(
                "--heatmap-n {} is not one of --budgets {:?}: expected one of the budgets",
                self.heatmap_n, self.budgets
            ))
            .into());
        }
        if self.samplers.is_empty() {
            bail!("--samplers is empty: expected at least one of random, stratified, sobol, lab");
        }
        Ok(())
    }
}

/// The largest total size of the K images a study holds at once.
pub const MAX_STUDY_BYTES: u64 = 4 << 30;

/// Runs the study with `render` (the engine), writes the outputs, then prints the table.
pub fn run(args: &VarianceArgs, engine: &str, render: &RenderFn) -> Result<()> {
    args.validate()?;
    let (scene, scene_bytes) = match &args.scene {
        Some(path) => (Scene::load(path)?, std::fs::read(path)?),
        None => (
            Scene::builtin_default(),
            BUILTIN_CORNELL_BOX.as_bytes().to_vec(),
        ),
    };
    for w in &scene.warnings {
        eprintln!("{w}");
    }
    if scene.lights.is_empty() {
        bail!(
            "{}: expected a scene with at least one area light (a face whose material has a non-zero `emitted`), found none: there is no light sampling to study",
            scene.source
        );
    }
    // Fail on an unusable output directory now, not after minutes of rendering.
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create the output directory {}", args.out.display()))?;
    let mut cache = (!args.no_cache).then_some(args.cache.as_path());
    if let Some(dir) = cache
        && let Err(e) = std::fs::create_dir_all(dir)
    {
        eprintln!(
            "warning: cannot use the cache directory {} ({e}): the converged reference will not be cached",
            dir.display()
        );
        cache = None;
    }
    let mut samplers = Vec::new();
    for s in &args.samplers {
        if !samplers.contains(s) {
            samplers.push(*s);
        }
    }
    let mut budgets = Vec::new();
    for n in &args.budgets {
        if !budgets.contains(n) {
            budgets.push(*n);
        }
    }
    let base = RenderSettings {
        width: args.size[0],
        height: args.size[1],
        bounces: args.bounces,
        light_model: args.light_model,
        background: scene
            .background
            .map(|c| c.to_array())
            .unwrap_or(RenderSettings::default().background),
        ..RenderSettings::default()
    };
    let config = StudyConfig {
        budgets,
        samplers,
        seeds: args.seeds,
        reference_samples: args.reference_samples,
        mask_samples: args.mask_samples,
        heatmap_n: args.heatmap_n,
        ..StudyConfig::standard(base)
    };
    let steps = 2 + (config.samplers.len() * config.budgets.len()) as u64 * config.seeds as u64;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} variance [{bar:30}] {pos}/{len} {msg} ({elapsed}, eta {eta})",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar.set_message("converged reference");
        bar
    };
    let result = run_study(
        &scene,
        &scene_bytes,
        &config,
        engine,
        render,
        cache,
        &|label| {
            bar.set_message(label.to_string());
            bar.inc(1);
        },
    )?;
    bar.finish_and_clear();
    // Files first: a closed or full standard output must not cost the results.
    let written = result.write(&args.out)?;
    for region in [Region::Penumbra, Region::Lit] {
        let margin = result.reference_margin(region);
        if result.region_pixels[Region::ALL.iter().position(|&r| r == region).unwrap_or(0)] > 0
            && margin < 10.0
        {
            eprintln!(
                "warning: the converged reference's own error is only {margin:.1}× below the smallest MSE measured on the {} region; raise --reference-samples",
                region.name()
            );
        }
    }
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "{}\nconverged reference: {}\nwrote   {}",
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
    )
    .context("cannot write to standard output")?;
    Ok(())
}
