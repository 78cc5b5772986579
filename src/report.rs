//! The `--stats-json` file of `raywave render`: one render's figures, with the machine, the
//! build and the settings. It shares [`Machine`], [`KindRates`] and [`StageFigure`] with
//! `raywave bench`'s records, so both describe a machine and a stage alike.

use crate::bench::record::{KindRates, StageFigure};
use crate::engine::Engine;
use crate::machine::Machine;
use crate::settings::RenderSettings;
use crate::stats::RayCounts;
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Everything `--stats-json` writes.
#[derive(Clone, Debug, Serialize)]
pub struct RenderRecord {
    /// raywave's version.
    pub raywave: &'static str,
    /// The machine (without its host name).
    pub machine: Machine,
    /// `raywave::simd_path()`.
    pub simd: &'static str,
    /// Worker threads.
    pub threads: usize,
    /// The engine that rendered.
    pub engine: Engine,
    /// Wavefront camera samples per tile (as given, whichever the engine).
    pub batch_size: u32,
    /// The scene.
    pub scene: SceneFigures,
    /// The settings the image was rendered with.
    pub settings: RenderSettings,
    /// Whose defaults filled which settings.
    pub defaults: DefaultsUsed,
    /// Wall-clock seconds of the render.
    pub seconds: f64,
    /// Rays and rays per second by kind: camera, shadow, reflection, total.
    pub rays: KindFigures,
    /// Per stage (`None` for the reference, which has no stages).
    pub stages: Option<Vec<StageFigure>>,
}

/// The scene's size, and the wavefront engine's BVH.
#[derive(Clone, Debug, Serialize)]
pub struct SceneFigures {
    /// File path, or `<built-in ...>`.
    pub source: String,
    /// Triangles after parsing.
    pub triangles: usize,
    /// Spheres.
    pub spheres: usize,
    /// Lights.
    pub lights: usize,
    /// Whether the wavefront engine built a mesh BVH (`None` for the reference).
    pub bvh: Option<bool>,
    /// How long that took.
    pub bvh_build_seconds: Option<f64>,
}

/// Whose defaults filled the settings no flag set.
#[derive(Clone, Debug, Serialize)]
pub struct DefaultsUsed {
    /// `raywave`, `lab` or `rpi`.
    pub from: &'static str,
    /// The settings they filled, as the summary names them.
    #[serde(rename = "for")]
    pub settings: Vec<&'static str>,
}

/// One kind's rays and rays per wall-clock second.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct KindFigure {
    /// Rays cast.
    pub rays: u64,
    /// Rays per wall-clock second.
    pub rays_per_second: f64,
}

/// [`KindFigure`] for each kind.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct KindFigures {
    /// Camera rays.
    pub camera: KindFigure,
    /// Shadow rays.
    pub shadow: KindFigure,
    /// Mirror rays.
    pub reflection: KindFigure,
    /// All rays.
    pub total: KindFigure,
}

impl KindFigures {
    /// The counts, and each divided by `seconds` as bench records do it ([`KindRates`]).
    pub fn new(counts: &RayCounts, seconds: f64) -> KindFigures {
        let rates = KindRates::new(counts, seconds);
        let figure = |rays, rays_per_second| KindFigure {
            rays,
            rays_per_second,
        };
        KindFigures {
            camera: figure(counts.camera, rates.camera),
            shadow: figure(counts.shadow, rates.shadow),
            reflection: figure(counts.reflection, rates.reflection),
            total: figure(counts.total(), rates.total),
        }
    }

    /// (kind, figure) in report order.
    pub fn rows(&self) -> [(&'static str, KindFigure); 4] {
        [
            ("camera", self.camera),
            ("shadow", self.shadow),
            ("reflection", self.reflection),
            ("total", self.total),
        ]
    }
}

impl RenderRecord {
    /// Writes the record as pretty JSON, whole or not at all. It goes through
    /// `serde_json::Value`, whose objects sort their keys: the files have always listed
    /// every object's keys alphabetically.
    pub fn write(&self, path: &Path) -> anyhow::Result<()> {
        let json = serde_json::to_value(self)?;
        crate::film::write_atomically(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &json)?;
            Ok(writeln!(w)?)
        })
    }

    /// [`RenderRecord::write`] with one more top-level entry, `key` (e.g. `mse_reference`,
    /// the render's error against `render --mse-reference`).
    pub fn write_with(
        &self,
        path: &Path,
        key: &str,
        value: serde_json::Value,
    ) -> anyhow::Result<()> {
        let mut json = serde_json::to_value(self)?;
        json[key] = value;
        crate::film::write_atomically(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &json)?;
            Ok(writeln!(w)?)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_keeps_its_keys_sorted_and_names_no_host() {
        let counts = RayCounts {
            camera: 4,
            shadow: 6,
            reflection: 2,
        };
        let record = RenderRecord {
            raywave: "0",
            machine: Machine {
                hostname: String::new(),
                ..Machine::current()
            },
            simd: "scalar",
            threads: 1,
            engine: Engine::Reference,
            batch_size: 8,
            scene: SceneFigures {
                source: "s".into(),
                triangles: 1,
                spheres: 0,
                lights: 0,
                bvh: None,
                bvh_build_seconds: None,
            },
            settings: RenderSettings::default(),
            defaults: DefaultsUsed {
                from: "raywave",
                settings: vec!["size"],
            },
            seconds: 2.0,
            rays: KindFigures::new(&counts, 2.0),
            stages: None,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.json");
        record.write(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let top: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("  \"") && !l.starts_with("   "))
            .map(|l| l.trim().split('"').nth(1).unwrap())
            .collect();
        let mut sorted = top.clone();
        sorted.sort_unstable();
        assert_eq!(top, sorted);
        assert!(!text.contains("hostname"));
        assert!(text.contains("\"for\": [\n      \"size\"\n    ]"), "{text}");
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(json["rays"]["total"]["rays"], 12);
        assert_eq!(json["rays"]["shadow"]["rays_per_second"], 3.0);
        assert_eq!(json["engine"], "reference");
        assert!(json["stages"].is_null() && json["scene"]["bvh"].is_null());
    }
}
