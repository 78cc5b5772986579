//! `raywave diff A B`: reads two images, compares A with the reference B over the whole image
//! or a mask, prints the figures (and writes them as JSON), draws the per-pixel error, and
//! exits 3 when `--fail-above` is passed.

use super::values::{DefaultsArg, MetricArg, float};
use anyhow::{Result, bail};
use clap::Args;
use raywave::diff::{self, Comparison, EXIT_FAILED, FileInfo, Image, Metric, Region, read_image};
use raywave::output::OutputPlan;
use raywave::output::image_file::{ldr_format, write_json};
use raywave::render::error::UsageError;
use raywave::render::scene::load_scene;
use raywave::render::settings::options::ImageOptions;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Flags of `raywave diff`.
#[derive(Args, Debug, Clone)]
pub struct DiffArgs {
    /// The image checked (PNG, PPM, PFM or EXR).
    pub a: PathBuf,
    /// The reference it is compared with (relMSE divides by it, FLIP takes it as reference).
    pub b: PathBuf,
    /// Compare only some pixels: `penumbra` (shadow edges, computed from the scene below as
    /// `raywave variance` does) or an image file whose non-zero pixels are inside (write
    /// `./penumbra` for a file of that name).
    #[arg(long, value_name = "penumbra|FILE")]
    pub mask: Option<PathBuf>,
    /// Write a false-colour map of --metric's per-pixel error, with a colour bar (.png or .ppm).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// The figure --fail-above tests and --out draws.
    #[arg(long, value_enum, default_value = "mse")]
    pub metric: MetricArg,
    /// Exit 3 when the overall --metric figure is above X (for psnr: below X).
    #[arg(long, value_name = "X", value_parser = float("a finite number", f64::is_finite), allow_negative_numbers = true)]
    pub fail_above: Option<f64>,
    /// Also compute FLIP, NVIDIA's perceptual error (implied by --metric flip).
    #[arg(long)]
    pub flip: bool,
    /// Write the figures as JSON (`-`: standard output; the table then goes to standard error).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Scene the images were rendered from [default: the built-in scene].
    #[arg(long, help_heading = "With --mask penumbra")]
    pub scene: Option<PathBuf>,
    /// Mirror bounces the images were rendered with [default: the --defaults' (5; lab, rpi: 0)].
    #[arg(long, help_heading = "With --mask penumbra", value_parser = clap::value_parser!(u32).range(0..=64))]
    pub bounces: Option<u32>,
    /// Whose defaults fill the bounces [default: raywave].
    #[arg(long, value_enum, help_heading = "With --mask penumbra")]
    pub defaults: Option<DefaultsArg>,
    /// Quads around each RPI cylinder ring of the scene [default: 20].
    #[arg(long, help_heading = "With --mask penumbra", value_parser = clap::value_parser!(u32).range(3..=65536))]
    pub ring_segments: Option<u32>,
    /// The images were rendered with --two-sided.
    #[arg(long, help_heading = "With --mask penumbra")]
    pub two_sided: bool,
    /// Points per light per hit for the penumbra test.
    #[arg(long, default_value_t = 1024, help_heading = "With --mask penumbra", value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub mask_samples: u32,
}

const PENUMBRA: &str = "penumbra";

impl DiffArgs {
    fn penumbra(&self) -> bool {
        self.mask.as_deref().map(Path::as_os_str) == Some(std::ffi::OsStr::new(PENUMBRA))
    }

    fn mask_file(&self) -> Option<&Path> {
        self.mask.as_deref().filter(|_| !self.penumbra())
    }
}

/// What `--json` writes.
#[derive(Serialize)]
struct Record<'a> {
    a: &'a FileInfo,
    b: &'a FileInfo,
    #[serde(flatten)]
    comparison: &'a Comparison,
    metric: Metric,
    value: Option<f64>,
    fail_above: Option<f64>,
    failed: bool,
}

/// Runs the comparison; the exit code is 3 when `--fail-above` is passed, else 0.
pub fn run(args: &DiffArgs) -> Result<u8> {
    let metric = Metric::from(args.metric);
    let want_flip = args.flip || metric == Metric::Flip;
    if want_flip && !diff::FLIP_AVAILABLE {
        bail!(UsageError(
            "--flip and --metric flip need raywave built with the `flip` feature (on by default; it needs a C++ compiler)".into(),
        ));
    }
    if let Some(out) = &args.out
        && ldr_format(out).is_err()
    {
        bail!(UsageError(format!(
            "--out {}: expected a figure file ending in .png or .ppm",
            out.display()
        )));
    }
    let scene_flags: Vec<&str> = [
        ("--scene", args.scene.is_some()),
        ("--bounces", args.bounces.is_some()),
        ("--defaults", args.defaults.is_some()),
        ("--ring-segments", args.ring_segments.is_some()),
        ("--two-sided", args.two_sided),
    ]
    .into_iter()
    .filter_map(|(flag, given)| given.then_some(flag))
    .collect();
    if !scene_flags.is_empty() && !args.penumbra() {
        let verb = if scene_flags.len() == 1 {
            "has"
        } else {
            "have"
        };
        eprintln!(
            "warning: {} {verb} no effect without --mask penumbra",
            scene_flags.join(", ")
        );
    }
    let plan = OutputPlan::new()
        .input("A", &args.a)
        .input("B", &args.b)
        .input_if("--mask", args.mask_file())
        .input_if("--scene", args.scene.as_deref().filter(|_| args.penumbra()))
        .output_if("--out", args.out.as_deref())
        .output_if("--json", args.json.as_deref());
    plan.check()?;
    plan.refuse_binary_on_terminal(&["--out"])?;

    let a = read_image(&args.a)?;
    let b = read_image(&args.b)?;
    let a_name = format!("A {}", args.a.display());
    let b_name = format!("B {}", args.b.display());
    diff::check_same_size(&a, &a_name, &b, &b_name).map_err(|e| UsageError::from_error(&e))?;
    let (a_info, b_info) = (FileInfo::of(&args.a, &a), FileInfo::of(&args.b, &b));
    let mut text = format!(
        "A        {}\nB        {}, the reference\n",
        a_info.describe(),
        b_info.describe()
    );
    if (a.encoding == diff::Encoding::Float) != (b.encoding == diff::Encoding::Float) {
        text.push_str(
            "note     one image holds linear floats and the other 8/16-bit values: the stored values are compared as they are\n",
        );
    }
    let region = region(args, &a, &plan)?;
    let mut comparison = diff::compare(&a, &b, &region)?;
    let flip_map = want_flip
        .then(|| diff::add_flip(&mut comparison, &a, &b, &region))
        .transpose()?;
    text.push_str(&diff::text::table(&comparison));

    let value = comparison.value(metric);
    let failed =
        (args.fail_above.zip(value)).is_some_and(|(threshold, v)| metric.fails(v, threshold));
    if let Some(out) = &args.out {
        let errors = match (&flip_map, metric) {
            (Some(map), Metric::Flip) => map.clone(),
            _ => diff::pixel_errors(&a, &b, &region, metric),
        };
        let within = match (args.penumbra(), args.mask_file()) {
            (true, _) => " in the penumbra (outside: black)".to_string(),
            (_, Some(mask)) => format!(" in {} (outside: black)", file_name(mask)),
            _ => String::new(),
        };
        let title = format!(
            "{} vs {}: {}{within}",
            file_name(&args.a),
            file_name(&args.b),
            match metric {
                Metric::Mse | Metric::Psnr => "squared error",
                Metric::Relmse => "relative squared error",
                Metric::Max => "largest |a − b|",
                Metric::Flip => "FLIP error",
            },
        );
        let fig = diff::figure(&errors, a.film.width, a.film.height, metric, &title)?;
        raywave::output::image_file::write_rgb8(&fig, out)?;
        text.push_str(&format!("wrote    {}\n", out.display()));
    }
    if let Some(json) = &args.json {
        let record = Record {
            a: &a_info,
            b: &b_info,
            comparison: &comparison,
            metric,
            value,
            fail_above: args.fail_above,
            failed,
        };
        // Through a `Value`, whose keys are sorted.
        write_json(json, &serde_json::to_value(&record)?)?;
    }
    if let (Some(threshold), Some(v)) = (args.fail_above, value) {
        let (verdict, relation) = match (failed, metric) {
            (true, Metric::Psnr) => ("FAIL", "below"),
            (true, _) => ("FAIL", "above"),
            (false, Metric::Psnr) => ("pass", "not below"),
            (false, _) => ("pass", "not above"),
        };
        let shown = match metric {
            Metric::Psnr => format!("{v:.2} dB"),
            _ => format!("{v:.4e}"),
        };
        text.push_str(&format!(
            "{verdict:<8} {} {shown} is {relation} --fail-above {threshold}\n",
            super::values::spelling(args.metric)
        ));
    }
    super::image::say(&plan, &text)?;
    Ok(if failed { EXIT_FAILED } else { 0 })
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// The pixels compared: every one, a mask file's non-zero ones, or the penumbra.
fn region(args: &DiffArgs, a: &Image, plan: &OutputPlan) -> Result<Region> {
    if let Some(path) = args.mask_file() {
        let mask = read_image(path)?;
        diff::check_same_size(
            &mask,
            &format!("--mask {}", path.display()),
            a,
            &format!("A {}", args.a.display()),
        )
        .map_err(|e| UsageError::from_error(&e))?;
        return Ok(Region::from_mask_image(&mask, path.display().to_string()));
    }
    if !args.penumbra() {
        return Ok(Region::whole(a.film.width, a.film.height));
    }
    let options = ImageOptions {
        size: Some([a.film.width, a.film.height]),
        bounces: args.bounces,
        ring_segments: args.ring_segments,
        defaults: args.defaults.map(Into::into),
        two_sided: args.two_sided,
        ..ImageOptions::default()
    };
    let scene = load_scene(args.scene.as_deref(), &options.parse_options())?.scene;
    for w in &scene.warnings {
        eprintln!("{w}");
    }
    plan.check_scene_files("--scene", &scene)?;
    if scene.lights.is_empty() {
        bail!(
            "{}: --mask penumbra needs a scene with an area light, found none",
            scene.source
        );
    }
    let settings = options
        .resolve(scene.background.map(|c| c.to_array()))
        .settings;
    let regions =
        raywave::variance::figures::mask::penumbra_mask(&scene, &settings, args.mask_samples);
    Ok(Region {
        name: format!("penumbra of {}, {} bounces", scene.source, settings.bounces),
        inside: regions.penumbra,
    })
}
