//! `raywave variance`: the study as a command (options, checks, outputs); the flags, the
//! progress bar and the printed table are the binary's (`cli/variance.rs`).

use super::{Cache, Region, RenderFn, StudyConfig, run_study};
use crate::render::engine::{Engine, Hooks};
use crate::render::error::UsageError;
use crate::render::sampling::LightSampler;
use crate::render::scene::Scene;
use crate::render::settings::{LightModel, RenderSettings, ShadowMode};
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
            let names: Vec<&str> = LightSampler::ALL.iter().map(|s| s.name()).collect();
            return Err(UsageError(format!(
                "--samplers is empty: expected at least one of {}",
                names.join(", ")
            ))
            .into());
        }
        // Every sampler takes every budget, or the study stops before it starts.
        for &sampler in &self.samplers {
            for &n in &self.budgets {
                let settings = RenderSettings {
                    width: self.size[0],
                    height: self.size[1],
                    shadows: ShadowMode::Soft,
                    shadow_samples: n,
                    sampler,
                    aa_samples: 1,
                    ..RenderSettings::default()
                };
                crate::render::sampling::check(&settings).map_err(|e| {
                    UsageError(format!(
                        "{e}; the study's --budgets include {n}: leave {} out of --samplers, or that budget out",
                        sampler.name()
                    ))
                })?;
            }
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

/// A finished study: its result, and the files written.
pub struct Outcome {
    /// The figures.
    pub result: super::StudyResult,
    /// The files written into `--out`, in order.
    pub written: Vec<PathBuf>,
}

/// Runs the study of `scene` (whose file held `scene_bytes`) as `options` say, on the current
/// rayon pool, and writes its files into `options.out`. Reports through `hooks`; prints
/// nothing.
pub fn study(
    options: &VarianceOptions,
    scene: &Scene,
    scene_bytes: &[u8],
    render: &RenderFn,
    hooks: &Hooks,
) -> Result<Outcome> {
    options.validate()?;
    if scene.lights.is_empty() {
        bail!(
            "{}: expected a scene with at least one area light (a face whose material has a non-zero `emitted`), found none: there is no light sampling to study",
            scene.source
        );
    }
    // Fail on an unusable output directory now, not after minutes of rendering.
    std::fs::create_dir_all(&options.out).with_context(|| {
        format!(
            "cannot create the output directory {}",
            options.out.display()
        )
    })?;
    let mut cache =
        (!options.no_cache).then(|| Cache::new(&options.cache, options.cache_limit_mib));
    if let Some(c) = &cache
        && let Err(e) = std::fs::create_dir_all(&c.dir)
    {
        (hooks.notice)(&format!(
            "warning: cannot use the cache directory {} ({e}): the converged reference will not be cached",
            c.dir.display()
        ));
        cache = None;
    }
    let mut samplers = Vec::new();
    for s in &options.samplers {
        if !samplers.contains(s) {
            samplers.push(*s);
        }
    }
    let mut budgets = Vec::new();
    for n in &options.budgets {
        if !budgets.contains(n) {
            budgets.push(*n);
        }
    }
    let base = RenderSettings {
        width: options.size[0],
        height: options.size[1],
        bounces: options.bounces,
        light_model: options.light_model,
        background: scene
            .background
            .map(|c| c.to_array())
            .unwrap_or(RenderSettings::default().background),
        ..RenderSettings::default()
    };
    let config = StudyConfig {
        budgets,
        samplers,
        seeds: options.seeds,
        reference_samples: options.reference_samples,
        mask_samples: options.mask_samples,
        heatmap_n: options.heatmap_budget(),
        ..StudyConfig::standard(base)
    };
    let result = run_study(
        scene,
        scene_bytes,
        &config,
        options.engine.name(),
        render,
        cache.as_ref(),
        hooks,
    )?;
    let written = result.write(&options.out)?;
    for region in [Region::Penumbra, Region::Lit] {
        let margin = result.reference_margin(region);
        if result.region_pixels[Region::ALL.iter().position(|&r| r == region).unwrap_or(0)] > 0
            && margin < 10.0
        {
            (hooks.notice)(&format!(
                "warning: the converged reference's own error is only {margin:.1}× below the smallest MSE measured on the {} region; raise --reference-samples",
                region.name()
            ));
        }
    }
    Ok(Outcome { result, written })
}
