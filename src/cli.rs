//! The command line: clap for the modern flags, plus a translation of the lab's single-dash
//! spelling (`-size 200 200 -input f.obj -soft_shadow ...`) so its run lines work verbatim.

use crate::film::ToneMap;
use crate::sampling::LightSampler;
use crate::settings::{RenderSettings, ShadowMode};
use clap::{Args, Parser, Subcommand};
use std::ffi::OsString;
use std::path::PathBuf;

/// raywave: a SIMD wavefront ray tracer for the lab's Cornell-box scenes.
#[derive(Parser, Debug)]
#[command(name = "raywave", version, about, long_about = None)]
pub struct Cli {
    /// What to do (default: render).
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
// Parsed once per run: the size of the `Render` variant does not matter.
#[allow(clippy::large_enum_variant)]
pub enum Command {
    /// Render a scene to an image (the default command; the lab's flags work too).
    Render(RenderArgs),
    /// Print the build's SIMD path, thread count and version.
    Info,
    /// Write a generated mesh scene: the lab's Cornell box with its three mirror spheres
    /// tessellated (for the BVH benchmarks: about 12k or 1M triangles).
    Meshgen(MeshgenArgs),
    /// Compare light samplers: MSE, bias, variance and slopes against a converged reference.
    Variance(crate::variance::command::VarianceArgs),
    /// Time both engines on a scene (rays/s per kind and stage); save and compare records
    /// (exit 3 when a figure regresses past --threshold).
    Bench(crate::bench::BenchArgs),
}

/// `raywave meshgen` flags.
#[derive(Args, Debug, Clone)]
pub struct MeshgenArgs {
    /// Approximate number of triangles.
    #[arg(long, default_value_t = 12_000,
          value_parser = clap::value_parser!(u64).range(36..=50_000_000))]
    pub triangles: u64,
    /// Output scene file (.obj).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `raywave render` flags.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene file (.obj); without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// The lab's `-input FILE` (same as the positional SCENE).
    #[arg(long = "input", hide = true, conflicts_with = "scene")]
    pub input: Option<PathBuf>,
    /// Output image (.png or .ppm), written whole or not at all.
    #[arg(short, long, default_value = "render.png")]
    pub output: PathBuf,
    /// Size, bounces, shadows and sampling (shared with `raywave bench`).
    #[command(flatten)]
    pub image: ImageArgs,
    /// Background colour for rays that hit nothing [default: the scene's, else white].
    #[arg(long, num_args = 3, value_names = ["R", "G", "B"], value_parser = parse_colour_component)]
    pub background: Option<Vec<f32>>,
    /// Seed of every random number.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Worker threads [default: all cores]; 1 runs serially.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Also write linear floats to this file (.pfm or .exr).
    #[arg(long)]
    pub hdr: Option<PathBuf>,
    /// Tone mapping of the 8-bit image: clamp (the lab's look) or exp (1 − e^(−3x)).
    #[arg(long, value_enum, default_value = "clamp")]
    pub tonemap: ToneMap,
    /// Let faces be hit from behind too.
    #[arg(long)]
    pub two_sided: bool,
    /// Print the rays traced for pixel X Y (from the top-left) and draw them over the image.
    #[arg(long, num_args = 2, value_names = ["X", "Y"])]
    pub debug_pixel: Option<Vec<u32>>,
    /// No progress bar and no summary.
    #[arg(short, long)]
    pub quiet: bool,
    /// Which engine renders the image.
    #[arg(long, value_enum, default_value = "wavefront")]
    pub engine: Engine,
    /// Camera samples per wavefront tile: the unit of work and of memory.
    #[arg(long, default_value_t = crate::wavefront::DEFAULT_BATCH_SIZE as u32,
          value_parser = clap::value_parser!(u32).range(1..=1 << 20))]
    pub batch_size: u32,
    /// Print rays and rays/s per kind, and per stage for the wavefront engine.
    #[arg(long)]
    pub stats: bool,
    /// Write the same figures as JSON, with the machine, SIMD path and thread count.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
}

/// The renderers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// Structure-of-arrays batches through 8-wide SIMD stages (the default).
    Wavefront,
    /// The scalar recursive renderer, one ray at a time: the whole-image twin.
    Reference,
}

impl Engine {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Wavefront => "wavefront",
            Engine::Reference => "reference",
        }
    }
}

fn parse_colour_component(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        Ok(_) => Err(format!(
            "expected a finite non-negative colour component, found `{s}`"
        )),
        Err(_) => Err(format!("expected a number, found `{s}`")),
    }
}

impl RenderArgs {
    /// The scene path, from the positional argument or the lab's `-input`.
    pub fn scene_path(&self) -> Option<&PathBuf> {
        self.scene.as_ref().or(self.input.as_ref())
    }

    /// Turns the flags into settings; `scene_background` is the file's `background_color`.
    pub fn settings(&self, scene_background: Option<[f32; 3]>) -> RenderSettings {
        let background = match &self.background {
            Some(c) => [c[0], c[1], c[2]],
            None => scene_background.unwrap_or(RenderSettings::default().background),
        };
        RenderSettings {
            seed: self.seed,
            two_sided: self.two_sided,
            ..self.image.settings(self.scene_path().is_some(), background)
        }
    }
}

/// The flags that shape the image, shared by `render` and `bench` so that both default alike
/// (a bench record then measures what the same flags render).
#[derive(Args, Debug, Clone)]
pub struct ImageArgs {
    /// Image size in pixels [default: 512 512].
    #[arg(long, num_args = 2, value_names = ["W", "H"], value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub size: Option<Vec<u32>>,
    /// Maximum mirror bounces.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub bounces: u32,
    /// Shadows: off (every light visible), hard (centroid), soft (N points per light).
    /// Default: hard, or soft when --shadow-samples > 1 or no scene is given.
    #[arg(long, value_enum)]
    pub shadows: Option<ShadowMode>,
    /// Points per light with soft shadows [default: 16].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub shadow_samples: Option<u32>,
    /// How the points on a light are chosen.
    #[arg(long, value_enum, default_value = "stratified")]
    pub sampler: LightSampler,
    /// Camera rays per pixel (1 = pixel centre, more = jittered strata).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub aa: u32,
}

impl ImageArgs {
    /// Settings from these flags, seed 0 and one-sided faces. Shadows default to soft when
    /// --shadow-samples > 1 or no scene is given (the lab's third run line), else hard.
    pub fn settings(&self, has_scene: bool, background: [f32; 3]) -> RenderSettings {
        let defaults = RenderSettings::default();
        let size = self
            .size
            .clone()
            .unwrap_or(vec![defaults.width, defaults.height]);
        let shadows = self.shadows.unwrap_or(match self.shadow_samples {
            Some(n) if n > 1 => ShadowMode::Soft,
            _ if !has_scene => ShadowMode::Soft,
            _ => ShadowMode::Hard,
        });
        RenderSettings {
            width: size[0],
            height: size[1],
            bounces: self.bounces,
            shadows,
            shadow_samples: self.shadow_samples.unwrap_or(defaults.shadow_samples),
            sampler: self.sampler,
            aa_samples: self.aa,
            background,
            ..defaults
        }
    }
}

/// A flag value that clap accepted but that fails a later check (an output extension raywave
/// cannot write, a debug pixel outside the image, ...): `main` reports it like clap's own usage
/// errors, with exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

impl UsageError {
    /// Wraps any error's message (with its causes) as a usage error.
    pub fn from_error(e: &anyhow::Error) -> Self {
        UsageError(format!("{e:#}"))
    }
}

/// The lab's flags and their modern spelling.
const LAB_FLAGS: &[(&str, &[&str])] = &[
    ("-size", &["--size"]),
    ("-input", &["--input"]),
    ("-output", &["--output"]),
    ("-background_color", &["--background"]),
    ("-num_shadow_samples", &["--shadow-samples"]),
    ("-num_bounces", &["--bounces"]),
    ("-num_antialias_samples", &["--aa"]),
    ("-soft_shadow", &["--shadows", "soft"]),
];

const SUBCOMMANDS: &[&str] = &[
    "render",
    "info",
    "meshgen",
    "variance",
    "bench",
    "help",
    "-h",
    "--help",
    "-V",
    "--version",
];

/// Rewrites argv so clap can read it: the lab's single-dash flags become modern ones, and a
/// command line without a subcommand (`raywave`, `raywave scene.obj`, `raywave -size ...`)
/// becomes `raywave render ...`.
pub fn normalize_args(args: impl IntoIterator<Item = OsString>) -> Vec<OsString> {
    let mut args: Vec<OsString> = args.into_iter().collect();
    let program = if args.is_empty() {
        OsString::from("raywave")
    } else {
        args.remove(0)
    };
    let mut out = vec![program];
    let first = args.first().and_then(|a| a.to_str()).unwrap_or("");
    if !SUBCOMMANDS.contains(&first) {
        out.push("render".into());
    }
    for arg in args {
        match arg
            .to_str()
            .and_then(|a| LAB_FLAGS.iter().find(|(lab, _)| *lab == a))
        {
            Some((_, modern)) => out.extend(modern.iter().map(OsString::from)),
            None => out.push(arg),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn norm(line: &str) -> Vec<String> {
        normalize_args(
            std::iter::once("raywave".into()).chain(line.split_whitespace().map(OsString::from)),
        )
        .into_iter()
        .map(|s| s.into_string().unwrap())
        .collect()
    }

    #[test]
    fn lab_run_line_is_translated() {
        assert_eq!(
            norm("-size 200 200 -input a.obj -soft_shadow -num_bounces 5").join(" "),
            "raywave render --size 200 200 --input a.obj --shadows soft --bounces 5"
        );
    }

    #[test]
    fn no_arguments_means_render() {
        assert_eq!(norm("").join(" "), "raywave render");
        assert_eq!(norm("info").join(" "), "raywave info");
        assert_eq!(
            norm("scene.obj -o x.png").join(" "),
            "raywave render scene.obj -o x.png"
        );
    }
}
