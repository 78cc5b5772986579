//! `raywave render`: its flags, mapped to [`FrameOptions`] for `raywave::frame::run`, and
//! what it prints.

use super::image::{ImageArgs, SeedArgs, ThreadsArg};
use super::values::{CostKindArg, CostMeasureArg, EngineArg, LanesArg, ToneMapArg};
use anyhow::Result;
use clap::Args;
use raywave::frame::phases::Phases;
use raywave::frame::{self, FrameOptions};
use raywave::output::OutputPlan;
use raywave::output::terminal::with_bar;
use raywave::render::engine::thread_pool;
use std::path::PathBuf;

/// `raywave render` flags.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene file (.obj); without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// The lab's `-input FILE` (same as the positional SCENE).
    #[arg(long = "input", hide = true, conflicts_with = "scene")]
    pub input: Option<PathBuf>,
    /// Output: an 8-bit image (.png or .ppm), or only the linear floats (.pfm or .exr);
    /// written whole or not at all. `-` writes PNG to standard output; a device or FIFO
    /// without an extension (/dev/null) gets PNG too.
    #[arg(short, long, default_value = "render.png")]
    pub output: PathBuf,
    /// Size, bounces, shadows, lighting and sampling (shared with `raywave bench`).
    #[command(flatten)]
    pub image: ImageArgs,
    #[command(flatten)]
    pub seed: SeedArgs,
    #[command(flatten)]
    pub workers: ThreadsArg,
    /// Also write linear floats to this file (.pfm or .exr; `-` or a device: PFM).
    #[arg(long)]
    pub hdr: Option<PathBuf>,
    /// Tone mapping of the 8-bit image: clamp (the lab's look) or exp (1 − e^(−3x)).
    #[arg(long, value_enum, default_value = "clamp")]
    pub tonemap: ToneMapArg,
    /// Print the rays traced for pixel X Y (from the top-left) and draw them over the image.
    #[arg(long, num_args = 2, value_names = ["X", "Y"])]
    pub debug_pixel: Option<Vec<u32>>,
    /// No progress bar and no summary.
    #[arg(short, long)]
    pub quiet: bool,
    /// Which engine renders the image.
    #[arg(long, value_enum, default_value = "wavefront")]
    pub engine: EngineArg,
    /// Lanes of the wavefront engine's kernels: auto (16 on an AVX-512 build, but 8 for hard
    /// shadows and for 8 or fewer points per light), 8 or 16. Speed only: the image is the same.
    #[arg(long, value_enum, default_value = "auto")]
    pub lanes: LanesArg,
    /// Camera samples per wavefront tile: the unit of work and of memory.
    #[arg(long, default_value_t = raywave::render::wavefront::DEFAULT_BATCH_SIZE as u32,
          value_parser = clap::value_parser!(u32).range(1..=1 << 20))]
    pub batch_size: u32,
    /// Print rays and rays/s per kind, and per stage for the wavefront engine.
    #[arg(long)]
    pub stats: bool,
    /// Write the same figures as JSON, with the machine, SIMD path and thread count (`-`:
    /// standard output).
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
    /// Also write a cost map (.png or .ppm): each pixel's BVH nodes visited and primitives
    /// tested, in false colour with a colour bar. Counted, as the traversal figures of --stats
    /// are, by a second render of the frame (the wavefront engine's; the first counts nothing).
    #[arg(long, value_name = "FILE")]
    pub cost_map: Option<PathBuf>,
    /// Which rays the cost map counts.
    #[arg(long, value_enum, default_value = "all", requires = "cost_map")]
    pub cost_kind: CostKindArg,
    /// What the cost map shows: nodes, tests, or both side by side.
    #[arg(long, value_enum, default_value = "both", requires = "cost_map")]
    pub cost_measure: CostMeasureArg,
    /// Refuse to start a render whose estimated peak memory exceeds SIZE (e.g. 512M, 2G);
    /// renders are also refused when they exceed the memory available.
    #[arg(long, value_name = "SIZE", value_parser = raywave::output::memory::parse_size)]
    pub max_memory: Option<u64>,
    /// After rendering, print the image's error against this reference (PNG, PPM, PFM or
    /// EXR; the figures of `raywave diff`): a float reference is compared with the linear
    /// image, an 8-bit one with the 8-bit image written.
    #[arg(long, value_name = "REF")]
    pub mse_reference: Option<PathBuf>,
}

/// Renders as the flags say, then prints the summary.
pub fn run(args: &RenderArgs) -> Result<()> {
    let mut phases = Phases::since_main();
    phases.mark("arguments and signals");
    let options = FrameOptions {
        scene: args.scene.clone().or_else(|| args.input.clone()),
        image: args.image.with_seed(&args.seed),
        engine: args.engine.into(),
        lanes: args.lanes.into(),
        batch_size: args.batch_size,
        output: args.output.clone(),
        hdr: args.hdr.clone(),
        tonemap: args.tonemap.into(),
        debug_pixel: args.debug_pixel.as_ref().map(|px| [px[0], px[1]]),
        figures: args.stats || args.stats_json.is_some(),
        stats_json: args.stats_json.clone(),
        cost_map: args
            .cost_map
            .clone()
            .map(|path| (path, args.cost_kind.into(), args.cost_measure.into())),
        max_memory: args.max_memory,
        mse_reference: args.mse_reference.clone(),
        // The scene (an input) and every output of a render, checked before any work.
        plan: OutputPlan::new()
            .input_if("SCENE", args.scene.as_deref())
            .input_if("-input", args.input.as_deref())
            .output("-o", &args.output)
            .output_if("--hdr", args.hdr.as_deref())
            .output_if("--stats-json", args.stats_json.as_deref())
            .output_if("--cost-map", args.cost_map.as_deref())
            .input_if("--mse-reference", args.mse_reference.as_deref()),
    };
    let pool = thread_pool(args.workers.threads)?;
    let template = "{spinner} {msg} [{bar:40}] {pos}/{len}, {elapsed} (eta {eta})";
    let outcome = with_bar(template, args.quiet, |progress| {
        frame::run(&options, &pool, progress, &mut phases)
    })?;
    let say = |text: &str| super::image::say(&options.plan, text);
    if let Some(text) = &outcome.pixel_rays {
        say(text)?;
    }
    if !args.quiet {
        let extra: String = [&args.hdr, &args.cost_map]
            .into_iter()
            .flatten()
            .map(|p| format!(" and {}", p.display()))
            .collect();
        say(&format!(
            "{}wrote   {}{extra}\n",
            outcome.summary(),
            args.output.display()
        ))?;
    }
    if args.stats {
        say(&outcome.stats_table())?;
        say(&phases.table("tables, BVH, progress bar"))?;
    }
    if let Some(text) = &outcome.reference_error {
        say(text)?;
    }
    Ok(())
}
