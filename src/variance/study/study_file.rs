//! `raywave variance --study FILE.toml`: a study over scenes × sizes × samplers × budgets ×
//! seeds, written down once and run the same way by every shard. Its JSON Schema is
//! docs/schema/study.schema.json (described in docs/SAMPLING.md); every key is optional and
//! takes the command's default.
//!
//! ```toml
//! scenes = ["cornell_box.obj", "builtin"]   # relative to this file; "builtin": the lab's box
//! samplers = ["random", "stratified", "sobol"]
//! budgets = [1, 4, 16, 64, 256]
//! seeds = 16
//! sizes = [[128, 128], [256, 256]]
//! ```

use crate::render::engine::Engine;
use crate::render::sampling::LightSampler;
use crate::render::settings::LightModel;
use crate::variance::command::VarianceOptions;
use anyhow::{Context, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A whole number in `LO..=HI`, refused while the file is parsed, so that the error names
/// the line and column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(try_from = "i64")]
pub struct Ranged<const LO: u32, const HI: u32>(pub u32);

impl<const LO: u32, const HI: u32> TryFrom<i64> for Ranged<LO, HI> {
    type Error = String;
    fn try_from(v: i64) -> Result<Self, String> {
        if (i64::from(LO)..=i64::from(HI)).contains(&v) {
            return Ok(Ranged(v as u32));
        }
        Err(format!(
            "{v} is out of range: expected a whole number from {LO} to {HI}"
        ))
    }
}

impl<const LO: u32, const HI: u32> schemars::JsonSchema for Ranged<LO, HI> {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        format!("Ranged_{LO}_{HI}").into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({ "type": "integer", "minimum": LO, "maximum": HI })
    }
}

/// The study file: what to measure, and where.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StudyFile {
    /// Scene files, relative to the study file's directory; `"builtin"` is the built-in lab
    /// Cornell box with mirror spheres (a file of that name is `"./builtin"`). Default: the
    /// built-in box.
    #[serde(default)]
    pub scenes: Vec<String>,
    /// Light samplers compared. Default: every sampler.
    pub samplers: Option<Vec<LightSampler>>,
    /// Light-sample budgets N. Default: 1, 4, 16, 64, 256.
    pub budgets: Option<Vec<Ranged<1, 65536>>>,
    /// Seeds (independent renders) per sampler and budget. Default: 8.
    pub seeds: Option<Ranged<2, 1024>>,
    /// Image sizes, `[width, height]`: every scene is studied at every size. Default:
    /// `[[128, 128]]`.
    pub sizes: Option<Vec<[Ranged<1, 4096>; 2]>>,
    /// Mirror bounces. Default: 5.
    pub bounces: Option<Ranged<0, 64>>,
    /// Stratified points per light in each half of the converged reference. Default: 4096.
    pub reference_samples: Option<Ranged<1, 65536>>,
    /// Points per light per hit for the penumbra mask. Default: 1024.
    pub mask_samples: Option<Ranged<1, 65536>>,
    /// The budget whose heat maps are drawn (the nearest budget if it is not one). Default: 16.
    pub heatmap_n: Option<Ranged<1, 65536>>,
    /// How a light's colour reaches a point: `lab` or `rpi`. Default: `lab`.
    pub light_model: Option<LightModel>,
    /// The engine that renders the images: `wavefront` or `reference`. Default: `wavefront`.
    pub engine: Option<Engine>,
}

/// The JSON Schema of the study file (docs/schema/study.schema.json).
pub fn schema() -> String {
    let schema = schemars::generate::SchemaSettings::draft2020_12()
        .for_deserialize()
        .into_generator()
        .into_root_schema_for::<StudyFile>();
    serde_json::to_string_pretty(&schema).unwrap_or_default() + "\n"
}

/// Reads the study file at `path` into `options` (its cases, what is measured and the engine);
/// errors name the file, and the line and column where there is one.
pub fn read(path: &Path, options: &mut VarianceOptions) -> Result<()> {
    let shown = path.display();
    let bytes = crate::output::read_bounded(path, "a study file (TOML)", 1 << 20)?;
    let text = String::from_utf8(bytes)
        .with_context(|| format!("{shown}: expected a study file (TOML) in UTF-8"))?;
    let file: StudyFile = toml::from_str(&text).map_err(|e| {
        let place = e.span().map_or(String::new(), |span| {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            format!(":{line}")
        });
        anyhow::anyhow!("{shown}{place}: {}", e.message().trim_end())
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    options.scenes = file
        .scenes
        .iter()
        .map(|s| (s != "builtin").then(|| dir.join(s)))
        .collect::<Vec<Option<PathBuf>>>();
    for (name, scene) in file.scenes.iter().zip(&options.scenes) {
        if let Some(scene) = scene
            && !scene.is_file()
        {
            let quoted = format!("\"{name}\"");
            let line = text
                .lines()
                .position(|l| l.contains(&quoted))
                .map_or(String::new(), |i| format!(":{}", i + 1));
            anyhow::bail!(
                "{shown}{line}: scene {quoted} is not a file (looked for {}): expected a scene file, relative to the study file, or \"builtin\"",
                scene.display()
            );
        }
    }
    if let Some(v) = file.samplers {
        options.samplers = v;
    }
    if let Some(v) = file.budgets {
        options.budgets = v.into_iter().map(|r| r.0).collect();
    }
    if let Some(v) = file.sizes {
        options.sizes = v.into_iter().map(|[w, h]| [w.0, h.0]).collect();
    }
    options.seeds = file.seeds.map_or(options.seeds, |r| r.0);
    options.bounces = file.bounces.map_or(options.bounces, |r| r.0);
    options.reference_samples = file
        .reference_samples
        .map_or(options.reference_samples, |r| r.0);
    options.mask_samples = file.mask_samples.map_or(options.mask_samples, |r| r.0);
    options.heatmap_n = file.heatmap_n.map_or(options.heatmap_n, |r| r.0);
    options.light_model = file.light_model.unwrap_or(options.light_model);
    options.engine = file.engine.unwrap_or(options.engine);
    for (key, empty) in [
        ("samplers", options.samplers.is_empty()),
        ("budgets", options.budgets.is_empty()),
        ("sizes", options.sizes.is_empty()),
    ] {
        if empty {
            anyhow::bail!("{shown}: `{key}` is empty: expected at least one");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str) -> Result<VarianceOptions> {
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("study.toml");
        std::fs::write(&path, text)?;
        std::fs::write(dir.path().join("a.obj"), "")?;
        let mut options = VarianceOptions::default();
        read(&path, &mut options)?;
        Ok(options)
    }

    #[test]
    fn a_study_file_sets_what_it_names_and_leaves_the_rest_at_the_defaults() {
        let o = read_text(
            "scenes = [\"a.obj\", \"builtin\"]\nsamplers = [\"random\", \"sobol\"]\nbudgets = [2, 8]\nsizes = [[16, 8], [8, 8]]\nseeds = 3\n",
        )
        .unwrap();
        assert_eq!(o.scenes.len(), 2);
        assert!(o.scenes[0].as_ref().unwrap().ends_with("a.obj"));
        assert_eq!(o.scenes[1], None);
        assert_eq!(o.samplers, [LightSampler::Random, LightSampler::Sobol]);
        assert_eq!(
            (o.budgets, o.sizes, o.seeds),
            (vec![2, 8], vec![[16, 8], [8, 8]], 3)
        );
        assert_eq!(o.bounces, VarianceOptions::default().bounces);
    }

    #[test]
    fn a_bad_study_file_is_refused_naming_the_line_and_what_was_expected() {
        for (text, says) in [
            (
                "seeds = 1\n",
                ":1: 1 is out of range: expected a whole number from 2 to 1024",
            ),
            ("budgets = [4]\n\nsamplers = [\"randm\"]\n", ":3:"),
            ("budget = [4]\n", "unknown field `budget`"),
            ("sizes = [[8]]\n", ":1:"),
            ("budgets = []\n", "`budgets` is empty"),
            ("seeds = \n", ":1:"),
            (
                "seeds = 4\nscenes = [\"builtin\", \"nowhere.obj\"]\n",
                ":2: scene \"nowhere.obj\" is not a file",
            ),
        ] {
            let e = format!("{:#}", read_text(text).unwrap_err());
            assert!(
                e.contains("study.toml") && e.contains(says),
                "{text:?}: {e}"
            );
        }
    }
}
