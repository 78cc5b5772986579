//! `raywave variance`: the study as a command (options, progress, outputs); the flags are the
//! binary's.

use super::{Cache, Region, StudyConfig, cache, run_study};
use crate::output::terminal::{print, progress_bar};
use crate::render::engine::Engine;
use crate::render::error::UsageError;
use crate::render::sampling::LightSampler;
use crate::render::scene::{ParseOptions, Scene, SceneFile, load_scene};
use crate::render::settings::{LightModel, RenderSettings};
use anyhow::{Context, Result, bail};
use std::path::PathBuf;

/// What `raywave variance` is asked to do (its flags, as plain values).
#[derive(Clone, Debug)]
pub struct VarianceOptions {
    /// Scene file; `None` for the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// Light-sample budgets N.
    pub budgets: Vec<u32>,
    /// Samplers to compare.
    pub samplers: Vec<LightSampler>,
    /// Seeds (independent renders) per sampler and budget.
    pub seeds: u32,
    /// Image width and height.
    pub size: [u32; 2],
    /// Mirror bounces.
    pub bounces: u32,
    /// Stratified points per light in each half of the converged reference.
    pub reference_samples: u32,
    /// Points per light per hit for the penumbra mask.
    pub mask_samples: u32,
    /// The budget whose per-pixel error maps are drawn (the nearest of `budgets` if it is not
    /// one, see [`VarianceOptions::heatmap_budget`]).
    pub heatmap_n: u32,
    /// Directory for the tables, plots and heat maps.
    pub out: PathBuf,
    /// Directory caching converged references.
    pub cache: PathBuf,
    /// Always render the converged reference, ignoring and not writing the cache.
    pub no_cache: bool,
    /// Bound on the cache's total size, in MiB: the least recently used entries go first.
    pub cache_limit_mib: u64,
    /// Remove the cache's entries and stop, without running a study.
    pub clean_cache: bool,
    /// How a light's colour reaches a point.
    pub light_model: LightModel,
    /// The engine that renders the images.
    pub engine: Engine,
    /// No progress bar.
    pub quiet: bool,
}

impl VarianceOptions {
    /// Checks the flags against each other; errors name the flag.
    pub fn validate(&self) -> Result<()> {
        // Every seed's image of every sampler at one N is kept until its statistics are taken
        // (the samplers are interleaved), and one 8-bit render per sampler and N for the
        // contact sheet.
        let pixels = self.size[0] as u64 * self.size[1] as u64;
        let samplers = self.samplers.len().max(1) as u64;
        let bytes = pixels * samplers * (self.seeds as u64 * 12 + self.budgets.len() as u64 * 3);
        if bytes > MAX_STUDY_BYTES {
            return Err(UsageError(format!(
                "--seeds {} of {} samplers at --size {} {} would hold {:.1} GiB of images at once: expected at most {} GiB; use fewer seeds or samplers, or a smaller size",
                self.seeds,
                samplers,
                self.size[0],
                self.size[1],
                bytes as f64 / (1u64 << 30) as f64,
                MAX_STUDY_BYTES >> 30
            ))
            .into());
        }
        if self.out.exists() && !self.out.is_dir() {
            bail!(
                "--out {}: expected a directory, found a file",
                self.out.display()
            );
        }
        if self.budgets.is_empty() {
            return Err(
                UsageError("--budgets is empty: expected at least one budget N".into()).into(),
            );
        }
        if self.samplers.is_empty() {
            return Err(UsageError(
                "--samplers is empty: expected at least one of random, stratified, sobol, lab"
                    .into(),
            )
            .into());
        }
        Ok(())
    }

    /// The budget whose heat maps are drawn: `heatmap_n` if it is one of the budgets, else the
    /// budget nearest to it on a log scale (budgets grow by factors), the smaller on a tie.
    pub fn heatmap_budget(&self) -> u32 {
        nearest_budget(&self.budgets, self.heatmap_n).unwrap_or(self.heatmap_n)
    }
}

/// The budget of `budgets` nearest to `n` on a log scale (|log b − log n| smallest), the
/// smaller of two at the same distance; None for no budgets.
pub fn nearest_budget(budgets: &[u32], n: u32) -> Option<u32> {
    let distance = |b: u32| ((b.max(1) as f64).ln() - (n.max(1) as f64).ln()).abs();
    budgets
        .iter()
        .copied()
        .min_by(|&a, &b| distance(a).total_cmp(&distance(b)).then(a.cmp(&b)))
}

/// The largest total size of the K images a study holds at once.
pub const MAX_STUDY_BYTES: u64 = 4 << 30;

/// Runs the study on the current rayon pool, writes the outputs, then prints the table.
pub fn run(args: &VarianceOptions) -> Result<()> {
    if args.clean_cache {
        let (files, bytes) = cache::clean(&args.cache)?;
        return print(&format!(
            "removed {files} cache entr{} ({:.1} MiB) from {}\n",
            if files == 1 { "y" } else { "ies" },
            bytes as f64 / (1u64 << 20) as f64,
            args.cache.display()
        ));
    }
    args.validate()?;
    let SceneFile {
        scene,
        bytes: scene_bytes,
    } = load_scene(args.scene.as_deref(), &ParseOptions::default())?;
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
    let mut cache = (!args.no_cache).then(|| Cache::new(&args.cache, args.cache_limit_mib));
    if let Some(c) = &cache
        && let Err(e) = std::fs::create_dir_all(&c.dir)
    {
        eprintln!(
            "warning: cannot use the cache directory {} ({e}): the converged reference will not be cached",
            c.dir.display()
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
    let heatmap_n = args.heatmap_budget();
    if heatmap_n != args.heatmap_n {
        eprintln!(
            "note: --heatmap-n {} is not one of --budgets; drawing the heat maps at the nearest budget, N = {heatmap_n}",
            args.heatmap_n
        );
    }
    let config = StudyConfig {
        budgets,
        samplers,
        seeds: args.seeds,
        reference_samples: args.reference_samples,
        mask_samples: args.mask_samples,
        heatmap_n,
        ..StudyConfig::standard(base)
    };
    // The reference, the mask, then per sampler and N a warm-up render and K timed ones.
    let steps =
        2 + (config.samplers.len() * config.budgets.len()) as u64 * (config.seeds as u64 + 1);
    let bar = progress_bar(
        steps,
        "{spinner} variance [{bar:30}] {pos}/{len} {msg} ({elapsed}, eta {eta})",
        args.quiet,
    );
    bar.set_message("converged reference");
    let result = run_study(
        &scene,
        &scene_bytes,
        &config,
        args.engine.name(),
        &|scene: &Scene, settings: &RenderSettings| args.engine.image(scene, settings),
        cache.as_ref(),
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
