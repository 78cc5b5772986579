//! The command line: clap for the modern flags, plus a translation of the lab's single-dash
//! spelling (`-size 200 200 -input f.obj -soft_shadow ...`) so its run lines work verbatim.

use crate::film::ToneMap;
use crate::sampling::LightSampler;
use crate::scene::{ParseOptions, RPI_RING_SEGMENTS};
use crate::settings::{LightModel, RenderSettings, ShadowMode};
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
    /// Output: an 8-bit image (.png or .ppm), or only the linear floats (.pfm or .exr);
    /// written whole or not at all.
    #[arg(short, long, default_value = "render.png")]
    pub output: PathBuf,
    /// Size, bounces, shadows, lighting and sampling (shared with `raywave bench`).
    #[command(flatten)]
    pub image: ImageArgs,
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

pub use crate::engine::Engine;

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
    pub fn settings(&self, scene_background: Option<[f32; 3]>) -> Effective {
        let mut effective = self.image.resolve(scene_background);
        effective.settings.seed = self.seed;
        effective.settings.two_sided = self.two_sided;
        effective
    }
}

/// Whose defaults fill the settings that no flag sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Defaults {
    /// raywave's own, the lab's third run line: 512×512, 5 bounces, soft shadows (16 points).
    Raywave,
    /// The lab's ArgParser: 100×100, 0 bounces, hard shadows, white background.
    Lab,
    /// RPI's 2023 ArgParser: 500×500, 0 bounces, no shadow test, ambient 0.1, RPI's light model.
    Rpi,
}

/// The values one set of defaults gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DefaultValues {
    /// Image width and height.
    pub size: [u32; 2],
    /// Mirror bounces.
    pub bounces: u32,
    /// Shadow mode when neither `--shadows` nor `--shadow-samples` is given.
    pub shadows: ShadowMode,
    /// Points per light for soft shadows when no count is given.
    pub shadow_samples: u32,
    /// Camera rays per pixel.
    pub aa: u32,
    /// Background when neither a flag nor the scene file sets one.
    pub background: [f32; 3],
    /// Ambient light.
    pub ambient: [f32; 3],
    /// How light falls off with distance.
    pub light_model: LightModel,
}

impl Defaults {
    /// The values; raywave's are `RenderSettings::default()`'s (a unit test holds them equal).
    ///
    /// The lab's and RPI's come from their ArgParsers' `DefaultValues`: `-size` 100 100 (the
    /// lab) and 500 500 (RPI 2023), `-num_bounces` 0, `-num_shadow_samples` 0,
    /// `-num_antialias_samples` 1, `-background_color` 1 1 1 (the lab), `ambient_light` 0.2
    /// grey (the lab) and 0.1 grey (RPI). A shadow-sample count of 0 means no count at all:
    /// the lab's finished program casts one shadow ray to each light's centroid unless
    /// `-soft_shadow` is given, and RPI's casts none; soft shadows without a count use
    /// raywave's 16 points.
    pub const fn values(self) -> DefaultValues {
        match self {
            Defaults::Raywave => DefaultValues {
                size: [512, 512],
                bounces: 5,
                shadows: ShadowMode::Soft,
                shadow_samples: 16,
                aa: 1,
                background: [1.0; 3],
                ambient: [0.2; 3],
                light_model: LightModel::Lab,
            },
            Defaults::Lab => DefaultValues {
                size: [100, 100],
                bounces: 0,
                shadows: ShadowMode::Hard,
                shadow_samples: 16,
                aa: 1,
                background: [1.0; 3],
                ambient: [0.2; 3],
                light_model: LightModel::Lab,
            },
            Defaults::Rpi => DefaultValues {
                size: [500, 500],
                bounces: 0,
                shadows: ShadowMode::Off,
                shadow_samples: 16,
                aa: 1,
                background: [1.0; 3],
                ambient: [0.1; 3],
                light_model: LightModel::Rpi,
            },
        }
    }

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Defaults::Raywave => "raywave",
            Defaults::Lab => "lab",
            Defaults::Rpi => "rpi",
        }
    }

    /// Whose defaults these are, for the summary.
    pub fn owner(self) -> &'static str {
        match self {
            Defaults::Raywave => "raywave's",
            Defaults::Lab => "the lab's ArgParser's",
            Defaults::Rpi => "RPI's 2023 ArgParser's",
        }
    }
}

/// Where the background colour came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackgroundSource {
    /// `--background` / `-background_color`.
    Flag,
    /// The scene file's `background_color`.
    Scene,
    /// The defaults.
    Defaults,
}

/// The settings a command line gives, and which of them came from the defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Effective {
    /// The settings.
    pub settings: RenderSettings,
    /// Whose defaults filled the gaps.
    pub defaults: Defaults,
    /// The settings no flag set, as printed in the summary ("size", "bounces", ...).
    pub defaulted: Vec<&'static str>,
    /// Where the background came from.
    pub background: BackgroundSource,
}

/// The flags that shape the image, shared by `render` and `bench` so that both default alike
/// (a bench record then measures what the same flags render). The defaults are the same with
/// or without a scene file: the built-in scene and the same file read from `scenes/` get the
/// same settings.
#[derive(Args, Debug, Clone)]
pub struct ImageArgs {
    /// Image size in pixels [default: 512 512; the lab's 100 100; RPI's 500 500].
    #[arg(long, num_args = 2, value_names = ["W", "H"], value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub size: Option<Vec<u32>>,
    /// Maximum mirror bounces [default: 5; the lab's and RPI's 0].
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub bounces: Option<u32>,
    /// Shadows: off (every light visible), hard (centroid), soft (N points per light).
    /// Without it: soft when --shadow-samples > 1, hard when it is 1, else the defaults'
    /// [soft; the lab's hard; RPI's off].
    #[arg(long, value_enum)]
    pub shadows: Option<ShadowMode>,
    /// Points per light with soft shadows [default: 16].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub shadow_samples: Option<u32>,
    /// How the points on a light are chosen.
    #[arg(long, value_enum, default_value = "stratified")]
    pub sampler: LightSampler,
    /// Camera rays per pixel (1 = pixel centre, more = jittered strata) [default: 1].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub aa: Option<u32>,
    /// Background colour for rays that hit nothing [default: the scene's, else white].
    #[arg(long, num_args = 3, value_names = ["R", "G", "B"], value_parser = parse_colour_component)]
    pub background: Option<Vec<f32>>,
    /// Ambient light: every hit gets ambient ⊙ kd [default: 0.2 grey; RPI's 0.1].
    #[arg(long, num_args = 3, value_names = ["R", "G", "B"], value_parser = parse_colour_component)]
    pub ambient: Option<Vec<f32>>,
    /// How a light's colour reaches a point: lab (no fall-off) or rpi (divided by π·d², as
    /// RPI's framework does) [default: lab; RPI's rpi].
    #[arg(long, value_enum)]
    pub light_model: Option<LightModel>,
    /// Quads around each RPI cylinder ring (`r` line) of the scene [default: 20, RPI's].
    #[arg(long, value_parser = clap::value_parser!(u32).range(3..=65536))]
    pub ring_segments: Option<u32>,
    /// Whose defaults fill what no flag sets [default: raywave; lab when the lab's
    /// single-dash flags are used, rpi with RPI 2023's double-dash ones].
    #[arg(long, value_enum)]
    pub defaults: Option<Defaults>,
}

impl ImageArgs {
    /// What the scene parser needs from these flags.
    pub fn parse_options(&self) -> ParseOptions {
        ParseOptions {
            ring_segments: self.ring_segments.unwrap_or(RPI_RING_SEGMENTS),
        }
    }

    /// Settings from these flags (seed 0, one-sided faces); `scene_background` is the file's
    /// `background_color`. What no flag sets comes from `--defaults`.
    pub fn resolve(&self, scene_background: Option<[f32; 3]>) -> Effective {
        let defaults = self.defaults.unwrap_or(Defaults::Raywave);
        let d = defaults.values();
        let mut defaulted = Vec::new();
        // The given value, or the default (noting the setting's name).
        fn pick<T>(given: Option<T>, default: T, name: &'static str, out: &mut Vec<&str>) -> T {
            given.unwrap_or_else(|| {
                out.push(name);
                default
            })
        }
        let size = pick(
            self.size.as_ref().map(|s| [s[0], s[1]]),
            d.size,
            "size",
            &mut defaulted,
        );
        let bounces = pick(self.bounces, d.bounces, "bounces", &mut defaulted);
        let shadows = pick(
            self.shadows.or(match self.shadow_samples {
                Some(n) if n > 1 => Some(ShadowMode::Soft),
                Some(_) => Some(ShadowMode::Hard),
                None => None,
            }),
            d.shadows,
            "shadows",
            &mut defaulted,
        );
        let shadow_samples = match (self.shadow_samples, shadows) {
            (Some(n), _) => n,
            (None, ShadowMode::Soft) => {
                // The lab's and RPI's count, 0, is no count: theirs is raywave's too.
                let name = match defaults {
                    Defaults::Raywave => "shadow samples",
                    _ => "shadow samples (raywave's 16)",
                };
                pick(None, d.shadow_samples, name, &mut defaulted)
            }
            (None, _) => d.shadow_samples,
        };
        let aa_samples = pick(self.aa, d.aa, "aa", &mut defaulted);
        let ambient = pick(
            self.ambient.as_ref().map(|c| [c[0], c[1], c[2]]),
            d.ambient,
            "ambient",
            &mut defaulted,
        );
        let light_model = pick(
            self.light_model,
            d.light_model,
            "light model",
            &mut defaulted,
        );
        let (background, source) = match (&self.background, scene_background) {
            (Some(c), _) => ([c[0], c[1], c[2]], BackgroundSource::Flag),
            (None, Some(c)) => (c, BackgroundSource::Scene),
            (None, None) => {
                defaulted.push("background");
                (d.background, BackgroundSource::Defaults)
            }
        };
        Effective {
            settings: RenderSettings {
                width: size[0],
                height: size[1],
                bounces,
                shadows,
                shadow_samples,
                sampler: self.sampler,
                aa_samples,
                background,
                light_model,
                ambient,
                ..RenderSettings::default()
            },
            defaults,
            defaulted,
            background: source,
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

/// What one value of a lab or RPI flag must look like.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Value {
    /// A whole number, 0 or more.
    Count,
    /// A finite number.
    Number,
    /// Any text (a file name).
    Text,
}

/// What a lab or RPI flag does in raywave.
#[derive(Clone, Copy, Debug)]
enum Meaning {
    /// This raywave flag, followed by the values as given.
    Flag(&'static str),
    /// These raywave arguments (the flag takes no values).
    Tokens(&'static [&'static str]),
    /// `-num_shadow_samples N`: `--shadow-samples N`, except that 0, both programs' default,
    /// is no count: the lab then shades hard shadows (or soft ones with raywave's count), RPI
    /// casts no shadow rays at all (`--shadows off`).
    ShadowSamples,
    /// Accepted and checked, then ignored with a note on stderr giving this reason.
    NoEffect(&'static str),
}

/// Which dashes a flag is spelled with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dashes {
    /// `-name` only: the lab's ArgParser, or RPI's older single-dash one.
    One,
    /// `-name` and RPI 2023's `--name`.
    Both,
}

/// One flag of the lab's or RPI's ArgParser.
struct ForeignFlag {
    /// The name without its dashes.
    name: &'static str,
    /// How it is spelled.
    dashes: Dashes,
    /// The values that follow it.
    values: &'static [Value],
    /// What raywave does with it.
    meaning: Meaning,
}

const fn flag(
    name: &'static str,
    dashes: Dashes,
    values: &'static [Value],
    meaning: Meaning,
) -> ForeignFlag {
    ForeignFlag {
        name,
        dashes,
        values,
        meaning,
    }
}

const RADIOSITY: &str = "raywave has no radiosity solver";
const PHOTONS: &str = "raywave has no photon mapping; indirect light stays the ambient term";
const SPHERES: &str = "raywave intersects spheres exactly; RPI cuts them into patches only for radiosity and its OpenGL view";
const GLOSSY: &str =
    "raywave traces no glossy reflection rays; glossiness only widens the highlight";

use Dashes::{Both, One};
use Meaning::{Flag, NoEffect, ShadowSamples, Tokens};
use Value::{Count, Number, Text};

/// Every flag of the lab's ArgParser and RPI's (single-dash, and the 2023 double-dash forms),
/// with raywave's meaning: one place to read and extend. Sources: the lab's `argparser.h`
/// (`-input`, `-size`, `-sphere_rasterization`, `-num_bounces`, `-num_shadow_samples`,
/// `-num_glossy_samples`, `-num_form_factor_samples`, `-background_color`, `-soft_shadow`),
/// RPI's `argparser.h` (adds `-i`, `-cylinder_ring_rasterization`, `-num_antialias_samples`,
/// `-ambient_light` and the photon-mapping flags) and RPI's 2023 `argparser.cpp` (the same with
/// two dashes, without `-i`). `-output` is raywave's own single-dash spelling of `-o`, kept for
/// lab-style lines.
#[rustfmt::skip]
const FOREIGN_FLAGS: &[ForeignFlag] = &[
    flag("input",                       Both, &[Text],                   Flag("--input")),
    flag("i",                           One,  &[Text],                   Flag("--input")),
    flag("output",                      One,  &[Text],                   Flag("--output")),
    flag("size",                        Both, &[Count, Count],           Flag("--size")),
    flag("num_bounces",                 Both, &[Count],                  Flag("--bounces")),
    flag("num_shadow_samples",          Both, &[Count],                  ShadowSamples),
    flag("soft_shadow",                 One,  &[],                       Tokens(&["--shadows", "soft"])),
    flag("background_color",            One,  &[Number, Number, Number], Flag("--background")),
    flag("num_antialias_samples",       Both, &[Count],                  Flag("--aa")),
    flag("ambient_light",               Both, &[Number, Number, Number], Flag("--ambient")),
    flag("cylinder_ring_rasterization", Both, &[Count],                  Flag("--ring-segments")),
    flag("sphere_rasterization",        Both, &[Count, Count],           NoEffect(SPHERES)),
    flag("num_glossy_samples",          Both, &[Count],                  NoEffect(GLOSSY)),
    flag("num_form_factor_samples",     Both, &[Count],                  NoEffect(RADIOSITY)),
    flag("num_photons_to_shoot",        Both, &[Count],                  NoEffect(PHOTONS)),
    flag("num_photons_to_collect",      Both, &[Count],                  NoEffect(PHOTONS)),
    flag("gather_indirect",             Both, &[],                       NoEffect(PHOTONS)),
];

/// Spellings in the table that are also raywave's own: they do not choose whose defaults apply.
const RAYWAVE_SPELLINGS: &[&str] = &["-output", "--input", "--size"];

/// raywave flags a lab or RPI flag can stand for, with the setting they name in messages.
const TARGETS: &[(&str, &str)] = &[
    ("--input", "the scene"),
    ("--output", "the output file"),
    ("-o", "the output file"),
    ("--size", "the size"),
    ("--bounces", "the bounces"),
    ("--shadows", "the shadow mode"),
    ("--shadow-samples", "the shadow samples"),
    ("--background", "the background"),
    ("--aa", "the antialiasing samples"),
    ("--ambient", "the ambient light"),
    ("--ring-segments", "the ring segments"),
];

/// The subcommands that take the image flags, and so the lab's and RPI's spellings.
const IMAGE_COMMANDS: &[&str] = &["render", "bench"];

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

/// argv rewritten for clap, and the notes to print on stderr.
#[derive(Debug, Clone, PartialEq)]
pub struct Normalized {
    /// The arguments clap reads.
    pub args: Vec<OsString>,
    /// One line each for flags accepted without effect (printed with a `note:` prefix).
    pub notes: Vec<String>,
}

/// The table entry for an argument, and whose spelling it is (`None`: raywave's own).
fn foreign(arg: &str) -> Option<(&'static ForeignFlag, Option<Defaults>)> {
    let (name, double) = match arg.strip_prefix("--") {
        Some(name) => (name, true),
        None => (arg.strip_prefix('-')?, false),
    };
    let flag = FOREIGN_FLAGS
        .iter()
        .find(|f| f.name == name && (!double || f.dashes == Both))?;
    let dialect = if RAYWAVE_SPELLINGS.contains(&arg) {
        None
    } else if double {
        Some(Defaults::Rpi)
    } else {
        Some(Defaults::Lab)
    };
    Some((flag, dialect))
}

/// Reads the values of `spelling` from `rest`, checking each one.
fn take_values<'a>(
    spelling: &str,
    kinds: &[Value],
    rest: &mut impl Iterator<Item = &'a OsString>,
) -> Result<Vec<String>, UsageError> {
    let what = match (kinds.first(), kinds.len()) {
        (Some(Value::Count), 1) => "a whole number".to_string(),
        (Some(Value::Count), n) => format!("{n} whole numbers"),
        (Some(Value::Number), n) => format!("{n} numbers"),
        _ => "a file name".to_string(),
    };
    let mut values = Vec::with_capacity(kinds.len());
    for kind in kinds {
        let found = rest.next().map(|v| v.to_string_lossy().into_owned());
        let ok = match (&found, kind) {
            (None, _) => false,
            (Some(v), Value::Count) => v.parse::<u32>().is_ok(),
            (Some(v), Value::Number) => v.parse::<f32>().is_ok_and(f32::is_finite),
            (Some(_), Value::Text) => true,
        };
        if !ok {
            let found = found.map_or("the end of the command line".to_string(), |v| {
                format!("`{v}`")
            });
            return Err(UsageError(format!(
                "{spelling}: expected {what}, found {found}"
            )));
        }
        values.push(found.unwrap_or_default());
    }
    Ok(values)
}

/// Rewrites argv so clap can read it. A command line without a subcommand (`raywave`,
/// `raywave scene.obj`, `raywave -size ...`) becomes `raywave render ...`. For `render` and
/// `bench`, the lab's and RPI's spellings become raywave's flags (see `FOREIGN_FLAGS`), and
/// they choose whose defaults fill the rest:
///
/// - the lab's single-dash spellings (also RPI's older single-dash ones): `--defaults lab`;
/// - RPI 2023's double-dash spellings (`--num_bounces`, ...; `--input` and `--size` are
///   raywave's too and choose nothing): `--defaults rpi`;
/// - an explicit `--defaults` wins over both;
/// - raywave's own flags mix freely with either: each still sets its setting, and the chosen
///   defaults fill only what no flag sets;
/// - the lab's and RPI 2023's spellings on one line, or one setting given twice under two
///   spellings (`-num_bounces 0 --bounces 3`), are usage errors.
pub fn normalize_args(args: impl IntoIterator<Item = OsString>) -> Result<Normalized, UsageError> {
    let mut args: Vec<OsString> = args.into_iter().collect();
    let program = if args.is_empty() {
        OsString::from("raywave")
    } else {
        args.remove(0)
    };
    let first = args.first().and_then(|a| a.to_str()).unwrap_or("");
    let (command, rest) = if SUBCOMMANDS.contains(&first) {
        (first.to_string(), args[1..].to_vec())
    } else {
        ("render".to_string(), args)
    };
    let mut out = vec![program, OsString::from(&command)];
    if !IMAGE_COMMANDS.contains(&command.as_str()) {
        out.extend(rest);
        return Ok(Normalized {
            args: out,
            notes: Vec::new(),
        });
    }

    // Whose defaults: an explicit --defaults, else the spellings used.
    let explicit = rest.iter().enumerate().find_map(|(i, a)| {
        let value = match a.to_str()?.strip_prefix("--defaults") {
            Some("") => rest.get(i + 1)?.to_str()?,
            Some(v) => v.strip_prefix('=')?,
            None => return None,
        };
        <Defaults as clap::ValueEnum>::from_str(value, false).ok()
    });
    let mut lab_spelling = None;
    let mut rpi_spelling = None;
    for arg in rest.iter().filter_map(|a| a.to_str()) {
        match foreign(arg) {
            Some((_, Some(Defaults::Lab))) => lab_spelling = lab_spelling.or(Some(arg)),
            Some((_, Some(Defaults::Rpi))) => rpi_spelling = rpi_spelling.or(Some(arg)),
            _ => {}
        }
    }
    let detected = match (lab_spelling, rpi_spelling) {
        (Some(lab), Some(rpi)) => {
            return Err(UsageError(format!(
                "`{lab}` is the lab's spelling and `{rpi}` RPI 2023's: expected one program's flags on a command line"
            )));
        }
        (Some(_), None) => Some(Defaults::Lab),
        (None, Some(_)) => Some(Defaults::Rpi),
        (None, None) => None,
    };
    let dialect = explicit.or(detected).unwrap_or(Defaults::Raywave);
    if explicit.is_none()
        && let Some(d) = detected
    {
        out.extend(["--defaults", d.name()].map(OsString::from));
    }

    let mut notes = Vec::new();
    // The setting each raywave flag sets, and the spelling that set it first.
    let mut set_by: Vec<(&str, String)> = Vec::new();
    let mut claim = |target: &str, spelling: &str| -> Result<(), UsageError> {
        let Some(&(target, what)) = TARGETS.iter().find(|(t, _)| *t == target) else {
            return Ok(());
        };
        let target = if target == "-o" { "--output" } else { target };
        if let Some((_, first)) = set_by.iter().find(|(t, _)| *t == target) {
            return Err(UsageError(format!(
                "`{first}` and `{spelling}` both set {what}: expected it once"
            )));
        }
        set_by.push((target, spelling.to_string()));
        Ok(())
    };
    let mut rest = rest.iter();
    while let Some(arg) = rest.next() {
        let Some(text) = arg.to_str() else {
            out.push(arg.clone());
            continue;
        };
        let Some((flag, _)) = foreign(text) else {
            claim(text, text)?;
            if text.len() > 2
                && text.starts_with('-')
                && !text.starts_with("--")
                && text[1..].starts_with(|c: char| c.is_ascii_alphabetic())
            {
                return Err(UsageError(format!(
                    "unknown flag `{text}`: expected one of raywave's flags (--help lists them), or one of the lab's or RPI's: {}",
                    FOREIGN_FLAGS
                        .iter()
                        .map(|f| format!("-{}", f.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
            out.push(arg.clone());
            continue;
        };
        let values = take_values(text, flag.values, &mut rest)?;
        match flag.meaning {
            Meaning::Flag(target) => {
                claim(target, text)?;
                out.push(target.into());
                out.extend(values.into_iter().map(OsString::from));
            }
            Meaning::Tokens(args) => {
                claim(args[0], text)?;
                out.extend(args.iter().map(OsString::from));
            }
            Meaning::ShadowSamples => match (values[0].as_str(), dialect) {
                ("0", Defaults::Rpi) => {
                    claim("--shadows", text)?;
                    out.extend(["--shadows", "off"].map(OsString::from));
                }
                ("0", _) => {}
                (n, _) => {
                    claim("--shadow-samples", text)?;
                    out.extend(["--shadow-samples", n].map(OsString::from));
                }
            },
            Meaning::NoEffect(why) => {
                let given = std::iter::once(text.to_string())
                    .chain(values)
                    .collect::<Vec<_>>()
                    .join(" ");
                notes.push(format!("{given}: accepted, no effect in raywave ({why})"));
            }
        }
    }
    Ok(Normalized { args: out, notes })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn norm(line: &str) -> Result<Normalized, UsageError> {
        normalize_args(
            std::iter::once("raywave".into()).chain(line.split_whitespace().map(OsString::from)),
        )
    }

    fn args(line: &str) -> String {
        norm(line)
            .unwrap()
            .args
            .into_iter()
            .map(|s| s.into_string().unwrap())
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn lab_run_line_is_translated_with_the_lab_defaults() {
        assert_eq!(
            args("-size 200 200 -input a.obj -soft_shadow -num_bounces 5"),
            "raywave render --defaults lab --size 200 200 --input a.obj --shadows soft --bounces 5"
        );
    }

    #[test]
    fn rpi_2023_line_is_translated_with_rpi_defaults() {
        assert_eq!(
            args("--input a.obj --size 300 300 --num_bounces 2 --num_shadow_samples 0"),
            "raywave render --defaults rpi --input a.obj --size 300 300 --bounces 2 --shadows off"
        );
        // --input and --size alone are raywave's spellings too: raywave's defaults.
        assert_eq!(
            args("--input a.obj --size 3 3"),
            "raywave render --input a.obj --size 3 3"
        );
    }

    #[test]
    fn shadow_sample_count_zero_is_no_count_for_the_lab() {
        assert_eq!(
            args("-num_shadow_samples 0"),
            "raywave render --defaults lab"
        );
    }

    #[test]
    fn explicit_defaults_win() {
        assert_eq!(
            args("--defaults raywave -num_bounces 1"),
            "raywave render --defaults raywave --bounces 1"
        );
        assert_eq!(
            args("--num_bounces 1 --defaults=lab"),
            "raywave render --bounces 1 --defaults=lab"
        );
    }

    #[test]
    fn no_effect_flags_give_notes() {
        let n = norm("-sphere_rasterization 16 12 --light-model rpi").unwrap();
        assert_eq!(n.notes.len(), 1);
        assert!(n.notes[0].starts_with("-sphere_rasterization 16 12: accepted, no effect"));
    }

    #[test]
    fn bad_values_mixed_dialects_and_duplicates_are_usage_errors() {
        for line in [
            "-size 200",
            "-size 200 x",
            "-num_bounces -1",
            "-ambient_light 1 nan 1",
            "-num_bounces 1 --num_shadow_samples 2",
            "-num_bounces 1 --bounces 2",
            "-soft_shadow --shadows hard",
            "-frobnicate",
            "-output a.png -o b.png",
            "-input a.obj -i b.obj",
        ] {
            assert!(norm(line).is_err(), "{line}");
        }
    }

    #[test]
    fn raywave_defaults_are_render_settings_default() {
        let d = Defaults::Raywave.values();
        let s = RenderSettings::default();
        assert_eq!(d.size, [s.width, s.height]);
        assert_eq!(
            (d.bounces, d.shadows, d.shadow_samples, d.aa),
            (s.bounces, s.shadows, s.shadow_samples, s.aa_samples)
        );
        assert_eq!(
            (d.background, d.ambient, d.light_model),
            (s.background, s.ambient, s.light_model)
        );
    }

    #[test]
    fn no_arguments_means_render() {
        assert_eq!(args(""), "raywave render");
        assert_eq!(args("info"), "raywave info");
        assert_eq!(
            args("scene.obj -o x.png"),
            "raywave render scene.obj -o x.png"
        );
    }
}
