//! The light-sampling study behind `raywave variance`: for each sampler and budget N, K seeded
//! renders against a converged reference, reported over the whole image, the penumbra and the
//! fully lit region.
//!
//! ```text
//! reference = mean of two independent stratified renders at N_ref   (cached on disk)
//! noise(ref) ≈ (A − B)² / 4 per pixel                                   (checked below the errors)
//! regions   = penumbra_mask(scene)                                      (dense stratified visibility)
//! for sampler, for N, for seed k < K: image_k = render(N, sampler, seed k)
//!     MSE, bias (with bound), variance across seeds, time, rays/s, 1/(MSE·time)   per region
//! slope of log MSE against log N                                        per sampler and region
//! ```

pub mod cache;
pub mod command;
pub mod mask;
pub mod plot;
pub mod stats;

use crate::film::Film;
use crate::sampling::LightSampler;
use crate::scene::Scene;
use crate::settings::{RenderSettings, ShadowMode};
use crate::stats::RayCounts;
use anyhow::{Context, Result, bail};
use glam::Vec3;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use cache::Cache;
pub use mask::{Regions, penumbra_mask};
pub use stats::{ErrorStats, LogLogFit, error_stats, loglog_fit, pixel_mse};

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
                eprintln!(
                    "warning: ignoring the cache entry {}: {what}; rendering the reference again",
                    c.entry_path(key).display()
                );
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
                eprintln!(
                    "warning: cannot cache the reference in {}: {e:#}",
                    c.entry_path(key).display()
                );
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
    /// Median seconds per image over the K seeds.
    pub seconds: f64,
    /// Rays per image (all kinds).
    pub rays: u64,
    /// Rays per second.
    pub rays_per_second: f64,
    /// 1 / (MSE × seconds): higher is better.
    pub efficiency: f64,
}

/// The fitted slope for a (sampler, region).
#[derive(Clone, Debug, Serialize)]
pub struct Slope {
    /// Sampler name.
    pub sampler: &'static str,
    /// Region.
    pub region: Region,
    /// The fit (None with fewer than two budgets with non-zero MSE).
    pub fit: Option<LogLogFit>,
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
    /// Per-sampler per-pixel MSE at `heatmap_n` (not serialised).
    #[serde(skip)]
    pub heatmaps: Vec<(LightSampler, Vec<f32>)>,
}

/// Runs the study. `progress` is called after each render with a short label.
pub fn run_study(
    scene: &Scene,
    scene_id: &[u8],
    config: &StudyConfig,
    engine: &str,
    render: &RenderFn,
    cache: Option<&Cache>,
    progress: &dyn Fn(&str),
) -> Result<StudyResult> {
    let reference = converged_reference(scene, scene_id, config, render, cache)?;
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
    let mut rows = Vec::new();
    let mut heatmaps = Vec::new();
    for &sampler in &config.samplers {
        for &n in &config.budgets {
            let mut films = Vec::new();
            let mut times = Vec::new();
            let mut rays = 0u64;
            for k in 0..config.seeds {
                let settings = config.run_settings(sampler, n, k + 1);
                let start = Instant::now();
                let (film, counts) = render(scene, &settings);
                times.push(start.elapsed().as_secs_f64());
                rays += counts.total();
                films.push(film);
                progress(&format!("{} N={n} seed {}", sampler.name(), k + 1));
            }
            let seconds = crate::statistics::median(&times);
            let rays = rays / config.seeds.max(1) as u64;
            let images: Vec<&[Vec3]> = films.iter().map(|f| f.pixels.as_slice()).collect();
            for (region, mask) in Region::ALL.iter().zip(&masks) {
                let stats = error_stats(&images, &reference.film.pixels, &reference.noise, mask);
                rows.push(Row {
                    sampler: sampler.name(),
                    n,
                    region: *region,
                    stats,
                    seconds,
                    rays,
                    rays_per_second: rays as f64 / seconds.max(1e-12),
                    efficiency: if stats.mse > 0.0 {
                        1.0 / (stats.mse * seconds.max(1e-12))
                    } else {
                        f64::INFINITY
                    },
                });
            }
            if n == config.heatmap_n {
                heatmaps.push((sampler, pixel_mse(&images, &reference.film.pixels)));
            }
        }
    }
    let slopes = config
        .samplers
        .iter()
        .flat_map(|&sampler| {
            let rows = &rows;
            Region::ALL.iter().map(move |&region| {
                let pts: Vec<(f64, f64)> = rows
                    .iter()
                    .filter(|r| r.sampler == sampler.name() && r.region == region)
                    .map(|r| (r.n as f64, r.stats.mse))
                    .collect();
                Slope {
                    sampler: sampler.name(),
                    region,
                    fit: loglog_fit(&pts),
                }
            })
        })
        .collect();
    Ok(StudyResult {
        config: config.clone(),
        scene: scene.source.clone(),
        engine: engine.to_string(),
        region_pixels,
        reference_mse,
        reference_cached: reference.cached,
        rows,
        slopes,
        heatmaps,
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

    /// The N at which `sampler`'s fitted MSE in `region` equals random sampling's fitted MSE
    /// at `random_n` (the lab's question: what matches 150 random points?). None without fits.
    pub fn matching_budget(
        &self,
        sampler: LightSampler,
        region: Region,
        random_n: f64,
    ) -> Option<f64> {
        let fit = |name: &str| {
            self.slopes
                .iter()
                .find(|s| s.sampler == name && s.region == region)
                .and_then(|s| s.fit)
        };
        let random = fit(LightSampler::Random.name())?;
        let other = fit(sampler.name())?;
        let target = random.intercept + random.slope * random_n.log10();
        (other.slope < 0.0).then(|| 10f64.powf((target - other.intercept) / other.slope))
    }

    /// A readable report: one table per region, the slopes, and the checks.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "variance study: {} at {}×{}, {} bounces, {} seeds per point, engine {}",
            self.scene,
            self.config.base.width,
            self.config.base.height,
            self.config.base.bounces,
            self.config.seeds,
            self.engine
        );
        for (i, region) in Region::ALL.iter().enumerate() {
            if self.region_pixels[i] == 0 {
                let _ = writeln!(
                    s,
                    "\n{}: no pixels in this region, nothing measured",
                    region.name()
                );
                continue;
            }
            let _ = writeln!(
                s,
                "\n{} ({} pixels; reference MSE {:.2e}, {:.0}× below the smallest measured)",
                region.name(),
                self.region_pixels[i],
                self.reference_mse[i],
                self.reference_margin(*region)
            );
            let _ = writeln!(
                s,
                "  {:<11} {:>5} {:>10} {:>11} {:>10} {:>10} {:>9} {:>8} {:>11}",
                "sampler",
                "N",
                "MSE",
                "bias",
                "±bound",
                "variance",
                "ms/image",
                "Mrays/s",
                "1/(MSE·s)"
            );
            for r in self.rows.iter().filter(|r| r.region == *region) {
                let _ = writeln!(
                    s,
                    "  {:<11} {:>5} {:>10.3e} {:>11.2e} {:>10.2e} {:>10.3e} {:>9.1} {:>8.2} {:>11.3e}{}",
                    r.sampler,
                    r.n,
                    r.stats.mse,
                    r.stats.bias,
                    r.stats.bias_bound,
                    r.stats.variance,
                    r.seconds * 1e3,
                    r.rays_per_second / 1e6,
                    r.efficiency,
                    if r.stats.bias.abs() > r.stats.bias_bound {
                        "  BIASED?"
                    } else {
                        ""
                    }
                );
            }
        }
        let _ = writeln!(s, "\nslope of log MSE against log N:");
        let _ = writeln!(
            s,
            "  {:<11} {:>8} {:>9} {:>8}",
            "sampler", "whole", "penumbra", "lit"
        );
        for sampler in &self.config.samplers {
            let slope = |region: Region| {
                self.slopes
                    .iter()
                    .find(|sl| sl.sampler == sampler.name() && sl.region == region)
                    .and_then(|sl| sl.fit)
                    .map(|f| format!("{:.3}", f.slope))
                    .unwrap_or_else(|| "-".into())
            };
            let _ = writeln!(
                s,
                "  {:<11} {:>8} {:>9} {:>8}",
                sampler.name(),
                slope(Region::Whole),
                slope(Region::Penumbra),
                slope(Region::Lit)
            );
        }
        if self.config.samplers.contains(&LightSampler::Random) {
            let _ = writeln!(
                s,
                "\nbudget matching the MSE of 150 random points (the lab's choice), from the fits \
                 (lab's fit includes its biased N = 1 point):"
            );
            for sampler in self
                .config
                .samplers
                .iter()
                .filter(|&&x| x != LightSampler::Random)
            {
                let n = |region| {
                    self.matching_budget(*sampler, region, 150.0)
                        .map(|n| format!("{n:.0}"))
                        .unwrap_or_else(|| "-".into())
                };
                let _ = writeln!(
                    s,
                    "  {:<11} {:>8} {:>9} {:>8}",
                    sampler.name(),
                    n(Region::Whole),
                    n(Region::Penumbra),
                    n(Region::Lit)
                );
            }
        }
        s
    }

    /// The rows as CSV.
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "sampler,n,region,pixels,mse,bias,bias_bound,variance,seconds,rays,rays_per_second,efficiency\n",
        );
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{},{},{},{},{:e},{:e},{:e},{:e},{:e},{},{:e},{:e}",
                r.sampler,
                r.n,
                r.region.name(),
                r.stats.pixels,
                r.stats.mse,
                r.stats.bias,
                r.stats.bias_bound,
                r.stats.variance,
                r.seconds,
                r.rays,
                r.rays_per_second,
                r.efficiency
            );
        }
        s
    }

    /// Writes table.txt, results.csv, results.json, mse.png and the heat maps into `dir`;
    /// returns the paths written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut written = Vec::new();
        let text = |name: &str, body: String, written: &mut Vec<PathBuf>| -> Result<()> {
            let path = dir.join(name);
            crate::film::write_atomically(&path, |w| {
                std::io::Write::write_all(w, body.as_bytes())?;
                Ok(())
            })?;
            written.push(path);
            Ok(())
        };
        text("table.txt", self.table(), &mut written)?;
        text("results.csv", self.csv(), &mut written)?;
        text(
            "results.json",
            serde_json::to_string_pretty(self)?,
            &mut written,
        )?;
        let plot_path = dir.join("mse.png");
        plot::mse_plot(self, &plot_path)?;
        written.push(plot_path);
        written.extend(plot::heatmaps(self, dir)?);
        Ok(written)
    }
}
