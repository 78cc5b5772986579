//! A study's work cut into jobs, the unit that shards split and merges join: one job is the K
//! seeded renders (and the untimed warm-up) of one sampler at one budget in one case, and what
//! they measured. Everything a job reports depends on its own images only; what compares
//! samplers or budgets (ratios to random, slopes, matching budgets) is computed from the jobs'
//! rows afterwards (`assemble`), so that a study run in one process and the same study run in
//! shards and merged give the same figures, bit for bit.
//!
//! ```text
//! case   = (scene, size): its converged reference and region masks (Setup)
//! jobs   = for case: for N in budgets: for sampler in samplers: Job { case, N, sampler }
//! cost   = estimated rays of a job's K + 1 renders, the weight of the shard split
//! run    = per case and N, the jobs present: each sampler's warm-up, then seed after seed with
//!          the samplers rotated (timing drift falls on all alike), then each job's rows
//! ```

use crate::render::film::{Film, ToneMap};
use crate::render::sampling::LightSampler;
use crate::render::scene::Scene;
use crate::variance::figures::{fits, perceived};
use crate::variance::{Converged, Region, RenderFn, Row, StudyConfig, StudyResult};
use crate::variance::{converged_reference, deterministic, error_stats, penumbra_mask};
use crate::variance::{per_image_errors, pixel_mse};
use anyhow::Result;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// One job: the seeded renders of `sampler` at `n` points per light, in case `case`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Job {
    /// Index of the case (scene and size) in the study.
    pub case: usize,
    /// Points per light.
    pub n: u32,
    /// The sampler.
    pub sampler: LightSampler,
}

/// The jobs of case `case`, in the study's order: budgets outermost, samplers inside.
pub fn case_jobs(case: usize, config: &StudyConfig) -> Vec<Job> {
    config
        .budgets
        .iter()
        .flat_map(|&n| {
            config
                .samplers
                .iter()
                .map(move |&sampler| Job { case, n, sampler })
        })
        .collect()
}

/// The estimated rays of `job`'s K + 1 renders in a scene with `lights` lights: per pixel a
/// camera ray and N shadow rays per light (mirror bounces scale every job of a case alike).
pub fn cost(config: &StudyConfig, lights: usize, job: &Job) -> f64 {
    let pixels = config.base.width as f64 * config.base.height as f64;
    pixels * (config.seeds as f64 + 1.0) * (1.0 + lights as f64 * job.n as f64)
}

/// What the jobs of a case share: its converged reference and its region masks.
pub struct Setup {
    /// The converged reference.
    pub reference: Converged,
    /// Whole image, penumbra, lit.
    pub masks: [Vec<bool>; 3],
}

/// The facts of a case that every shard with a job of it finds alike.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseFacts {
    /// Pixels in each region.
    pub region_pixels: [usize; 3],
    /// The reference's own MSE per region.
    pub reference_mse: [f64; 3],
    /// True when the reference was read from the cache.
    pub reference_cached: bool,
}

impl Setup {
    /// Renders (or reads from `cache`) the reference, and computes the masks.
    pub fn new(
        scene: &Scene,
        scene_id: &[u8],
        config: &StudyConfig,
        render: &RenderFn,
        cache: Option<&crate::variance::Cache>,
        notice: &(dyn Fn(&str) + Sync),
    ) -> Result<Setup> {
        let reference = converged_reference(scene, scene_id, config, render, cache, notice)?;
        let regions = penumbra_mask(scene, &config.base, config.mask_samples);
        let masks = [regions.whole(), regions.penumbra, regions.lit];
        Ok(Setup { reference, masks })
    }

    /// Pixels per region and the reference's own MSE per region.
    pub fn facts(&self) -> CaseFacts {
        let noise = |i: usize| {
            let in_region = self.reference.noise.iter().zip(&self.masks[i]);
            in_region.filter_map(|(v, &inside)| inside.then_some(*v as f64))
        };
        let region_pixels: [usize; 3] = std::array::from_fn(|i| noise(i).count());
        let reference_mse = std::array::from_fn(|i| {
            noise(i).fold(0.0, |s, v| s + v) / region_pixels[i].max(1) as f64
        });
        CaseFacts {
            region_pixels,
            reference_mse,
            reference_cached: self.reference.cached,
        }
    }
}

/// A tone-mapped 8-bit image (a job's warm-up render, for the contact sheet).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Thumbnail {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// RGB bytes, rows from the top.
    #[serde(with = "serde_bytes")]
    pub rgb: Vec<u8>,
}

/// What one job measured: its rows as the report reads them, or as a part keeps them
/// ([`JobRecord`](super::job_record::JobRecord)).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobResult<R = Row> {
    /// The job.
    pub job: Job,
    /// One row per region, in `Region::ALL` order, without the figures relative to random.
    pub rows: Vec<R>,
    /// Per-pixel MSE when `job.n` is the study's heat-map budget.
    pub heatmap: Option<Vec<f32>>,
    /// The warm-up render (seed 0).
    pub thumbnail: Thumbnail,
}

impl<R> JobResult<R> {
    /// The same result with each row converted.
    pub fn convert<S: From<R>>(self) -> JobResult<S> {
        let rows = self.rows.into_iter().map(S::from).collect();
        let (job, heatmap, thumbnail) = (self.job, self.heatmap, self.thumbnail);
        JobResult {
            job,
            rows,
            heatmap,
            thumbnail,
        }
    }
}

/// The rows of `job` from its timed images: their seconds each, and rays per image.
fn rows_of(
    job: &Job,
    images: &[&[Vec3]],
    times: &[f64],
    rays: u64,
    setup: &Setup,
    host: &str,
) -> Vec<Row> {
    let (film, k) = (&setup.reference.film, images.len());
    let (seconds, lo, hi) = crate::stats::median_with_interval(times);
    let seconds_interval = (lo.is_finite() && hi.is_finite()).then_some([lo, hi]);
    let excluded_sampler = deterministic(job.sampler, job.n);
    let (width, height) = (film.width as usize, film.height as usize);
    Region::ALL
        .iter()
        .zip(&setup.masks)
        .map(|(region, mask)| {
            let stats = error_stats(images, &film.pixels, &setup.reference.noise, mask);
            let perceived = perceived::measure(images, &film.pixels, width, height, mask);
            let per = per_image_errors(images, &film.pixels, mask);
            let (seed_mse, seed_bias): (Vec<f64>, Vec<f64>) = per.into_iter().unzip();
            let mse_interval = fits::interval(k, |idx| fits::mean_at(&seed_mse, Some(idx)));
            let mut row = Row {
                sampler: job.sampler.name(),
                n: job.n,
                region: *region,
                stats,
                mse_interval,
                excluded_from_fit: excluded_sampler || (stats.pixels > 0 && stats.variance == 0.0),
                seconds,
                seconds_interval,
                rays,
                rays_per_second: rays as f64 / seconds.max(1e-12),
                efficiency: if stats.mse > 0.0 {
                    1.0 / (stats.mse * seconds.max(1e-12))
                } else {
                    f64::INFINITY
                },
                efficiency_interval: None,
                error_reduction: None,
                error_reduction_interval: None,
                efficiency_vs_random: None,
                efficiency_vs_random_interval: None,
                perceived,
                host: host.to_string(),
                seed_mse,
                seed_bias,
                seed_seconds: times.to_vec(),
            };
            row.efficiency_interval = fits::interval(k, |idx| fits::efficiency_at(&row, idx));
            row
        })
        .collect()
}

/// Runs `jobs` (all of one case, in `case_jobs` order) against `setup`. `progress` is told each
/// render's estimated rays (its job's cost over K + 1) and a label.
pub fn run_jobs(
    scene: &Scene,
    config: &StudyConfig,
    setup: &Setup,
    jobs: &[Job],
    render: &RenderFn,
    host: &str,
    progress: &dyn Fn(f64, &str),
) -> Vec<JobResult> {
    let lights = scene.lights.len();
    let mut out = Vec::new();
    for group in jobs.chunk_by(|a, b| a.n == b.n) {
        let n = group[0].n;
        let per_render = |job: &Job| cost(config, lights, job) / (config.seeds as f64 + 1.0);
        // Warm-up: caches, page tables and the thread pool reach their working state before
        // the first timed render; the images (seed 0, used by no timed render) are kept.
        let mut thumbnails = Vec::new();
        for job in group {
            let (film, _) = render(scene, &config.run_settings(job.sampler, n, 0));
            let image = film.to_rgb8(ToneMap::Clamp);
            thumbnails.push(Thumbnail {
                width: image.width(),
                height: image.height(),
                rgb: image.into_raw(),
            });
            let label = format!("{} N={n} warm-up", job.sampler.name());
            progress(per_render(job), &label);
        }
        let mut films: Vec<Vec<Film>> = vec![Vec::new(); group.len()];
        let mut times = vec![Vec::new(); group.len()];
        let mut rays = vec![0u64; group.len()];
        for k in 0..config.seeds {
            // Rotate the order per seed, so that no sampler always runs first (or after the
            // same one): slow drifts of the machine fall on every sampler alike.
            for j in 0..group.len() {
                let i = (j + k as usize) % group.len();
                let settings = config.run_settings(group[i].sampler, n, k + 1);
                let start = Instant::now();
                let (film, counts) = render(scene, &settings);
                times[i].push(start.elapsed().as_secs_f64());
                rays[i] += counts.total();
                films[i].push(film);
                let label = format!("{} N={n} seed {}", group[i].sampler.name(), k + 1);
                progress(per_render(&group[i]), &label);
            }
        }
        for (i, (job, thumbnail)) in group.iter().zip(thumbnails).enumerate() {
            let images: Vec<&[Vec3]> = films[i].iter().map(|f| f.pixels.as_slice()).collect();
            let rays = rays[i] / config.seeds.max(1) as u64;
            let rows = rows_of(job, &images, &times[i], rays, setup, host);
            let heatmap =
                (n == config.heatmap_n).then(|| pixel_mse(&images, &setup.reference.film.pixels));
            out.push(JobResult {
                job: *job,
                rows,
                heatmap,
                thumbnail,
            });
        }
    }
    out
}

/// The study of one case from its jobs' results (every job of the case, in any order): the
/// rows in report order, then the figures that compare samplers and budgets.
pub fn assemble(
    config: &StudyConfig,
    scene: &str,
    engine: &str,
    threads: usize,
    facts: CaseFacts,
    mut results: Vec<JobResult>,
) -> StudyResult {
    let samplers = &config.samplers;
    let position = |s: LightSampler| samplers.iter().position(|&x| x == s);
    let budget = |n: u32| config.budgets.iter().position(|&b| b == n);
    results.sort_by_key(|r| (position(r.job.sampler), budget(r.job.n)));
    let mut rows = Vec::new();
    let mut heatmaps = Vec::new();
    let mut thumbnails = Vec::new();
    for r in results {
        rows.extend(r.rows);
        if let Some(map) = r.heatmap {
            heatmaps.push((r.job.sampler, map));
        }
        let t = r.thumbnail;
        if let Some(image) = image::RgbImage::from_raw(t.width, t.height, t.rgb) {
            thumbnails.push((r.job.sampler, r.job.n, image));
        }
    }
    let k = config.seeds as usize;
    fits::ratios_to_random(&mut rows, k);
    perceived::low_band_vs_random(&mut rows, k);
    let slopes = fits::slopes(&rows, samplers, k);
    let matching = fits::matching(&rows, samplers, k);
    StudyResult {
        config: config.clone(),
        scene: scene.to_string(),
        engine: engine.to_string(),
        threads,
        facts,
        rows,
        slopes,
        matching,
        heatmaps,
        thumbnails,
    }
}
