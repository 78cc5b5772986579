//! `raywave view` flags, turned into `raywave::view::ViewOptions`.

use super::image::scene_and_settings;
use super::image::{ImageArgs, SeedArgs, ThreadsArg};
use super::values::EngineArg;
use anyhow::Result;
use clap::Args;
use raywave::render::engine::Engine;
use raywave::render::error::UsageError;
use raywave::view::request::{MAX_CAMERA_SAMPLES, MAX_SIDE, Resolved};
use raywave::view::{ViewOptions, run as serve};
use std::path::PathBuf;

/// Flags of `raywave view`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Scene file (.obj); without one, the built-in lab Cornell box with mirror spheres.
    pub scene: Option<PathBuf>,
    /// The settings the page starts with (it can change all but the background, ambient,
    /// ring segments and defaults).
    #[command(flatten)]
    pub image: ImageArgs,
    /// The engine the page starts with.
    #[arg(long, value_enum, default_value = "wavefront")]
    pub engine: EngineArg,
    #[command(flatten)]
    pub seed: SeedArgs,
    #[command(flatten)]
    pub workers: ThreadsArg,
    /// Camera samples per wavefront tile.
    #[arg(long, default_value_t = raywave::render::wavefront::DEFAULT_BATCH_SIZE as u32,
          value_parser = clap::value_parser!(u32).range(1..=1 << 20))]
    pub batch_size: u32,
    /// Port on 127.0.0.1 [default: a free port the system chooses]; the URL is printed.
    #[arg(long, default_value_t = 0)]
    pub port: u16,
}

/// Serves the page until Ctrl-C.
pub fn run(args: &ViewArgs) -> Result<()> {
    let (scene, effective) = scene_and_settings(args.scene.as_deref(), &args.image, &args.seed)?;
    let settings = effective.settings;
    if settings.width > MAX_SIDE || settings.height > MAX_SIDE {
        return Err(UsageError(format!(
            "--size {} {}: the viewer renders at most {MAX_SIDE} pixels a side",
            settings.width, settings.height
        ))
        .into());
    }
    let samples = settings.width as u64 * settings.height as u64 * settings.aa_samples as u64;
    if samples > MAX_CAMERA_SAMPLES {
        return Err(UsageError(format!(
            "--size × --aa is {samples} camera samples: the viewer renders at most {MAX_CAMERA_SAMPLES}"
        ))
        .into());
    }
    let base = Resolved {
        camera: scene.camera,
        settings,
        engine: Engine::from(args.engine),
    };
    let signal = serve(
        ViewOptions {
            scene,
            base,
            threads: args.workers.threads,
            batch_size: args.batch_size as usize,
            port: args.port,
        },
        &|text| raywave::output::terminal::print(text),
    )?;
    eprintln!("raywave view: stopped by {signal}");
    Ok(())
}
