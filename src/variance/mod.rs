//! The light-sampling study behind `raywave variance`: for each sampler and budget N, K seeded
//! renders against a converged reference, reported over the whole image, the penumbra and the
//! fully lit region.
//!
//! ```text
//! reference = mean of two independent stratified renders at N_ref   (cached on disk)
//! noise(ref) ≈ (A − B)² / 4 per pixel                                   (checked below the errors)
//! regions   = penumbra_mask(scene)                                      (dense stratified visibility)
//! for N:
//!     for sampler: warm-up render, seed 0 (untimed; kept for the contact sheet)
//!     for seed k in 1..=K: for sampler in samplers rotated by k: image = render(N, sampler, k)
//!                                                   (timed: interleaved, so drift hits all alike)
//!     per sampler and region: MSE, bias (with bound), variance across seeds, per-seed MSE,
//!     median time, rays/s, 1/(MSE·time)
//! slope of log MSE against log N over the noisy points      per sampler and region
//! budget matching 150 random points                          per sampler and region
//! 95% intervals: MSE, slope, efficiency, matching budget by bootstrap over seeds
//!                (stats::bootstrap_interval); time by the median's sign-test interval
//! ```

pub mod command;
pub mod figures;
pub mod merge;
pub mod report;
pub mod study;

use crate::render::film::Film;
use crate::render::per_kind::RayCounts;
use crate::render::progress::Progress;
use crate::render::sampling::LightSampler;
use crate::render::scene::Scene;
use crate::render::settings::{RenderSettings, ShadowMode};
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

pub use figures::errors::{
    BIAS_FALSE_ALARM, ErrorStats, bias_bound, deterministic, error_stats, per_image_errors,
    pixel_mse,
};
pub use figures::fits::{Matching, Slope, match_budget};
pub use figures::mask::{Regions, penumbra_mask};
pub use study::cache::Cache;

use figures::perceived;
use study::{cache, jobs};

/// Renders one image: the engine is the caller's choice (the fastest one, normally).
pub type RenderFn<'a> = dyn Fn(&Scene, &RenderSettings) -> (Film, RayCounts) + Sync + 'a;

/// What to measure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyConfig {
    /// Size, bounces, background, two-sidedness (shadows, N, sampler and seed are set per run;
    /// antialiasing is forced to 1 so that light sampling is the only noise).
    pub base: RenderSettings,
    /// The light-sample budgets N.
    pub budgets: Vec<u32>,
    /// The samplers compared.
    pub samplers: Vec<LightSampler>,
    /// Seeds per (sampler, N).
    pub seeds: u32,
    /// Stratified points per light in each of the two halves of the converged reference.
    pub reference_samples: u32,
    /// Points per light per hit for the penumbra mask.
    pub mask_samples: u32,
    /// The N whose per-pixel error maps are drawn.
    pub heatmap_n: u32,
}

impl StudyConfig {
    /// The command's defaults: N = 1, 4, 16, 64, 256, every sampler, 8 seeds, at 128×128.
    pub fn standard(base: RenderSettings) -> Self {
        StudyConfig {
            base: RenderSettings {
                aa_samples: 1,
                ..base
            },
            budgets: vec![1, 4, 16, 64, 256],
            samplers: LightSampler::ALL.to_vec(),
            seeds: 8,
            reference_samples: 4096,
            mask_samples: 1024,
            heatmap_n: 16,
        }
    }

    /// The settings of one study render: soft shadows, `n` points of `sampler`, `seed`, 1 aa
    /// sample (also used by `benches/variance.rs`, so the bench renders what the study does).
    pub fn run_settings(&self, sampler: LightSampler, n: u32, seed: u32) -> RenderSettings {
        RenderSettings {
            shadows: ShadowMode::Soft,
            shadow_samples: n,
            sampler,
            seed,
            aa_samples: 1,
            ..self.base.clone()
        }
    }
}

/// The converged reference and an estimate of its own error.
pub struct Converged {
    /// Mean of the two halves.
    pub film: Film,
    /// Per-pixel error variance of `film`, (A − B)²/4 averaged over channels.
    pub noise: Vec<f32>,
    /// True when it was read from the cache.
    pub cached: bool,
}

/// Renders (or reads from `cache`) the converged reference. `scene_id` must change when the
/// scene does (the CLI passes the bytes it parsed). An entry that fails its checks is reported
/// in one warning line and rendered again; a reference with values that are not finite is an
/// error, not a table of NaN.
pub fn converged_reference(
    scene: &Scene,
    scene_id: &[u8],
    config: &StudyConfig,
    render: &RenderFn,
    cache: Option<&Cache>,
    notice: &(dyn Fn(&str) + Sync),
) -> Result<Converged> {
    let half = |seed| config.run_settings(LightSampler::Stratified, config.reference_samples, seed);
    let settings = [half(0xa11c_e000), half(0xb0b0_0001)];
    let key = cache::key(scene_id, &settings);
    // Held until the entry is read, or rendered and written: concurrent shards render it once.
    let _lock = cache.and_then(|c| {
        let waiting = |path: &std::path::Path| {
            notice(&format!(
                "note: another process is rendering this converged reference; waiting for its lock {}",
                path.display()
            ))
        };
        c.lock(key, waiting)
            .map_err(|e| {
                notice(&format!(
                    "warning: {e:#}: rendering the reference without the lock, so another process may render it too"
                ))
            })
            .ok()
    });
    let (width, height) = (config.base.width, config.base.height);
    let lookup = cache.map_or(cache::Lookup::Miss, |c| c.read(key, width, height));
    let cached = matches!(lookup, cache::Lookup::Hit(_));
    let [a, b] = match lookup {
        cache::Lookup::Hit(films) => films,
        miss => {
            if let (cache::Lookup::Invalid(what), Some(c)) = (&miss, cache) {
                notice(&format!(
                    "warning: ignoring the cache entry {}: {what}; rendering the reference again",
                    c.entry_path(key).display()
                ));
            }
            let films = [render(scene, &settings[0]).0, render(scene, &settings[1]).0];
            let bad: usize = films.iter().map(Film::non_finite_pixels).sum();
            if bad > 0 {
                bail!(
                    "{}: the converged reference has {bad} pixels that are not finite: expected \
                     finite light everywhere, so there is nothing to measure the errors against",
                    scene.source
                );
            }
            if let Some(c) = cache
                && let Err(e) = c.write(key, &films)
            {
                notice(&format!(
                    "warning: cannot cache the reference in {}: {e:#}",
                    c.entry_path(key).display()
                ));
            }
            films
        }
    };
    let (pixels, noise) = (a.pixels.iter().zip(&b.pixels))
        .map(|(&x, &y)| ((x + y) * 0.5, ((x - y) * (x - y)).element_sum() / 12.0))
        .unzip();
    Ok(Converged {
        film: Film { pixels, ..a },
        noise,
        cached,
    })
}

/// The three regions a study reports, in `ALL` order: `region as usize` indexes the per-region
/// arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Region {
    /// Every pixel.
    Whole,
    /// Pixels with a partly visible light on their path.
    Penumbra,
    /// Pixels that see every light fully.
    Lit,
}

impl Region {
    /// All regions in report order.
    pub const ALL: [Region; 3] = [Region::Whole, Region::Penumbra, Region::Lit];
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        ["whole", "penumbra", "lit"][self as usize]
    }
}

/// `items` without repeats, in first-seen order.
pub(crate) fn unique<T: PartialEq>(items: impl IntoIterator<Item = T>) -> Vec<T> {
    let mut out = Vec::new();
    for x in items {
        if !out.contains(&x) {
            out.push(x);
        }
    }
    out
}

/// One line of the results: a (sampler, N, region).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    /// Sampler name.
    #[serde(deserialize_with = "sampler_name")]
    pub sampler: SamplerName,
    /// Light samples per light.
    pub n: u32,
    /// Region.
    pub region: Region,
    /// Error statistics over the K seeds.
    #[serde(flatten)]
    pub stats: ErrorStats,
    /// 95% interval of `mse` (bootstrap over seeds); None with fewer than two seeds.
    pub mse_interval: Option<[f64; 2]>,
    /// The sampler draws the same points whatever the seed at this N ([`deterministic`]), or
    /// its images did not vary across seeds: the error is bias, and the point is left out of
    /// the slope and matching-budget fits.
    pub excluded_from_fit: bool,
    /// Median seconds per image over the K timed renders.
    pub seconds: f64,
    /// 95% interval of `seconds` (the median's sign-test interval); None below 6 seeds.
    pub seconds_interval: Option<[f64; 2]>,
    /// Rays per image (all kinds).
    pub rays: u64,
    /// Rays per second at the median time.
    pub rays_per_second: f64,
    /// 1 / (MSE × seconds): higher is better.
    pub efficiency: f64,
    /// 95% interval of `efficiency` (bootstrap over seeds of mean MSE and median time).
    pub efficiency_interval: Option<[f64; 2]>,
    /// Random's MSE over this one at the same N and region: how many times less error than
    /// random (None without random).
    pub error_reduction: Option<f64>,
    /// 95% interval of `error_reduction` (bootstrap over seeds, the same seeds for both).
    pub error_reduction_interval: Option<[f64; 2]>,
    /// `efficiency` over random's at the same N and region (None without random).
    pub efficiency_vs_random: Option<f64>,
    /// 95% interval of `efficiency_vs_random`, resampling the same seeds for both samplers
    /// (their renders were timed in the same rounds, so a slow round slows both).
    pub efficiency_vs_random_interval: Option<[f64; 2]>,
    /// Where the error sits in screen space: its spectrum, its low band and its low-pass
    /// error (`perceived.rs`).
    pub perceived: perceived::Perceived,
    /// The host whose clock measured `seconds` and the figures made from it.
    pub host: String,
    /// Per seed (seeds 1..=K): MSE.
    #[serde(skip)]
    pub seed_mse: Vec<f64>,
    /// Per seed: mean signed error.
    #[serde(skip)]
    pub seed_bias: Vec<f64>,
    /// Per seed: seconds for its image.
    #[serde(skip)]
    pub seed_seconds: Vec<f64>,
}

/// A sampler's name (an alias, so that serde's derive does not take the field for a borrow of
/// the input and tie rows to a `'static` input).
pub(crate) type SamplerName = &'static str;

/// A sampler's name as the `&'static str` a [`Row`] holds.
fn sampler_name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<&'static str, D::Error> {
    LightSampler::deserialize(d).map(LightSampler::name)
}

/// Everything a study found.
pub struct StudyResult {
    /// The configuration.
    pub config: StudyConfig,
    /// Where the scene came from.
    pub scene: String,
    /// Engine used.
    pub engine: String,
    /// Worker threads the renders ran on.
    pub threads: usize,
    /// Pixels per region, the reference's own MSE per region, and whether it was cached.
    pub facts: jobs::CaseFacts,
    /// One row per (sampler, N, region).
    pub rows: Vec<Row>,
    /// One slope per (sampler, region).
    pub slopes: Vec<Slope>,
    /// One per (sampler other than random, region), when random was studied.
    pub matching: Vec<Matching>,
    /// Per-sampler per-pixel MSE at `heatmap_n`.
    pub heatmaps: Vec<(LightSampler, Vec<f32>)>,
    /// Per (sampler, N): the warm-up render (seed 0), tone-mapped, for the contact sheet.
    pub thumbnails: Vec<(LightSampler, u32, image::RgbImage)>,
}

/// Runs the study of one scene in this process: the reference and masks, every job, then the
/// figures across them. `progress` counts estimated rays.
pub fn run_study(
    scene: &Scene,
    scene_id: &[u8],
    config: &StudyConfig,
    engine: &str,
    render: &RenderFn,
    cache: Option<&Cache>,
    progress: &Progress,
) -> Result<StudyResult> {
    let all = jobs::case_jobs(0, config);
    let lights = scene.lights.len();
    let total: f64 = all.iter().map(|j| jobs::cost(config, lights, j)).sum();
    let rays = progress.steps(total as u64, "converged reference and regions");
    let setup = jobs::Setup::new(scene, scene_id, config, render, cache, progress.notice)?;
    let progress = |done: f64, label: &str| rays.advance(done as u64, label);
    let host = crate::output::machine::hostname();
    let results = jobs::run_jobs(scene, config, &setup, &all, render, &host, &progress);
    let (threads, facts) = (rayon::current_num_threads(), setup.facts());
    let study = jobs::assemble(config, &scene.source, engine, threads, facts, results);
    Ok(study)
}

impl StudyResult {
    /// How many times the reference's own MSE lies below the smallest MSE measured in `region`.
    pub fn reference_margin(&self, region: Region) -> f64 {
        let smallest = self
            .rows
            .iter()
            .filter(|r| r.region == region && r.stats.mse > 0.0)
            .map(|r| r.stats.mse)
            .fold(f64::INFINITY, f64::min);
        smallest / self.facts.reference_mse[region as usize].max(1e-30)
    }

    /// The fitted slope of `sampler` in `region` and its 95% interval; None without a fit.
    pub fn slope(&self, sampler: LightSampler, region: Region) -> Option<(f64, Option<[f64; 2]>)> {
        let s = self
            .slopes
            .iter()
            .find(|s| s.sampler == sampler.name() && s.region == region)?;
        s.fit.map(|f| (f.slope, s.slope_interval))
    }
}
