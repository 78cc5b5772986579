//! What a render prints and records once the frame is rendered: the summary, the
//! `--stats` tables and the `--stats-json` record, from what the render measured.

use super::Outcome;
use crate::diff::{self, Encoding, FileInfo, Image, Region};
use crate::output::bench_record::KindFigures;
use crate::output::machine::Machine;
use crate::output::render_record::{DefaultsUsed, KindTiming, RenderRecord, SceneFigures};
use crate::render::film::{Film, ToneMap};
use crate::render::quote::escape;
use crate::render::settings::options::BackgroundSource;
use crate::render::settings::{LightModel, ShadowMode};
use crate::render::wavefront::shadow::ShadowPath;
use anyhow::Result;
use image::RgbImage;
use std::fmt::Write as _;
use std::path::Path;

impl Outcome {
    /// Rays by kind, each kind per thread-second of its work, the total per wall-clock second,
    /// as the JSON gives them.
    pub fn kinds(&self) -> KindFigures {
        KindFigures::new(&self.stats, self.seconds)
    }

    /// The summary printed after a render: engine, scene, settings, rays and time.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        let (scene, effective) = (&self.scene, &self.effective);
        let s = &effective.settings;
        let shadows = match s.shadows {
            ShadowMode::Off => "off (every light visible)".to_string(),
            ShadowMode::Hard => "hard (light centroids)".to_string(),
            ShadowMode::Soft => format!(
                "soft, {} {} points per light",
                s.shadow_samples,
                s.sampler.name()
            ),
        };
        let _ = writeln!(
            out,
            "raywave {} · engine {} · simd {} · {} thread(s)",
            env!("CARGO_PKG_VERSION"),
            self.engine.name(),
            self.simd,
            self.threads
        );
        let rings = match scene.ring_count {
            0 => String::new(),
            n => format!("; {n} ring(s) cut into faces"),
        };
        let _ = writeln!(
            out,
            "scene   {}: {} faces ({} triangles{rings}), {} spheres, {} light(s), {} camera",
            scene.source,
            scene.face_count,
            scene.triangles.len(),
            scene.spheres.len(),
            scene.lights.len(),
            if scene.camera_from_file {
                "file"
            } else {
                "lab default"
            }
        );
        for t in &scene.textures {
            let outside = if t.outside_folder {
                " (outside the scene file's folder)"
            } else {
                ""
            };
            let _ = writeln!(
                out,
                "texture {}: {}×{} texels from {}{outside}",
                escape(&t.name),
                t.width,
                t.height,
                escape(&t.path.display().to_string())
            );
        }
        let _ = writeln!(
            out,
            "render  {}×{}, {} bounces, shadows {shadows}, {} aa sample(s), seed {}, {} faces",
            s.width,
            s.height,
            s.bounces,
            s.aa_samples,
            s.seed,
            if s.two_sided {
                "two-sided"
            } else {
                "one-sided"
            }
        );
        let model = match s.light_model {
            LightModel::Lab => "lab (no fall-off)",
            LightModel::Rpi => "rpi (divided by π·d²)",
        };
        let background = match effective.background {
            BackgroundSource::Flag => "flag",
            BackgroundSource::Scene => "scene",
            BackgroundSource::Defaults => "default",
        };
        let [r, g, b] = s.background;
        let [ar, ag, ab] = s.ambient;
        let _ = writeln!(
            out,
            "light   model {model}, ambient {ar} {ag} {ab}, background {r} {g} {b} ({background})"
        );
        let defaulted = if effective.defaulted.is_empty() {
            "none needed: flags set every setting".to_string()
        } else {
            format!(
                "{} (--defaults {}) for {}",
                effective.defaults.owner(),
                effective.defaults.name(),
                effective.defaulted.join(", ")
            )
        };
        let _ = writeln!(out, "default {defaulted}");
        let counts = &self.stats.counts;
        let _ = writeln!(
            out,
            "rays    {} total: {} camera, {} shadow, {} reflection",
            counts.total(),
            counts.camera,
            counts.shadow,
            counts.reflection
        );
        let _ = writeln!(
            out,
            "time    {:.3} s, {:.2} Mrays/s",
            self.seconds,
            self.kinds().total.rays_per_second / 1e6
        );
        out
    }

    /// The `--stats` tables: rays by kind (each kind over the thread-time of its own work, the
    /// total over the wall clock), then (wavefront) the BVH build and each stage.
    pub fn stats_table(&self) -> String {
        let mut out = String::new();
        let kinds = self.kinds();
        // A row of the kind and stage tables: name, rays, seconds, rate.
        let row = |out: &mut String, cells: [&dyn std::fmt::Display; 4]| {
            let [name, rays, seconds, rate] = cells;
            let _ = writeln!(out, "{name:<12} {rays:>14} {seconds:>14} {rate:>20}");
        };
        let or_dash = |x: Option<f64>, scale: f64, digits: usize| {
            x.map_or("-".to_string(), |x| format!("{:.digits$}", x * scale))
        };
        row(&mut out, [&"kind", &"rays", &"thread-s", &"Mrays/thread-s"]);
        for (kind, figure) in kinds.kinds.iter() {
            let seconds = or_dash(figure.thread_seconds, 1.0, 4);
            let rate = or_dash(figure.rays_per_thread_second, 1e-6, 2);
            row(&mut out, [&kind.name(), &figure.rays, &seconds, &rate]);
        }
        let total = kinds.total;
        row(&mut out, [&"", &"", &"wall s", &"Mrays/s"]);
        let seconds = format!("{:.3}", total.seconds);
        let rate = format!("{:.2}", total.rays_per_second / 1e6);
        row(&mut out, [&"total", &total.rays, &seconds, &rate]);
        match self.instrumented_seconds {
            Some(pass) => {
                let _ = writeln!(
                    out,
                    "kinds timed by a second pass with timers: {pass:.3} s against the render's \
                     {:.3} s ({:+.1}%); the render itself had no timers",
                    self.seconds,
                    (pass / self.seconds.max(1e-9) - 1.0) * 100.0
                );
            }
            None => {
                let _ = writeln!(
                    out,
                    "kinds timed by the stage timers: camera = generate + intersect of camera rays, \
                     reflection = reflect + intersect of mirror rays, shadow = shadow; film in none"
                );
            }
        }
        if let Some(Some(build)) = self.bvh {
            let _ = writeln!(out, "bvh build {build:.3} s");
        }
        if let Some(path) = self.shadow_path {
            let _ = writeln!(out, "shadow path {}: {}", path.name(), path.describe());
        }
        if let Some(t) = &self.traversal {
            let _ = writeln!(
                out,
                "{:<12} {:>14} {:>14} {:>14} {:>14}",
                "traversal", "rays", "nodes/ray", "leaves/ray", "tests/ray"
            );
            for (kind, f) in t.kinds.iter() {
                let _ = writeln!(
                    out,
                    "{:<12} {:>14} {:>14} {:>14} {:>14}",
                    kind.name(),
                    f.rays,
                    or_dash(f.nodes_per_ray, 1.0, 2),
                    or_dash(f.leaves_per_ray, 1.0, 2),
                    or_dash(f.primitive_tests_per_ray, 1.0, 2)
                );
            }
            let _ = writeln!(
                out,
                "traversal counted by a second pass: {:.3} s; the render timed above counted nothing \
                 (tests: triangles of the leaves visited, spheres, and without a BVH every primitive)",
                t.counted_seconds
            );
        }
        if self.bvh.is_some() {
            row(
                &mut out,
                [&"stage", &"rays", &"thread-s", &"Mrays/thread-s"],
            );
            for stage in self.stats.stage_figures() {
                let seconds = format!("{:.4}", stage.thread_seconds);
                let rate = format!("{:.2}", stage.rays_per_thread_second / 1e6);
                row(&mut out, [&stage.stage, &stage.rays, &seconds, &rate]);
            }
        }
        out
    }

    /// The `--stats-json` record of a render.
    pub(super) fn record(&self) -> RenderRecord {
        let (scene, effective) = (&self.scene, &self.effective);
        RenderRecord {
            format: crate::output::bench_record::FORMAT,
            raywave: env!("CARGO_PKG_VERSION"),
            // The record has never named the host.
            machine: Machine {
                hostname: String::new(),
                ..Machine::current()
            },
            simd: self.simd,
            threads: self.threads,
            engine: self.engine,
            batch_size: self.batch_size,
            shadow_path: self.shadow_path.map(ShadowPath::name),
            scene: SceneFigures {
                source: scene.source.clone(),
                triangles: scene.triangles.len(),
                spheres: scene.spheres.len(),
                lights: scene.lights.len(),
                bvh: self.bvh.map(|b| b.is_some()),
                bvh_build_seconds: self.bvh.flatten(),
            },
            settings: effective.settings.clone(),
            defaults: DefaultsUsed {
                from: effective.defaults.name(),
                settings: effective.defaulted.clone(),
            },
            seconds: self.seconds,
            rays: self.kinds(),
            kinds_timed_by: match self.instrumented_seconds {
                Some(_) => KindTiming::InstrumentedPass,
                None => KindTiming::StageTimers,
            },
            instrumented_seconds: self.instrumented_seconds,
            stages: self.bvh.map(|_| self.stats.stage_figures()),
            traversal: self.traversal,
        }
    }
}

/// The render's error against `--mse-reference`, as text and as JSON: the linear image against
/// a float reference, the 8-bit image written (`rgb8`, else the film tone mapped) against an
/// 8- or 16-bit one, so that `raywave diff` on the files gives the same figures.
pub(super) fn reference_error(
    path: &Path,
    reference: &Image,
    film: &Film,
    rgb8: Option<&RgbImage>,
    tone: ToneMap,
) -> Result<(String, serde_json::Value)> {
    let (render, compared_as) = if reference.encoding == Encoding::Float {
        (Image::from_film(film.clone(), "render"), "linear floats")
    } else {
        let image = match rgb8 {
            Some(img) => Image::from_rgb8(img, "render"),
            None => Image::from_rgb8(&film.to_rgb8(tone), "render"),
        };
        (image, "the 8-bit image")
    };
    let region = Region::whole(render.film.width, render.film.height);
    let comparison = diff::compare(&render, reference, &region)?;
    let info = FileInfo::of(path, reference);
    let text = format!(
        "error of the render ({compared_as}) against --mse-reference {}\n{}",
        info.describe(),
        diff::text::table(&comparison)
    );
    let mut json = serde_json::to_value(&comparison)?;
    json["reference"] = serde_json::to_value(&info)?;
    json["compared_as"] = compared_as.into();
    Ok((text, json))
}
