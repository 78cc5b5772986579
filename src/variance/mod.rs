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
//!                (statistics::bootstrap_interval); time by the median's sign-test interval
//! ```

pub mod cache;
pub mod command;
pub(crate) mod figures;
pub(crate) mod fits;
pub mod mask;
pub mod perceived;
mod perceived_report;
pub(crate) mod plot;
pub mod report;
pub mod sheet;
pub mod spectrum;
pub mod spectrum_plot;

use crate::render::engine::Hooks;
use crate::render::film::Film;
use crate::render::film::ToneMap;
use crate::render::per_kind::RayCounts;
use crate::render::sampling::LightSampler;
use crate::render::scene::Scene;
use crate::render::settings::{RenderSettings, ShadowMode};
use anyhow::{Result, bail};
use glam::Vec3;
use serde::Serialize;
use std::time::Instant;

pub use cache::Cache;
pub use figures::{
    BIAS_FALSE_ALARM, ErrorStats, LogLogFit, bias_bound, deterministic, error_stats, loglog_fit,
    per_image_errors, pixel_mse,
};
pub use fits::{Matching, Slope, match_budget};
pub use mask::{Regions, penumbra_mask};

/// Renders one image: the engine is the caller's choice (the fastest one, normally).
pub type RenderFn<'a> = dyn Fn(&Scene, &RenderSettings) -> (Film, RayCounts) + Sync + 'a;

/// What to measure.
#[derive(Clone, Debug, Serialize)]
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
    /// The issue's defaults: N = 1, 4, 16, 64, 256, every sampler, 8 seeds, at 128×128.
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
    let halves = [0xa11c_e000u32, 0xb0b0_0001];
    let settings: Vec<RenderSettings> = halves
        .iter()
        .map(|&seed| config.run_settings(LightSampler::Stratified, config.reference_samples, seed))
        .collect();
    let key = cache::key(scene_id, &settings);
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
    let film = Film {
        width: a.width,
        height: a.height,
        pixels: a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(x, y)| (*x + *y) * 0.5)
            .collect(),
    };
    let noise = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(x, y)| ((*x - *y) * (*x - *y)).element_sum() / 12.0)
        .collect();
    Ok(Converged {
        film,
        noise,
        cached,
    })
}

/// The three regions a study reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
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
        match self {
            Region::Whole => "whole",
            Region::Penumbra => "penumbra",
            Region::Lit => "lit",
        }
    }
}

/// One line of the results: a (sampler, N, region).
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Sampler name.
    pub sampler: &'static str,
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

/// Everything a study found.
#[derive(Serialize)]
pub struct StudyResult {
    /// The configuration.
    pub config: StudyConfig,
    /// Where the scene came from.
    pub scene: String,
    /// Engine used.
    pub engine: String,
    /// Worker threads the renders ran on.
    pub threads: usize,
    /// Pixels in each region.
    pub region_pixels: [usize; 3],
    /// Mean error variance of the reference per region (its own MSE).
    pub reference_mse: [f64; 3],
    /// True when the reference came from the cache.
    pub reference_cached: bool,
    /// One row per (sampler, N, region).
    pub rows: Vec<Row>,
    /// One slope per (sampler, region).
    pub slopes: Vec<Slope>,
    /// One per (sampler other than random, region), when random was studied.
    pub matching: Vec<Matching>,
    /// Per-sampler per-pixel MSE at `heatmap_n` (not serialised).
    #[serde(skip)]
    pub heatmaps: Vec<(LightSampler, Vec<f32>)>,
    /// Per (sampler, N): the warm-up render (seed 0), tone-mapped, for the contact sheet.
    #[serde(skip)]
    pub thumbnails: Vec<(LightSampler, u32, image::RgbImage)>,
}

/// The rows of one (sampler, N): one per region.
struct Measured<'a> {
    sampler: LightSampler,
    n: u32,
    images: Vec<&'a [Vec3]>,
    times: Vec<f64>,
    rays: u64,
}

fn rows_of(m: &Measured, reference: &Converged, masks: &[Vec<bool>; 3]) -> Vec<Row> {
    let k = m.images.len();
    let (seconds, lo, hi) = crate::output::statistics::median_with_interval(&m.times);
    let seconds_interval = (lo.is_finite() && hi.is_finite()).then_some([lo, hi]);
    let excluded_sampler = deterministic(m.sampler, m.n);
    Region::ALL
        .iter()
        .zip(masks)
        .map(|(region, mask)| {
            let stats = error_stats(&m.images, &reference.film.pixels, &reference.noise, mask);
            let (width, height) = (
                reference.film.width as usize,
                reference.film.height as usize,
            );
            let perceived =
                perceived::measure(&m.images, &reference.film.pixels, width, height, mask);
            let per = per_image_errors(&m.images, &reference.film.pixels, mask);
            let seed_mse: Vec<f64> = per.iter().map(|e| e.0).collect();
            let seed_bias: Vec<f64> = per.iter().map(|e| e.1).collect();
            let mse_interval = fits::interval(k, |idx| fits::mean_at(&seed_mse, Some(idx)));
            let times = &m.times;
            let efficiency_interval = fits::interval(k, |idx| {
                let t: Vec<f64> = idx.iter().map(|&i| times[i]).collect();
                1.0 / (fits::mean_at(&seed_mse, Some(idx))
                    * crate::output::statistics::median(&t).max(1e-12))
            });
            Row {
                sampler: m.sampler.name(),
                n: m.n,
                region: *region,
                stats,
                mse_interval,
                excluded_from_fit: excluded_sampler || (stats.pixels > 0 && stats.variance == 0.0),
                seconds,
                seconds_interval,
                rays: m.rays,
                rays_per_second: m.rays as f64 / seconds.max(1e-12),
                efficiency: if stats.mse > 0.0 {
                    1.0 / (stats.mse * seconds.max(1e-12))
                } else {
                    f64::INFINITY
                },
                efficiency_interval,
                error_reduction: None,
                error_reduction_interval: None,
                efficiency_vs_random: None,
                efficiency_vs_random_interval: None,
                perceived,
                seed_mse,
                seed_bias,
                seed_seconds: m.times.clone(),
            }
        })
        .collect()
}

/// Runs the study. `progress` is called after each render with a short label.
pub fn run_study(
    scene: &Scene,
    scene_id: &[u8],
    config: &StudyConfig,
    engine: &str,
    render: &RenderFn,
    cache: Option<&Cache>,
    hooks: &Hooks,
) -> Result<StudyResult> {
    // The reference, the mask, then per sampler and N a warm-up render and K timed ones.
    let steps =
        2 + (config.samplers.len() * config.budgets.len()) as u64 * (config.seeds as u64 + 1);
    let done = std::cell::Cell::new(0u64);
    let progress = |label: &str| {
        done.set(done.get() + 1);
        (hooks.progress)(done.get(), steps, label);
    };
    (hooks.progress)(0, steps, "converged reference");
    let reference = converged_reference(scene, scene_id, config, render, cache, hooks.notice)?;
    progress("converged reference");
    let regions = penumbra_mask(scene, &config.base, config.mask_samples);
    progress("penumbra mask");
    let masks = [
        regions.whole(),
        regions.penumbra.clone(),
        regions.lit.clone(),
    ];
    let region_pixels = masks.clone().map(|m| m.iter().filter(|&&b| b).count());
    let reference_mse = masks.clone().map(|m| {
        let (sum, count) = reference
            .noise
            .iter()
            .zip(&m)
            .filter(|(_, in_region)| **in_region)
            .fold((0.0f64, 0usize), |(s, c), (v, _)| (s + *v as f64, c + 1));
        if count == 0 { 0.0 } else { sum / count as f64 }
    });
    let samplers = &config.samplers;
    let mut rows = Vec::new();
    let mut heatmaps = Vec::new();
    let mut thumbnails = Vec::new();
    for &n in &config.budgets {
        // Warm-up: caches, page tables and the thread pool reach their working state before
        // the first timed render; the images (seed 0, used by no timed render) are kept.
        for &sampler in samplers {
            let (film, _) = render(scene, &config.run_settings(sampler, n, 0));
            thumbnails.push((sampler, n, film.to_rgb8(ToneMap::Clamp)));
            progress(&format!("{} N={n} warm-up", sampler.name()));
        }
        let mut films: Vec<Vec<crate::render::film::Film>> = vec![Vec::new(); samplers.len()];
        let mut times = vec![Vec::new(); samplers.len()];
        let mut rays = vec![0u64; samplers.len()];
        for k in 0..config.seeds {
            // Rotate the order per seed, so that no sampler always runs first (or after the
            // same one): slow drifts of the machine fall on every sampler alike.
            for j in 0..samplers.len() {
                let i = (j + k as usize) % samplers.len();
                let settings = config.run_settings(samplers[i], n, k + 1);
                let start = Instant::now();
                let (film, counts) = render(scene, &settings);
                times[i].push(start.elapsed().as_secs_f64());
                rays[i] += counts.total();
                films[i].push(film);
                progress(&format!("{} N={n} seed {}", samplers[i].name(), k + 1));
            }
        }
        for (i, &sampler) in samplers.iter().enumerate() {
            let images: Vec<&[Vec3]> = films[i].iter().map(|f| f.pixels.as_slice()).collect();
            let measured = Measured {
                sampler,
                n,
                images,
                times: std::mem::take(&mut times[i]),
                rays: rays[i] / config.seeds.max(1) as u64,
            };
            rows.extend(rows_of(&measured, &reference, &masks));
            if n == config.heatmap_n {
                heatmaps.push((sampler, pixel_mse(&measured.images, &reference.film.pixels)));
            }
        }
    }
    // Report order: sampler, then N, then region (the rows were made N first).
    let position = |name: &str| samplers.iter().position(|s| s.name() == name);
    rows.sort_by_key(|r| {
        (
            position(r.sampler),
            config.budgets.iter().position(|&b| b == r.n),
            Region::ALL.iter().position(|&g| g == r.region),
        )
    });
    let k = config.seeds as usize;
    fits::ratios_to_random(&mut rows, k);
    perceived::low_band_vs_random(&mut rows, k);
    let slopes = fits::slopes(&rows, samplers, k);
    let matching = fits::matching(&rows, samplers, k);
    Ok(StudyResult {
        config: config.clone(),
        scene: scene.source.clone(),
        engine: engine.to_string(),
        threads: rayon::current_num_threads(),
        region_pixels,
        reference_mse,
        reference_cached: reference.cached,
        rows,
        slopes,
        matching,
        heatmaps,
        thumbnails,
    })
}

impl StudyResult {
    /// The smallest MSE measured in a region, to compare with the reference's own error.
    pub fn smallest_mse(&self, region: Region) -> f64 {
        self.rows
            .iter()
            .filter(|r| r.region == region && r.stats.mse > 0.0)
            .map(|r| r.stats.mse)
            .fold(f64::INFINITY, f64::min)
    }

    /// How many times the reference's own MSE lies below the smallest measured MSE, per region.
    pub fn reference_margin(&self, region: Region) -> f64 {
        let i = Region::ALL.iter().position(|&r| r == region).unwrap_or(0);
        self.smallest_mse(region) / self.reference_mse[i].max(1e-30)
    }
}
