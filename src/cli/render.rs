//! `raywave render`: checks what can fail cheaply, renders with the chosen engine, writes the
//! image (and the linear floats, and the `--stats-json` record), then prints the summary.

use super::image::scene_and_settings;
use super::image::{ImageArgs, SeedArgs, ThreadsArg};
use super::phases::Phases;
use super::render_report::{Report, RunInfo, record, stats_table, summary};
use super::values::{CostKindArg, CostMeasureArg, EngineArg, LanesArg, ToneMapArg};
use anyhow::Result;
use clap::Args;
use image::RgbImage;

use raywave::diff::{self, Encoding, FileInfo, Image, Region, read_image};
use raywave::output::OutputPlan;
use raywave::output::cost_map::{self, CostInput};
use raywave::output::image_file::{OutputFormat, check_hdr_path, ldr_format, output_format};
use raywave::output::memory::{self, RenderFootprint};
use raywave::output::render_record::TraversalFigures;
use raywave::output::terminal::progress_bar;
use raywave::render::camera::CameraRays;
use raywave::render::engine::{Engine, Prepared, clamped_warning};
use raywave::render::error::UsageError;
use raywave::render::film::{Film, ToneMap};
use std::path::{Path, PathBuf};
use std::time::Instant;

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

impl RenderArgs {
    /// The scene path, from the positional argument or the lab's `-input`.
    pub fn scene_path(&self) -> Option<&PathBuf> {
        self.scene.as_ref().or(self.input.as_ref())
    }
}

/// Renders as the flags say.
pub fn run(args: &RenderArgs) -> Result<()> {
    let mut phases = Phases::since_main();
    phases.mark("arguments and signals");
    // Check everything that can fail cheaply before the long part.
    let format = output_format(&args.output).map_err(|e| UsageError::from_error(&e))?;
    if let Some(hdr) = &args.hdr {
        check_hdr_path(hdr).map_err(|e| UsageError::from_error(&e))?;
    }
    if let Some(map) = &args.cost_map {
        if ldr_format(map).is_err() {
            return Err(UsageError(format!(
                "--cost-map {}: expected a file ending in .png or .ppm (an 8-bit figure)",
                map.display()
            ))
            .into());
        }
        if Engine::from(args.engine) == Engine::Reference {
            return Err(UsageError(
                "--cost-map counts the wavefront engine's traversal: expected --engine wavefront (the default), not --engine reference".into(),
            )
            .into());
        }
    }
    let plan = output_plan(args);
    plan.check()?;
    plan.refuse_binary_on_terminal(&["-o", "--hdr", "--cost-map"])?;
    // Text meant for the terminal goes to stderr when an image or record goes to stdout.
    let say = |text: &str| super::image::say(&plan, text);
    let (scene, effective) = scene_and_settings(
        args.scene_path().map(PathBuf::as_path),
        &args.image,
        &args.seed,
        &plan,
    )?;
    let settings = effective.settings.clone();
    phases.mark("outputs, scene, settings");
    if let Some(px) = &args.debug_pixel
        && (px[0] >= settings.width || px[1] >= settings.height)
    {
        return Err(UsageError(format!(
            "--debug-pixel {} {} is outside the {}×{} image",
            px[0], px[1], settings.width, settings.height
        ))
        .into());
    }
    // The reference is read and its size checked before the long part.
    let reference = match &args.mse_reference {
        Some(path) => {
            let image = read_image(path)?;
            if (image.film.width, image.film.height) != (settings.width, settings.height) {
                return Err(UsageError(format!(
                    "--mse-reference {} is {}×{} but the render is {}×{}: expected a reference of the render's size",
                    path.display(),
                    image.film.width,
                    image.film.height,
                    settings.width,
                    settings.height
                ))
                .into());
            }
            Some((path, image))
        }
        None => None,
    };
    let pool = args.workers.pool()?;
    let threads = pool.current_num_threads();
    phases.mark("thread pool");
    let engine_choice = Engine::from(args.engine);
    let exr_to_stream = |p: &PathBuf| {
        p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
            && raywave::output::target(p).is_stream()
    };
    memory::check(
        &RenderFootprint {
            pixels: settings.width as u64 * settings.height as u64,
            primitives: (scene.triangles.len() + scene.spheres.len()) as u64,
            threads: threads as u64,
            batch_size: args.batch_size as u64,
            rgb8: matches!(format, OutputFormat::Ldr(_)),
            exr_in_memory: exr_to_stream(&args.output)
                || args.hdr.as_ref().is_some_and(exr_to_stream),
            cost_map: args.cost_map.is_some(),
        },
        args.max_memory,
    )?;
    phases.mark("memory check");

    // The reference's set-up (its BVH for meshes) is timed with its render; the wavefront
    // engine's BVH build is reported on its own.
    let setup_start = Instant::now();
    let engine = engine_choice.prepare_lanes(
        &scene,
        &settings,
        args.batch_size as usize,
        args.lanes.into(),
    );
    let (units, unit) = engine.work_units(&settings);
    let progress = progress_bar(
        units,
        &format!(
            "{{spinner}} rendering [{{bar:40}}] {{pos}}/{{len}} {unit}, {{elapsed}} (eta {{eta}})"
        ),
        args.quiet,
    );
    phases.mark("tables, BVH, progress bar");
    let start = match engine_choice {
        Engine::Reference => setup_start,
        Engine::Wavefront => Instant::now(),
    };
    let (film, mut stats) = pool.install(|| engine.render(&|| progress.inc(1)));
    let seconds = start.elapsed().as_secs_f64();
    phases.mark("render");
    progress.finish_and_clear();
    if let Some(w) = clamped_warning(&stats) {
        eprintln!("{w}");
    }
    let mut img = match format {
        OutputFormat::Ldr(_) => Some(film.to_rgb8(args.tonemap.into())),
        OutputFormat::Linear => None,
    };
    if let Some(px) = &args.debug_pixel {
        // The tree both engines trace for the pixel (raywave::trace), checked against both.
        let mut tree = raywave::trace::trace_pixel(&scene, &settings, px[0], px[1])
            .map_err(|e| UsageError(format!("--debug-pixel: {e}")))?;
        tree.check = Some(raywave::trace::check_pixel(&scene, &settings, &tree));
        say(&format!(
            "rays traced for pixel ({}, {}):\n{}",
            px[0],
            px[1],
            raywave::trace::summary(&tree)
        ))?;
        match &mut img {
            Some(img) => {
                let camera = CameraRays::new(&scene.camera, settings.width, settings.height);
                raywave::trace::draw::draw_over_render(img, &tree, &camera);
            }
            None => eprintln!(
                "note: the rays are drawn only over an 8-bit image; {} holds the linear image alone",
                args.output.display()
            ),
        }
    }
    match &img {
        Some(img) => raywave::output::image_file::write_rgb8(img, &args.output)?,
        None => film.write_hdr(&args.output)?,
    }
    if let Some(hdr) = &args.hdr {
        film.write_hdr(hdr)?;
    }
    phases.mark("tone map, encode, write");
    let reference_error = match &reference {
        Some((path, image)) => Some(reference_error(
            path,
            image,
            &film,
            img.as_ref(),
            args.tonemap.into(),
        )?),
        None => None,
    };
    // The reference's render carries no timer; its kinds are timed by a second pass with
    // timers, only when the figures are asked for (its image is dropped, as are these first:
    // the memory check counted one film).
    drop((img, film));
    let mut instrumented_seconds = None;
    if let (Prepared::Reference(reference), true) =
        (&engine, args.stats || args.stats_json.is_some())
    {
        let progress = progress_bar(
            units,
            "{spinner} timing ray kinds (a second pass, with timers) [{bar:40}] {pos}/{len} rows, {elapsed} (eta {eta})",
            args.quiet,
        );
        let start = Instant::now();
        let (_, counts, times) = pool.install(|| reference.render_timed(&|| progress.inc(1)));
        instrumented_seconds = Some(start.elapsed().as_secs_f64());
        progress.finish_and_clear();
        debug_assert_eq!(counts, stats.counts);
        stats.kind_time = Some(times);
    }
    // The traversal counters: a second render with the counting instantiation of the stages,
    // so that the render timed above ran none of it.
    let mut traversal = None;
    if let (Prepared::Wavefront(wavefront), true) = (
        &engine,
        args.stats || args.stats_json.is_some() || args.cost_map.is_some(),
    ) {
        let progress = progress_bar(
            units,
            "{spinner} counting the traversal (a second pass) [{bar:40}] {pos}/{len} tiles, {elapsed} (eta {eta})",
            args.quiet,
        );
        let start = Instant::now();
        let (counted, counted_stats, costs) =
            pool.install(|| wavefront.render_counted(&|| progress.inc(1), args.cost_map.is_some()));
        let counted_seconds = start.elapsed().as_secs_f64();
        progress.finish_and_clear();
        drop(counted);
        debug_assert_eq!(counted_stats.counts, stats.counts);
        if let (Some(path), Some(pixels)) = (&args.cost_map, &costs.pixels) {
            let input = CostInput {
                pixels,
                width: settings.width,
                height: settings.height,
                aa_samples: settings.aa_samples,
                totals: &costs.totals,
                rays: &stats.counts,
            };
            let map = cost_map::figure(&input, args.cost_kind.into(), args.cost_measure.into())?;
            raywave::output::image_file::write_rgb8(&map, path)?;
        }
        traversal = Some(TraversalFigures::new(
            &costs.totals,
            &stats.counts,
            counted_seconds,
        ));
    }
    let report = Report {
        stats,
        seconds,
        stages: engine.bvh_build_seconds().map(|bvh| (stats, bvh)),
        instrumented_seconds,
        traversal,
    };

    let run = RunInfo {
        engine: engine_choice,
        simd: engine.simd_path(),
        threads,
        batch_size: args.batch_size,
    };
    if let Some(path) = &args.stats_json {
        let record = record(&scene, &effective, &run, &report);
        match &reference_error {
            Some((_, json)) => record.write_with(path, "mse_reference", json.clone())?,
            None => record.write(path)?,
        }
    }
    // Every output in place before the summary says it was written.
    raywave::output::commit_outputs()?;
    if !args.quiet {
        let extra: String = [&args.hdr, &args.cost_map]
            .into_iter()
            .flatten()
            .map(|p| format!(" and {}", p.display()))
            .collect();
        say(&format!(
            "{}wrote   {}{extra}\n",
            summary(&scene, &effective, &run, &report),
            args.output.display()
        ))?;
    }
    if args.stats {
        say(&stats_table(&report))?;
        say(&phases.table("tables, BVH, progress bar"))?;
    }
    if let Some((text, _)) = &reference_error {
        say(text)?;
    }
    Ok(())
}

/// The render's error against `--mse-reference`, as text and as JSON: the linear image against
/// a float reference, the 8-bit image written (`rgb8`, else the film tone mapped) against an
/// 8- or 16-bit one, so that `raywave diff` on the files gives the same figures.
fn reference_error(
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

/// The scene (an input) and every output of a render, for the checks before any work.
fn output_plan(args: &RenderArgs) -> OutputPlan {
    let mut plan = OutputPlan::new();
    if let Some(scene) = &args.scene {
        plan = plan.input("SCENE", scene);
    }
    if let Some(input) = &args.input {
        plan = plan.input("-input", input);
    }
    plan = plan.output("-o", &args.output);
    if let Some(hdr) = &args.hdr {
        plan = plan.output("--hdr", hdr);
    }
    if let Some(json) = &args.stats_json {
        plan = plan.output("--stats-json", json);
    }
    if let Some(map) = &args.cost_map {
        plan = plan.output("--cost-map", map);
    }
    if let Some(reference) = &args.mse_reference {
        plan = plan.input("--mse-reference", reference);
    }
    plan
}
