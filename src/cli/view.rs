//! `raywave view` flags, turned into `raywave::view::ViewOptions`.

use super::image::{ImageArgs, SeedArgs, ThreadsArg};
use super::values::EngineArg;
use anyhow::{Result, bail};
use clap::Args;
use raywave::frame::scene_and_settings;
use raywave::render::engine::Engine;
use raywave::render::error::UsageError;
use raywave::view::request::{MAX_CAMERA_SAMPLES, MAX_SIDE, Resolved};
use raywave::view::server::DEFAULT_MAX_CONNECTIONS;
use raywave::view::token::{Access, Token};
use raywave::view::{ViewOptions, run as serve};
use std::net::IpAddr;
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
    /// Port [default: a free port the system chooses]; the URL is printed.
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// The address to listen on. Loopback by default; any other (a LAN address, 0.0.0.0 for
    /// every interface) needs the token, and a warning names it.
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1")]
    pub bind: IpAddr,
    /// The access token every request must carry [default: 192 random bits, new at every
    /// start]: 16 to 256 of A-Z a-z 0-9 - . _ ~. For scripts; prefer the variable, which other
    /// users cannot read in the process list.
    #[arg(long, value_name = "TOKEN", env = "RAYWAVE_VIEW_TOKEN", hide_env_values = true,
          value_parser = Token::parse, conflicts_with = "no_token")]
    pub token: Option<Token>,
    /// Serve without a token: every local user and process can then drive the server.
    /// Loopback only.
    #[arg(long)]
    pub no_token: bool,
    /// Connections open at once; past it, new ones are answered 503 with Retry-After.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_CONNECTIONS as u32,
          value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub max_connections: u32,
}

/// Serves the page until Ctrl-C (exit 130) or SIGTERM (143); returns the exit code.
pub fn run(args: &ViewArgs) -> Result<u8> {
    let access = access(args)?;
    let (scene, effective) = scene_and_settings(
        args.scene.as_deref(),
        &args.image.with_seed(&args.seed),
        // The viewer writes no file.
        &raywave::output::OutputPlan::new(),
        &|w| eprintln!("{w}"),
    )?;
    let settings = effective.settings;
    if settings.width > MAX_SIDE || settings.height > MAX_SIDE {
        bail!(UsageError(format!(
            "--size {} {}: the viewer renders at most {MAX_SIDE} pixels a side",
            settings.width, settings.height
        )));
    }
    let samples = settings.width as u64 * settings.height as u64 * settings.aa_samples as u64;
    if samples > MAX_CAMERA_SAMPLES {
        bail!(UsageError(format!(
            "--size × --aa is {samples} camera samples: the viewer renders at most {MAX_CAMERA_SAMPLES}"
        )));
    }
    let base = Resolved {
        camera: scene.camera,
        settings,
        engine: Engine::from(args.engine),
        cost_map: Default::default(),
        cost_measure: Default::default(),
    };
    let signal = serve(
        ViewOptions {
            scene,
            base,
            threads: args.workers.threads,
            batch_size: args.batch_size as usize,
            // Compiled here, in the binary: see `ViewOptions::counted`.
            counted: |w, progress, cancel| w.render_counted_until(progress, true, cancel),
            bind: args.bind,
            port: args.port,
            access,
            max_connections: args.max_connections as usize,
        },
        &|text| raywave::output::terminal::print(text),
    )?;
    let (name, code) = match signal {
        signal_hook::consts::SIGTERM => ("SIGTERM", 143),
        _ => ("SIGINT", 130),
    };
    eprintln!("raywave view: stopped by {name}");
    Ok(code)
}

/// The token to require: given, generated, or none (loopback only); warns when the server is
/// reachable from elsewhere.
fn access(args: &ViewArgs) -> Result<Access> {
    let loopback = args.bind.is_loopback();
    if args.no_token && !loopback {
        bail!(UsageError(format!(
            "--bind {} --no-token: a server on an address other than loopback needs its token \
             (leave out --no-token)",
            args.bind
        )));
    }
    if !loopback {
        let whom = if args.bind.is_unspecified() {
            "every interface of this machine".to_string()
        } else {
            args.bind.to_string()
        };
        eprintln!(
            "warning: --bind {}: serving on {whom}; anyone who can reach it and holds the \
             token can start renders here (docs/VIEWER.md shows an SSH tunnel instead)",
            args.bind
        );
    }
    Ok(match (&args.token, args.no_token) {
        (_, true) => Access::Open,
        (Some(token), false) => Access::Token(token.clone()),
        (None, false) => Access::Token(
            Token::random().map_err(|e| anyhow::anyhow!("cannot draw a random token: {e}"))?,
        ),
    })
}
