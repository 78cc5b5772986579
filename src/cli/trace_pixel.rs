//! `raywave trace-pixel X Y [SCENE]`: one pixel's ray tree, checked against both engines'
//! render of that pixel, written as JSON, OBJ, PLY and a PNG from a debug camera, or printed
//! as a readable summary when no output is asked for.

use super::image::{ImageArgs, SeedArgs, ThreadsArg};
use super::values::{ToneMapArg, float};
use anyhow::{Context, Result};
use clap::Args;
use raywave::frame::scene_and_settings;
use raywave::output::image_file::{ldr_format, write_json};
use raywave::output::terminal::with_bar;
use raywave::output::{OutputPlan, write_output};
use raywave::render::camera::CameraRays;
use raywave::render::engine::{Engine, clamped_warning, thread_pool};
use raywave::render::error::UsageError;
use raywave::render::wavefront::DEFAULT_BATCH_SIZE;
use raywave::trace::draw::{Overlay, depth_buffer};
use raywave::trace::view::ViewPlacement;
use raywave::trace::{check_pixel, mesh, obj, ply, scene_bounds, summary, trace_pixel};
use std::path::PathBuf;

/// `raywave trace-pixel` flags.
#[derive(Args, Debug, Clone)]
pub struct TracePixelArgs {
    /// Column of the pixel, from the left (0-based).
    pub x: u32,
    /// Row of the pixel, from the top (0-based).
    pub y: u32,
    /// Scene file (.obj); without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// Size, bounces, shadows, lighting and sampling: the render's flags, so the tree is that
    /// render's pixel.
    #[command(flatten)]
    pub image: ImageArgs,
    #[command(flatten)]
    pub seed: SeedArgs,
    /// Write the tree as JSON (docs/TRACE.md; `-`: standard output).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write the scene and the rays as a Wavefront OBJ (`l` lines, one object per kind; `-`:
    /// standard output).
    #[arg(long, value_name = "FILE")]
    pub obj: Option<PathBuf>,
    /// Write the scene and the rays as an ASCII PLY (`edge` elements; `-`: standard output).
    #[arg(long, value_name = "FILE")]
    pub ply: Option<PathBuf>,
    /// Render the scene from the debug camera with the rays drawn over it (.png or .ppm; `-`:
    /// PNG to standard output).
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// Place the debug camera's eye here (before --orbit), looking at the render camera's
    /// point of interest [default: the render camera's eye].
    #[arg(long, num_args = 3, action = clap::ArgAction::Set, value_names = ["X", "Y", "Z"],
          allow_negative_numbers = true,
          value_parser = float("a finite number", f32::is_finite))]
    pub view_from: Option<Vec<f32>>,
    /// Turn the debug camera this many degrees about the scene's up axis, around the point of
    /// interest [default: 30, or 0 with --view-from].
    #[arg(long, value_name = "DEG", allow_negative_numbers = true, value_parser = float("a finite number", f32::is_finite))]
    pub orbit: Option<f32>,
    /// Multiply the debug camera's distance from the point of interest by F (above 1 backs
    /// away to show more around the tree).
    #[arg(long, value_name = "F", default_value_t = 1.0, value_parser = float("a positive number", |x: f32| x.is_finite() && x > 0.0))]
    pub view_distance: f32,
    /// Size of the debug camera's image [default: the render's size].
    #[arg(long, num_args = 2, action = clap::ArgAction::Set, value_names = ["W", "H"],
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub view_size: Option<Vec<u32>>,
    /// Draw only the scene and the render camera's marker in the PNG, not the rays.
    #[arg(long)]
    pub no_rays: bool,
    /// Tone mapping of the PNG: clamp (the lab's look) or exp (1 − e^(−3x)).
    #[arg(long, value_enum, default_value = "clamp")]
    pub tonemap: ToneMapArg,
    #[command(flatten)]
    pub workers: ThreadsArg,
}

impl TracePixelArgs {
    /// The output flags, with their paths.
    fn outputs(&self) -> [(&'static str, &Option<PathBuf>); 4] {
        [
            ("--json", &self.json),
            ("--obj", &self.obj),
            ("--ply", &self.ply),
            ("--png", &self.png),
        ]
    }
}

/// Traces, checks and writes as the flags say.
pub fn run(args: &TracePixelArgs) -> Result<()> {
    if let Some(png) = &args.png {
        ldr_format(png).map_err(|e| UsageError::from_error(&e))?;
    }
    // The scene (an input) and the outputs, checked before any work.
    let plan = OutputPlan::new().input_if("SCENE", args.scene.as_deref());
    let plan = (args.outputs().into_iter()).fold(plan, |plan, (flag, path)| {
        plan.output_if(flag, path.as_deref())
    });
    plan.check()?;
    plan.refuse_binary_on_terminal(&["--png"])?;

    let (scene, effective) = scene_and_settings(
        args.scene.as_deref(),
        &args.image.with_seed(&args.seed),
        &plan,
        &|w| eprintln!("{w}"),
    )?;
    let settings = effective.settings;
    let mut tree =
        trace_pixel(&scene, &settings, args.x, args.y).map_err(|e| UsageError(e.to_string()))?;
    let placement = ViewPlacement {
        from: args.view_from.as_deref().map(glam::Vec3::from_slice),
        orbit_degrees: args.orbit.unwrap_or(if args.view_from.is_some() {
            0.0
        } else {
            raywave::trace::view::DEFAULT_ORBIT_DEGREES
        }),
        distance: args.view_distance,
    };
    let view_camera = (args.png.as_ref())
        .map(|_| placement.camera(&scene.camera).map_err(UsageError))
        .transpose()?;
    tree.check = Some(check_pixel(&scene, &settings, &tree));

    let say = |text: &str| super::image::say(&plan, text);
    let title = format!(
        "raywave trace-pixel {} {}: {}",
        args.x, args.y, scene.source
    );
    if let Some(path) = &args.json {
        write_json(path, &tree)?;
    }
    if args.obj.is_some() || args.ply.is_some() {
        let groups = mesh::groups(&scene, &tree);
        if let Some(path) = &args.obj {
            write_output(path, |w| Ok(obj::write_obj(w, &title, &groups)?))?;
        }
        if let Some(path) = &args.ply {
            write_output(path, |w| Ok(ply::write_ply(w, &title, &groups)?))?;
        }
    }
    if let (Some(path), Some(camera)) = (&args.png, view_camera) {
        let (width, height) =
            (args.view_size.as_ref()).map_or((settings.width, settings.height), |s| (s[0], s[1]));
        let mut view_scene = scene.clone();
        view_scene.camera = camera;
        let view_settings = raywave::render::settings::RenderSettings {
            width,
            height,
            ..settings.clone()
        };
        let pool = thread_pool(args.workers.threads)?;
        let engine = Engine::Wavefront.prepare(&view_scene, &view_settings, DEFAULT_BATCH_SIZE);
        let rays = CameraRays::new(&camera, width, height);
        let template = "{spinner} rendering the debug view [{bar:40}] {pos}/{len} {msg}";
        let (film, depth) = with_bar(template, false, |progress| {
            pool.install(|| {
                let (film, stats) = engine.render(progress);
                if let Some(w) = clamped_warning(&stats) {
                    (progress.notice)(&w);
                }
                (film, depth_buffer(&view_scene, &rays, settings.two_sided))
            })
        });
        let mut img = film.to_rgb8(args.tonemap.into());
        let (lo, hi) = scene_bounds(&scene);
        Overlay {
            camera: rays,
            depth: &depth,
            diagonal: (hi - lo).length(),
        }
        .draw(
            &mut img,
            &tree,
            &scene.camera,
            settings.width as f32 / settings.height as f32,
            !args.no_rays,
        );
        raywave::output::image_file::write_rgb8(&img, path)
            .with_context(|| format!("cannot write --png {}", path.display()))?;
    }
    let wrote: Vec<String> = (args.outputs().iter())
        .filter_map(|(flag, p)| p.as_ref().map(|p| format!("{flag} {}", p.display())))
        .collect();
    if wrote.is_empty() {
        say(&summary(&tree))?;
    } else {
        let check = tree.check.as_ref().expect("checked above");
        let (camera, reflection, shadow, blocked) = raywave::trace::summary::counts(&tree);
        say(&format!(
            "pixel ({}, {}): {camera} camera, {reflection} reflection, {shadow} shadow ({blocked} blocked) segments\n\
             sum ({:.6}, {:.6}, {:.6}); reference |difference| {:.2e}, wavefront |difference| {:.2e}, tolerance {:.1e}: {}\n\
             wrote   {}\n",
            args.x,
            args.y,
            tree.sum[0],
            tree.sum[1],
            tree.sum[2],
            check.reference_difference,
            check.wavefront_difference,
            check.tolerance,
            if check.agrees { "agrees" } else { "MISMATCH" },
            wrote.join(", ")
        ))?;
    }
    Ok(())
}

/// The debug camera's flags without `--png`: they shape only that image.
pub fn meaningless(args: &TracePixelArgs) -> Vec<String> {
    if args.png.is_some() {
        return Vec::new();
    }
    let given = [
        ("--view-from", args.view_from.is_some()),
        ("--orbit", args.orbit.is_some()),
        ("--view-distance", args.view_distance != 1.0),
        ("--view-size", args.view_size.is_some()),
        ("--no-rays", args.no_rays),
        ("--tonemap", args.tonemap != ToneMapArg::Clamp),
        ("--threads", args.workers.threads.is_some()),
    ];
    given
        .iter()
        .filter(|(_, set)| *set)
        .map(|(flag, _)| {
            format!("{flag} has no effect without --png (it shapes the debug camera's image only)")
        })
        .collect()
}
