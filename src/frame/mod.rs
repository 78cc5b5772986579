//! `raywave render` without its flags: one frame checked, rendered, measured and written.
//! [`run`] returns what the command prints; the binary maps its flags to [`FrameOptions`] and
//! prints the [`Outcome`], as it does for `raywave bench`.
//!
//! The order is the command's promise: everything that can fail cheaply (outputs, the scene,
//! the debug pixel, the reference image, the memory estimate) fails before the render; the
//! image and the other files are written whole; the summary is printed only once they are.

pub mod phases;
pub mod report;

use crate::diff::{Image, read_image};
use crate::output::OutputPlan;
use crate::output::bench_record::KindFigures;
use crate::output::cost_map::{self, CostInput, CostKind, CostMeasure};
use crate::output::image_file::{OutputFormat, hdr_format, ldr_format, output_format};
use crate::output::machine::Machine;
use crate::output::memory::{self, RenderFootprint};
use crate::output::render_record::{
    DefaultsUsed, KindTiming, RenderRecord, SceneFigures, TraversalFigures,
};
use crate::render::camera::CameraRays;
use crate::render::engine::{Engine, Prepared, clamped_warning};
use crate::render::error::UsageError;
use crate::render::film::ToneMap;
use crate::render::progress::Progress;
use crate::render::scene::{Scene, load_scene};
use crate::render::settings::options::{Effective, ImageOptions};
use crate::render::wavefront::lanes::LaneWidth;
use crate::render::wavefront::shadow::ShadowPath;
use anyhow::{Result, bail};
use phases::Phases;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What `raywave render` is asked to do (its flags, as plain values).
pub struct FrameOptions {
    /// Scene file; `None` for the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// Size, bounces, shadows, lighting, sampling, the seed and the facing.
    pub image: ImageOptions,
    /// Which engine renders.
    pub engine: Engine,
    /// The wavefront engine's lane width (speed only).
    pub lanes: LaneWidth,
    /// Camera samples per wavefront tile.
    pub batch_size: u32,
    /// The image: 8-bit (.png, .ppm) or linear floats (.pfm, .exr).
    pub output: PathBuf,
    /// Also the linear floats here.
    pub hdr: Option<PathBuf>,
    /// Tone mapping of the 8-bit image.
    pub tonemap: ToneMap,
    /// The pixel whose rays are traced, listed and drawn over the image.
    pub debug_pixel: Option<[u32; 2]>,
    /// Time each ray kind and count the traversal (`--stats`, `--stats-json`).
    pub figures: bool,
    /// Write the render record here.
    pub stats_json: Option<PathBuf>,
    /// Write a cost map here, of these rays and this measure.
    pub cost_map: Option<(PathBuf, CostKind, CostMeasure)>,
    /// Refuse a render whose estimated peak memory exceeds this many bytes.
    pub max_memory: Option<u64>,
    /// Give the image's error against this reference.
    pub mse_reference: Option<PathBuf>,
    /// The command's inputs and outputs (every path above), checked before any work.
    pub plan: OutputPlan,
}

/// What a render did, for the command to print.
pub struct Outcome {
    /// The scene rendered.
    pub scene: Scene,
    /// The settings it was rendered with, and where each came from.
    pub effective: Effective,
    /// How the wavefront engine's shadow stage ran; `None` for the reference.
    pub shadow_path: Option<ShadowPath>,
    /// How it ran and what it measured, as `--stats-json` writes it.
    pub record: RenderRecord,
    /// With a debug pixel: the rays traced for it.
    pub pixel_rays: Option<String>,
    /// With a reference: the error table.
    pub reference_error: Option<String>,
}

/// Loads the scene at `path` (the built-in one for `None`), its warnings to `notice`, checks
/// that no output of `plan` is a file it reads, and resolves `image` against it: the one way
/// `render`, `trace-pixel` and `view` turn their flags into a scene and settings.
pub fn scene_and_settings(
    path: Option<&Path>,
    image: &ImageOptions,
    plan: &OutputPlan,
    notice: &dyn Fn(&str),
) -> Result<(Scene, Effective)> {
    let scene = load_scene(path, &image.parse_options())?.scene;
    for w in &scene.warnings {
        notice(&w.to_string());
    }
    plan.check_scene_files("SCENE", &scene)?;
    let effective = image.resolve(scene.background.map(|c| c.to_array()));
    effective
        .settings
        .check_sampler()
        .map_err(|e| UsageError(e.to_string()))?;
    Ok((scene, effective))
}

/// Renders as `options` say, writes every file, and returns what to print. The phases of the
/// wall time are marked in `phases`; the render passes report to `progress`.
pub fn run(
    options: &FrameOptions,
    pool: &rayon::ThreadPool,
    progress: &Progress,
    phases: &mut Phases,
) -> Result<Outcome> {
    // An 8-bit image is made unless `-o` names a float format.
    let rgb8 = matches!(check_outputs(options)?, OutputFormat::Ldr(_));
    let (scene, effective) = scene_and_settings(
        options.scene.as_deref(),
        &options.image,
        &options.plan,
        progress.notice,
    )?;
    let settings = &effective.settings;
    phases.mark("outputs, scene, settings");
    if let Some([x, y]) = options.debug_pixel
        && (x >= settings.width || y >= settings.height)
    {
        bail!(UsageError(format!(
            "--debug-pixel {x} {y} is outside the {}×{} image",
            settings.width, settings.height
        )));
    }
    let reference = match &options.mse_reference {
        Some(path) => Some((path, read_reference(path, settings.width, settings.height)?)),
        None => None,
    };
    let threads = pool.current_num_threads();
    phases.mark("thread pool");
    let exr_to_stream = |p: &PathBuf| {
        p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
            && crate::output::target(p).is_stream()
    };
    memory::check(
        &RenderFootprint {
            pixels: settings.width as u64 * settings.height as u64,
            primitives: (scene.triangles.len() + scene.spheres.len()) as u64,
            threads: threads as u64,
            batch_size: options.batch_size as u64,
            rgb8,
            exr_in_memory: exr_to_stream(&options.output)
                || options.hdr.as_ref().is_some_and(exr_to_stream),
            cost_map: options.cost_map.is_some(),
        },
        options.max_memory,
    )?;
    phases.mark("memory check");

    // The reference's set-up (its BVH for meshes) is timed with its render; the wavefront
    // engine's BVH build is reported on its own.
    let setup_start = Instant::now();
    let engine =
        options
            .engine
            .prepare_lanes(&scene, settings, options.batch_size as usize, options.lanes);
    phases.mark("tables, BVH, progress bar");
    let start = match options.engine {
        Engine::Reference => setup_start,
        Engine::Wavefront => Instant::now(),
    };
    let (film, mut stats) = progress.within("rendering", |p| pool.install(|| engine.render(p)));
    let seconds = start.elapsed().as_secs_f64();
    phases.mark("render");
    if let Some(w) = clamped_warning(&stats) {
        (progress.notice)(&w);
    }
    let mut img = rgb8.then(|| film.to_rgb8(options.tonemap));
    let mut pixel_rays = None;
    if let Some([x, y]) = options.debug_pixel {
        // The tree both engines trace for the pixel (crate::trace), checked against both.
        let mut tree = crate::trace::trace_pixel(&scene, settings, x, y)
            .map_err(|e| UsageError(format!("--debug-pixel: {e}")))?;
        tree.check = Some(crate::trace::check_pixel(&scene, settings, &tree));
        pixel_rays = Some(format!(
            "rays traced for pixel ({x}, {y}):\n{}",
            crate::trace::summary(&tree)
        ));
        match &mut img {
            Some(img) => {
                let camera = CameraRays::new(&scene.camera, settings.width, settings.height);
                crate::trace::draw::draw_over_render(img, &tree, &camera);
            }
            None => (progress.notice)(&format!(
                "note: the rays are drawn only over an 8-bit image; {} holds the linear image alone",
                options.output.display()
            )),
        }
    }
    match &img {
        Some(img) => crate::output::image_file::write_rgb8(img, &options.output)?,
        None => film.write_hdr(&options.output)?,
    }
    if let Some(hdr) = &options.hdr {
        film.write_hdr(hdr)?;
    }
    phases.mark("tone map, encode, write");
    let reference_error = reference
        .as_ref()
        .map(|(path, image)| {
            report::reference_error(path, image, &film, img.as_ref(), options.tonemap)
        })
        .transpose()?;
    // The second passes below render again: the memory check counted one film.
    drop((img, film));
    // The reference's render carries no timer; its kinds are timed by a second pass with
    // timers, only when the figures are asked for.
    let mut instrumented_seconds = None;
    if let (Prepared::Reference(reference), true) = (&engine, options.figures) {
        let start = Instant::now();
        let (_, counts, times) = progress
            .within("timing ray kinds (a second pass, with timers)", |p| {
                pool.install(|| reference.render_timed(p))
            });
        instrumented_seconds = Some(start.elapsed().as_secs_f64());
        debug_assert_eq!(counts, stats.counts);
        stats.kind_time = Some(times);
    }
    // The traversal counters: a second render with the counting instantiation of the stages,
    // so that the render timed above ran none of it.
    let mut traversal = None;
    if let (Prepared::Wavefront(wavefront), true) =
        (&engine, options.figures || options.cost_map.is_some())
    {
        let start = Instant::now();
        let (_, counted_stats, costs) = progress
            .within("counting the traversal (a second pass)", |p| {
                pool.install(|| wavefront.render_counted(p, options.cost_map.is_some()))
            });
        let counted_seconds = start.elapsed().as_secs_f64();
        debug_assert_eq!(counted_stats.counts, stats.counts);
        if let (Some((path, kind, measure)), Some(pixels)) = (&options.cost_map, &costs.pixels) {
            let input = CostInput {
                pixels,
                width: settings.width,
                height: settings.height,
                aa_samples: settings.aa_samples,
                totals: &costs.totals,
                rays: &stats.counts,
            };
            let map = cost_map::figure(&input, *kind, *measure)?;
            crate::output::image_file::write_rgb8(&map, path)?;
        }
        traversal = Some(TraversalFigures::new(
            &costs.totals,
            &stats.counts,
            counted_seconds,
        ));
    }
    // The wavefront engine's BVH build time if it used a BVH; `None` for the reference.
    let (shadow_path, bvh) = (engine.shadow_path(), engine.bvh_build_seconds());
    let record = RenderRecord {
        format: crate::output::bench_record::FORMAT,
        raywave: env!("CARGO_PKG_VERSION"),
        // Read (from /proc/cpuinfo) only when the record is written: nothing else shows it.
        // The record has never named the host.
        machine: match options.stats_json {
            Some(_) => Machine {
                hostname: String::new(),
                ..Machine::current()
            },
            None => Machine::default(),
        },
        simd: engine.simd_path(),
        threads,
        engine: options.engine,
        batch_size: options.batch_size,
        shadow_path: shadow_path.map(ShadowPath::name),
        scene: SceneFigures {
            source: scene.source.clone(),
            triangles: scene.triangles.len(),
            spheres: scene.spheres.len(),
            lights: scene.lights.len(),
            bvh: bvh.map(|b| b.is_some()),
            bvh_build_seconds: bvh.flatten(),
        },
        settings: settings.clone(),
        defaults: DefaultsUsed {
            from: effective.defaults.name(),
            settings: effective.defaulted.clone(),
        },
        seconds,
        rays: KindFigures::new(&stats, seconds),
        kinds_timed_by: match instrumented_seconds {
            Some(_) => KindTiming::InstrumentedPass,
            None => KindTiming::StageTimers,
        },
        instrumented_seconds,
        stages: bvh.map(|_| stats.stage_figures()),
        traversal,
    };
    drop(engine);
    let (reference_error, reference_json) = reference_error.unzip();
    if let Some(path) = &options.stats_json {
        let extra = reference_json.map(|json| ("mse_reference", json));
        record.write(path, extra)?;
    }
    // Every output in place before the summary says it was written.
    crate::output::commit_outputs()?;
    Ok(Outcome {
        scene,
        effective,
        shadow_path,
        record,
        pixel_rays,
        reference_error,
    })
}

/// The checks of the outputs' names and of the plan, before the scene is read; returns the
/// image's format.
fn check_outputs(options: &FrameOptions) -> Result<OutputFormat> {
    let format = output_format(&options.output).map_err(|e| UsageError::from_error(&e))?;
    if let Some(hdr) = &options.hdr {
        hdr_format(hdr).map_err(|e| UsageError::from_error(&e))?;
    }
    if let Some((map, _, _)) = &options.cost_map {
        if ldr_format(map).is_err() {
            bail!(UsageError(format!(
                "--cost-map {}: expected a file ending in .png or .ppm (an 8-bit figure)",
                map.display()
            )));
        }
        if options.engine == Engine::Reference {
            bail!(UsageError(
                "--cost-map counts the wavefront engine's traversal: expected --engine wavefront (the default), not --engine reference".into(),
            ));
        }
    }
    options.plan.check()?;
    options
        .plan
        .refuse_binary_on_terminal(&["-o", "--hdr", "--cost-map"])?;
    Ok(format)
}

/// The reference image at `path`, refused unless it is `width`×`height`.
fn read_reference(path: &Path, width: u32, height: u32) -> Result<Image> {
    let image = read_image(path)?;
    if (image.film.width, image.film.height) != (width, height) {
        bail!(UsageError(format!(
            "--mse-reference {} is {}×{} but the render is {width}×{height}: expected a reference of the render's size",
            path.display(),
            image.film.width,
            image.film.height,
        )));
    }
    Ok(image)
}
