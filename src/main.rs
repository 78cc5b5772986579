//! The `raywave` command. `main` owns the exit code: 0 on success, 2 for a usage error (clap),
//! 1 for anything else, printed once with its cause chain.

use anyhow::{Context, Result, bail};
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use raywave::cli::{Cli, Command, RenderArgs};
use raywave::debug_view::RayRecorder;
use raywave::film::{check_hdr_path, check_output_dir, ldr_format};
use raywave::reference::Reference;
use raywave::scene::Scene;
use raywave::settings::{RenderSettings, ShadowMode};
use raywave::stats::RayCounts;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let cli = Cli::parse_from(raywave::cli::normalize_args(std::env::args_os()));
    let result = match cli.command {
        Command::Render(args) => render(&args),
        Command::Info => {
            info();
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn info() {
    println!("raywave {}", env!("CARGO_PKG_VERSION"));
    println!("simd    {}", raywave::simd_path());
    println!(
        "threads {} (rayon default; --threads N to change)",
        rayon::current_num_threads()
    );
}

fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n as usize);
    }
    builder.build().context("cannot start the worker threads")
}

fn render(args: &RenderArgs) -> Result<()> {
    // Check everything that can fail cheaply before the long part.
    ldr_format(&args.output)?;
    check_output_dir(&args.output)?;
    if let Some(hdr) = &args.hdr {
        check_hdr_path(hdr)?;
        check_output_dir(hdr)?;
    }
    let scene = match args.scene_path() {
        Some(path) => Scene::load(path)?,
        None => Scene::builtin_default(),
    };
    for w in &scene.warnings {
        eprintln!("{w}");
    }
    let settings = args.settings(scene.background.map(|c| c.to_array()));
    if let Some(px) = &args.debug_pixel {
        if px[0] >= settings.width || px[1] >= settings.height {
            bail!(
                "--debug-pixel {} {} is outside the {}×{} image",
                px[0],
                px[1],
                settings.width,
                settings.height
            );
        }
    }
    let pool = thread_pool(args.threads)?;
    let threads = pool.current_num_threads();

    let reference = Reference::new(&scene, &settings);
    let progress = progress_bar(settings.height as u64, args.quiet);
    let start = Instant::now();
    let (film, counts) = pool.install(|| reference.render(&|| progress.inc(1)));
    let seconds = start.elapsed().as_secs_f64();
    progress.finish_and_clear();

    let mut img = film.to_rgb8(args.tonemap);
    if let Some(px) = &args.debug_pixel {
        let mut recorder = RayRecorder {
            miss_length: 10.0,
            ..Default::default()
        };
        let pixel = px[1] * settings.width + px[0];
        let colour = reference.pixel(pixel, &mut RayCounts::default(), &mut recorder);
        println!(
            "rays traced for pixel ({}, {}), colour {:.5}:",
            px[0], px[1], colour
        );
        print!("{}", recorder.report(&scene));
        let camera =
            raywave::camera::CameraRays::new(&scene.camera, settings.width, settings.height);
        recorder.draw(&mut img, &camera);
    }
    raywave::film::write_atomically(&args.output, |w| {
        img.write_to(w, ldr_format(&args.output)?)
            .map_err(anyhow::Error::from)
    })?;
    if let Some(hdr) = &args.hdr {
        film.write_hdr(hdr)?;
    }
    if !args.quiet {
        summary(&scene, &settings, threads, &counts, seconds);
        let extra = args
            .hdr
            .as_ref()
            .map(|h| format!(" and {}", h.display()))
            .unwrap_or_default();
        println!("wrote   {}{extra}", args.output.display());
    }
    Ok(())
}

fn progress_bar(rows: u64, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    // indicatif draws nothing when stderr is not a terminal.
    let bar = ProgressBar::with_draw_target(Some(rows), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} rendering [{bar:40}] {pos}/{len} rows, {elapsed} (eta {eta})",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar
}

fn summary(scene: &Scene, s: &RenderSettings, threads: usize, counts: &RayCounts, seconds: f64) {
    let shadows = match s.shadows {
        ShadowMode::Off => "off (every light visible)".to_string(),
        ShadowMode::Hard => "hard (light centroids)".to_string(),
        ShadowMode::Soft => format!(
            "soft, {} {} points per light",
            s.shadow_samples,
            s.sampler.name()
        ),
    };
    println!(
        "raywave {} · engine reference · simd {} · {threads} thread(s)",
        env!("CARGO_PKG_VERSION"),
        raywave::simd_path()
    );
    println!(
        "scene   {}: {} faces ({} triangles), {} spheres, {} light(s), {} camera",
        scene.source,
        scene.face_count,
        scene.triangles.len(),
        scene.spheres.len(),
        scene.lights.len(),
        if scene.camera_from_file {
            "file"
        } else {
            "lab default"
        }
    );
    println!(
        "render  {}×{}, {} bounces, shadows {shadows}, {} aa sample(s), seed {}",
        s.width, s.height, s.bounces, s.aa_samples, s.seed
    );
    println!(
        "rays    {} total: {} camera, {} shadow, {} reflection",
        counts.total(),
        counts.camera,
        counts.shadow,
        counts.reflection
    );
    println!(
        "time    {seconds:.3} s, {:.2} Mrays/s",
        counts.total() as f64 / seconds.max(1e-9) / 1e6
    );
}
