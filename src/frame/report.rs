//! What a render prints once the frame is rendered: the summary and the `--stats` tables, from
//! its `--stats-json` record, and its error against `--mse-reference`.

use super::Outcome;
use crate::diff::{self, Encoding, FileInfo, Image, Region};
use crate::output::terminal::table_line;
use crate::render::film::{Film, ToneMap};
use crate::render::quote::escape;
use crate::render::settings::options::BackgroundSource;
use crate::render::settings::{LightModel, ShadowMode};
use anyhow::Result;
use image::RgbImage;
use std::fmt::Write as _;
use std::path::Path;

impl Outcome {
    /// The summary printed after a render: engine, scene, settings, rays and time.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        let (scene, effective, rec) = (&self.scene, &self.effective, &self.record);
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
            rec.raywave,
            rec.engine.name(),
            rec.simd,
            rec.threads
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
        let (kinds, total) = (&rec.rays.kinds, &rec.rays.total);
        let _ = writeln!(
            out,
            "rays    {} total: {} camera, {} shadow, {} reflection",
            total.rays, kinds.camera.rays, kinds.shadow.rays, kinds.reflection.rays
        );
        let _ = writeln!(
            out,
            "time    {:.3} s, {:.2} Mrays/s",
            rec.seconds,
            total.rays_per_second / 1e6
        );
        out
    }

    /// The `--stats` tables: rays by kind (each kind over the thread-time of its own work, the
    /// total over the wall clock), then (wavefront) the BVH build and each stage.
    pub fn stats_table(&self) -> String {
        let (mut out, rec) = (String::new(), &self.record);
        let kinds = &rec.rays;
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
        match rec.instrumented_seconds {
            Some(pass) => {
                let _ = writeln!(
                    out,
                    "kinds timed by a second pass with timers: {pass:.3} s against the render's \
                     {:.3} s ({:+.1}%); the render itself had no timers",
                    rec.seconds,
                    (pass / rec.seconds.max(1e-9) - 1.0) * 100.0
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
        if let Some(build) = rec.scene.bvh_build_seconds {
            let _ = writeln!(out, "bvh build {build:.3} s");
        }
        if let Some(path) = self.shadow_path {
            let _ = writeln!(out, "shadow path {}: {}", path.name(), path.describe());
        }
        if let Some(t) = &rec.traversal {
            let line = |cells: [&str; 5]| table_line(&[-12, 14, 14, 14, 14], cells);
            let header = ["traversal", "rays", "nodes/ray", "leaves/ray", "tests/ray"];
            let _ = writeln!(out, "{}", line(header));
            for (kind, f) in t.kinds.iter() {
                let per_ray = [f.nodes_per_ray, f.leaves_per_ray, f.primitive_tests_per_ray];
                let [nodes, leaves, tests] = per_ray.map(|x| or_dash(x, 1.0, 2));
                let cells = [kind.name(), &f.rays.to_string(), &nodes, &leaves, &tests];
                let _ = writeln!(out, "{}", line(cells));
            }
            let _ = writeln!(
                out,
                "traversal counted by a second pass: {:.3} s; the render timed above counted nothing \
                 (tests: triangles of the leaves visited, spheres, and without a BVH every primitive)",
                t.counted_seconds
            );
        }
        if let Some(stages) = &rec.stages {
            row(
                &mut out,
                [&"stage", &"rays", &"thread-s", &"Mrays/thread-s"],
            );
            for stage in stages {
                let seconds = format!("{:.4}", stage.thread_seconds);
                let rate = format!("{:.2}", stage.rays_per_thread_second / 1e6);
                row(&mut out, [&stage.stage, &stage.rays, &seconds, &rate]);
            }
        }
        out
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
