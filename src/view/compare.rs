//! The comparison mode: two light samplers at the same budget (N points per light), side by
//! side, each with its per-pixel error against the converged reference as a heat map on one
//! shared scale, so "which light points?" is answered by looking. The machinery is the
//! variance study's (`variance::converged_reference`, `pixel_mse`, `error_stats`,
//! `penumbra_mask`, `plot::heat_images`) at a size that finishes in seconds.
//!
//! ```text
//! reference = converged_reference(stratified, 2 × reference_samples)     (no disk cache)
//! for each sampler: K renders (seeds 1..=K) at N points
//!     heat = pixel_mse(renders, reference); MSE whole and penumbra, mean ± standard error over seeds
//!     perceived = the error's spectrum, low band and blurred MSE (variance/figures/perceived.rs)
//! spectrum.png = both sides' spectra, one plot
//! ```

use super::http::ApiError;
use super::request::{Resolved, ViewSettings, in_range, parse_json};
use super::{keep, lock};
use crate::output::image_file::png_bytes;
use crate::render::film::{Film, ToneMap};
use crate::render::sampling::LightSampler;
use crate::render::scene::Scene;
use crate::stats::median;
use crate::variance::figures::perceived::{self, Perceived};
use crate::variance::report::{plot::heat_images, spectrum_plot};
use crate::variance::{StudyConfig, converged_reference, error_stats, penumbra_mask, pixel_mse};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use statrs::statistics::Statistics;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// How many comparisons are kept for their images.
pub(crate) const KEPT: usize = 4;
/// Points per light per hit for the penumbra mask.
const MASK_SAMPLES: u32 = 64;

/// What the page asks to compare.
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(crate) struct CompareRequest {
    /// Bounces, light model, camera, engine (size, shadows, sampler and seed are the
    /// comparison's own).
    pub settings: ViewSettings,
    pub samplers: [LightSampler; 2],
    /// The budget: points per light per hit, the same for both.
    pub n: u32,
    /// Renders (seeds) per sampler, for the heat map and the standard error.
    pub seeds: u32,
    /// The longer side of the images.
    pub size: u32,
    /// Stratified points per light in each half of the converged reference.
    pub reference_samples: u32,
}

/// What a request leaves out.
impl Default for CompareRequest {
    fn default() -> Self {
        CompareRequest {
            settings: ViewSettings::default(),
            samplers: [LightSampler::Random, LightSampler::Stratified],
            n: 4,
            seeds: 4,
            size: 64,
            reference_samples: 1024,
        }
    }
}

impl CompareRequest {
    /// Parses and range-checks a request body (an empty body is every default).
    pub(crate) fn parse(body: &[u8]) -> Result<CompareRequest, ApiError> {
        let r: CompareRequest = parse_json(body, "comparison")?;
        for (name, v, lo, hi) in [
            ("n", r.n, 1, 256),
            ("seeds", r.seeds, 2, 16),
            ("size", r.size, 8, 256),
            ("reference_samples", r.reference_samples, 16, 4096),
        ] {
            in_range(&format!("comparison: {name}"), v, lo, hi)?;
        }
        if r.reference_samples < 4 * r.n {
            return Err(ApiError::bad(format!(
                "comparison: reference_samples ({}) must be at least 4 × n ({}), or the reference is no better than what it measures",
                r.reference_samples, r.n
            )));
        }
        Ok(r)
    }
}

/// A mean over seeds and its standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub(crate) struct Estimate {
    pub mean: f64,
    /// Standard error of the mean (sample standard deviation / √K).
    pub se: f64,
}

impl Estimate {
    /// Of two or more values (a request asks for at least two seeds); NaN for fewer.
    fn of(values: &[f64]) -> Estimate {
        Estimate {
            mean: values.mean(),
            se: values.std_dev() / (values.len() as f64).sqrt(),
        }
    }
}

/// One sampler's side.
#[derive(Clone, Debug, Serialize)]
pub(crate) struct Side {
    pub sampler: LightSampler,
    /// URL of its first render (seed 1).
    pub image: String,
    /// URL of its heat map.
    pub heat: String,
    /// MSE per image over the whole image: mean ± standard error over the seeds.
    pub mse: Estimate,
    /// The same over the penumbra (pixels with a partly visible light on their path).
    pub mse_penumbra: Option<Estimate>,
    /// Mean signed error over everything, and its bound (`variance::bias_bound`: no bias
    /// expected within it).
    pub bias: [f64; 2],
    /// Median seconds per render.
    pub seconds: f64,
    /// Where the error sits over the whole image (the variance study's figures): the
    /// radially averaged spectrum, the low band's share, the MSE after blurs of 1 and 2
    /// pixels, over the seeds.
    pub perceived: Perceived,
}

/// What the page shows.
#[derive(Clone, Debug, Serialize)]
pub(crate) struct Comparison {
    /// Its id (for the image URLs).
    pub id: u64,
    pub width: u32,
    pub height: u32,
    /// Points per light per hit, for both samplers.
    pub n: u32,
    /// Renders per sampler.
    pub seeds: u32,
    /// Stratified points per light in each half of the reference.
    pub reference_samples: u32,
    /// The reference's own per-pixel error variance, averaged: should be far below the MSEs.
    pub reference_noise: f64,
    /// URL of the reference image.
    pub reference: String,
    /// The heat maps' shared scale, log10 of the per-pixel MSE at dark and at bright.
    pub heat_scale: Option<[f32; 2]>,
    /// Pixels in the penumbra.
    pub penumbra_pixels: usize,
    /// URL of the two sides' error spectra, one plot.
    pub spectrum: String,
    pub sides: Vec<Side>,
    /// Seconds for the whole comparison.
    pub seconds: f64,
}

/// An image of a comparison and its name in the URL.
type NamedPng = (String, Arc<Vec<u8>>);

/// Kept comparisons and their images.
#[derive(Default)]
pub(crate) struct Comparisons {
    next: std::sync::atomic::AtomicU64,
    kept: Mutex<VecDeque<(u64, Vec<NamedPng>)>>,
    /// Held while one runs: a second request gets 409 instead of halving the first one's speed.
    pub running: Mutex<()>,
}

impl Comparisons {
    /// The PNG `name` of comparison `id`.
    pub(crate) fn png(&self, id: u64, name: &str) -> Option<Arc<Vec<u8>>> {
        lock(&self.kept)
            .iter()
            .find(|(i, _)| *i == id)
            .and_then(|(_, imgs)| imgs.iter().find(|(n, _)| n == name))
            .map(|(_, png)| png.clone())
    }

    /// Runs a comparison on `pool`.
    pub(crate) fn run(
        &self,
        request: &CompareRequest,
        scene: &Scene,
        base: &Resolved,
        pool: &rayon::ThreadPool,
    ) -> Result<Comparison, ApiError> {
        let _running = self.running.try_lock().map_err(|_| {
            ApiError::status(
                409,
                "a comparison is already running: try again when it has finished",
            )
        })?;
        let start = Instant::now();
        let resolved = request.settings.resolve(base)?;
        let scene = super::renders::with_camera(scene, &resolved.camera);
        let (w, h) = (resolved.settings.width, resolved.settings.height);
        let longer = w.max(h) as f32;
        let base_settings = crate::render::settings::RenderSettings {
            width: ((w as f32 / longer * request.size as f32).round() as u32).max(1),
            height: ((h as f32 / longer * request.size as f32).round() as u32).max(1),
            ..resolved.settings.clone()
        };
        let config = StudyConfig {
            budgets: vec![request.n],
            samplers: request.samplers.to_vec(),
            seeds: request.seeds,
            reference_samples: request.reference_samples,
            mask_samples: MASK_SAMPLES,
            heatmap_n: request.n,
            ..StudyConfig::standard(base_settings)
        };
        let (wc, hc) = (config.base.width, config.base.height);
        let render = |s: &Scene, settings: &crate::render::settings::RenderSettings| {
            pool.install(|| resolved.engine.image(s, settings))
        };
        let internal = |e: anyhow::Error| ApiError::status(500, format!("{e:#}"));
        let encode = |img: &image::RgbImage| png_bytes(img).map(Arc::new).map_err(internal);
        let film_png = |film: &Film| encode(&film.to_rgb8(ToneMap::Clamp));
        let reference =
            converged_reference(&scene, b"raywave view", &config, &render, None, &|_| {})
                .map_err(internal)?;
        let regions = pool.install(|| penumbra_mask(&scene, &config.base, MASK_SAMPLES));
        let whole = regions.whole();
        let penumbra_pixels = regions.penumbra.iter().filter(|&&b| b).count();
        let id = self.next.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        let url = |name: &str| format!("/api/compare/{id}/{name}.png");
        let mut pngs = vec![("reference".to_string(), film_png(&reference.film)?)];
        let mut maps = Vec::new();
        let mut sides = Vec::new();
        for (&sampler, side_name) in request.samplers.iter().zip(["a", "b"]) {
            let mut films = Vec::new();
            let mut times = Vec::new();
            for k in 1..=request.seeds {
                let t = Instant::now();
                films.push(render(&scene, &config.run_settings(sampler, request.n, k)).0);
                times.push(t.elapsed().as_secs_f64());
            }
            let images: Vec<&[Vec3]> = films.iter().map(|f| f.pixels.as_slice()).collect();
            let per_seed = |mask: &[bool]| {
                let v: Vec<f64> = images
                    .iter()
                    .map(|img| {
                        error_stats(&[img], &reference.film.pixels, &reference.noise, mask).mse
                    })
                    .collect();
                Estimate::of(&v)
            };
            let all = error_stats(&images, &reference.film.pixels, &reference.noise, &whole);
            pngs.push((format!("image-{side_name}"), film_png(&films[0])?));
            maps.push(pixel_mse(&images, &reference.film.pixels));
            let (wu, hu) = (wc as usize, hc as usize);
            let perceived = perceived::measure(&images, &reference.film.pixels, wu, hu, &whole);
            sides.push(Side {
                sampler,
                image: url(&format!("image-{side_name}")),
                heat: url(&format!("heat-{side_name}")),
                mse: per_seed(&whole),
                mse_penumbra: (penumbra_pixels > 0).then(|| per_seed(&regions.penumbra)),
                bias: [all.bias, all.bias_bound],
                seconds: median(&times),
                perceived,
            });
        }
        let map_refs: Vec<&[f32]> = maps.iter().map(Vec::as_slice).collect();
        let (heat_imgs, heat_scale) = match heat_images(&map_refs, wc, hc) {
            Some((imgs, scale)) => (imgs, Some(scale)),
            None => (vec![image::RgbImage::new(wc, hc); 2], None),
        };
        for (img, name) in heat_imgs.iter().zip(["heat-a", "heat-b"]) {
            pngs.push((name.to_string(), encode(img)?));
        }
        let spectra: Vec<(LightSampler, &Perceived)> =
            sides.iter().map(|s| (s.sampler, &s.perceived)).collect();
        let spectrum =
            spectrum_plot::comparison_image(&spectra, request.n, (640, 400)).map_err(internal)?;
        pngs.push(("spectrum".to_string(), encode(&spectrum)?));
        let noise = reference.noise.iter().map(|&v| f64::from(v)).mean();
        keep(&self.kept, (id, pngs), KEPT);
        Ok(Comparison {
            id,
            width: wc,
            height: hc,
            n: request.n,
            seeds: request.seeds,
            reference_samples: request.reference_samples,
            reference_noise: noise,
            reference: url("reference"),
            heat_scale,
            penumbra_pixels,
            spectrum: url("spectrum"),
            sides,
            seconds: start.elapsed().as_secs_f64(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_checked() {
        let r = CompareRequest::parse(b"").unwrap();
        assert_eq!(r.samplers, [LightSampler::Random, LightSampler::Stratified]);
        assert_eq!((r.n, r.seeds, r.size), (4, 4, 64));
        for (body, expected) in [
            (&br#"{"n": 0}"#[..], "n must be in"),
            (br#"{"seeds": 1}"#, "seeds must be in"),
            (br#"{"samplers": ["random"]}"#, "invalid length"),
            (br#"{"n": 64, "reference_samples": 128}"#, "at least 4"),
            (br#"{"colour": 1}"#, "unknown field"),
        ] {
            let e = CompareRequest::parse(body).unwrap_err();
            assert!(e.message.contains(expected), "{}", e.message);
        }
    }

    #[test]
    fn the_estimate_is_mean_and_standard_error() {
        let e = Estimate::of(&[1.0, 3.0]);
        assert_eq!(e.mean, 2.0);
        // sample sd √2, over √2.
        assert!((e.se - 1.0).abs() < 1e-12);
    }
}
