//! The `raywave` command. `main` owns the exit code: 0 on success, 2 for a usage error (clap),
//! 1 for anything else, printed once with its cause chain.

use anyhow::{Context, Result};
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use raywave::cli::{
    BackgroundSource, Cli, Command, Effective, MeshgenArgs, RenderArgs, UsageError,
};
use raywave::debug_view::RayRecorder;
use raywave::engine::Engine;
use raywave::film::{OutputFormat, check_hdr_path, check_output_dir, output_format};
use raywave::reference::Reference;
use raywave::scene::Scene;
use raywave::settings::{LightModel, RenderSettings, ShadowMode};
use raywave::stats::RayCounts;
use raywave::variance::command::VarianceArgs;
use raywave::wavefront::stats::RenderStats;
use std::io::Write;
use std::process::ExitCode;
use std::time::Instant;

// Standard output that fails with an error (exit 1) instead of panicking when it is closed
// (`raywave ... | head`) or full: these shadow std's macros in this file, so every function that
// prints returns a Result.
macro_rules! println {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).context("cannot write to standard output")?
    }};
}
macro_rules! print {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*).context("cannot write to standard output")?
    }};
}

fn main() -> ExitCode {
    let normalized = match raywave::cli::normalize_args(std::env::args_os()) {
        Ok(n) => n,
        Err(e) => {
            eprintln!("error: {e}\n\nFor more information, try '--help'.");
            return ExitCode::from(2);
        }
    };
    let cli = Cli::parse_from(normalized.args);
    // Lab and RPI flags accepted without effect: one line each, like the scene's warnings.
    for note in &normalized.notes {
        eprintln!("note: {note}");
    }
    let result = match cli.command {
        Command::Render(args) => render(&args),
        Command::Info => info(),
        Command::Meshgen(args) => meshgen(&args),
        Command::Variance(args) => variance(&args),
        // Exit 3 when --compare finds a regression (raywave::bench::EXIT_REGRESSION).
        Command::Bench(args) => match raywave::bench::run(&args) {
            Ok(outcome) => return ExitCode::from(outcome.exit_code()),
            Err(e) => Err(e),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<UsageError>().is_some() => {
            eprintln!("error: {e:#}\n\nFor more information, try '--help'.");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn info() -> Result<()> {
    println!("raywave {}", env!("CARGO_PKG_VERSION"));
    println!("simd    {}", raywave::simd_path());
    println!(
        "threads {} (rayon default; --threads N to change)",
        rayon::current_num_threads()
    );
    Ok(())
}

fn meshgen(args: &MeshgenArgs) -> Result<()> {
    check_output_dir(&args.output)?;
    let bands = raywave::meshgen::bands_for(args.triangles as usize);
    let text = raywave::meshgen::cornell_box_mesh_spheres(bands);
    raywave::film::write_atomically(&args.output, |w| Ok(w.write_all(text.as_bytes())?))?;
    println!(
        "wrote   {}: {} triangles ({bands} latitude bands per sphere)",
        args.output.display(),
        raywave::meshgen::triangle_count(bands)
    );
    Ok(())
}

fn variance(args: &VarianceArgs) -> Result<()> {
    let pool = thread_pool(args.threads)?;
    let engine = args.engine;
    let render = |scene: &Scene, settings: &RenderSettings| engine.image(scene, settings);
    pool.install(|| raywave::variance::command::run(args, engine.name(), &render))
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
    let format = output_format(&args.output).map_err(|e| UsageError::from_error(&e))?;
    check_output_dir(&args.output)?;
    if let Some(hdr) = &args.hdr {
        check_hdr_path(hdr).map_err(|e| UsageError::from_error(&e))?;
        check_output_dir(hdr)?;
    }
    let scene = match args.scene_path() {
        Some(path) => Scene::load_with(path, &args.image.parse_options())?,
        None => Scene::builtin_default(),
    };
    for w in &scene.warnings {
        eprintln!("{w}");
    }
    let effective = args.settings(scene.background.map(|c| c.to_array()));
    let settings = effective.settings.clone();
    if let Some(px) = &args.debug_pixel
        && (px[0] >= settings.width || px[1] >= settings.height)
    {
        return Err(UsageError(format!(
            "--debug-pixel {} {} is outside the {}×{} image",
            px[0], px[1], settings.width, settings.height
        ))
        .into());
    }
    if let Some(path) = &args.stats_json {
        check_output_dir(path)?;
    }
    let pool = thread_pool(args.threads)?;
    let threads = pool.current_num_threads();

    // The reference's set-up (its BVH for meshes) is timed with its render; the wavefront
    // engine's BVH build is reported on its own.
    let setup_start = Instant::now();
    let engine = args
        .engine
        .prepare(&scene, &settings, args.batch_size as usize);
    let (units, unit) = engine.work_units(&settings);
    let progress = progress_bar(units, unit, args.quiet);
    let start = match engine.engine() {
        Engine::Reference => setup_start,
        Engine::Wavefront => Instant::now(),
    };
    let (film, stats) = pool.install(|| engine.render(&|| progress.inc(1)));
    let seconds = start.elapsed().as_secs_f64();
    progress.finish_and_clear();
    let stages = engine.bvh_build_seconds().map(|bvh| (stats, bvh));
    let report = Report::new(stats.counts, seconds, stages);

    let mut img = match format {
        OutputFormat::Ldr(_) => Some(film.to_rgb8(args.tonemap)),
        OutputFormat::Linear => None,
    };
    if let Some(px) = &args.debug_pixel {
        let mut recorder = RayRecorder {
            miss_length: 10.0,
            ..Default::default()
        };
        let pixel = px[1] * settings.width + px[0];
        // The debug view follows the reference's recursion (both engines trace the same rays).
        let reference = Reference::new(&scene, &settings);
        let colour = reference.pixel(pixel, &mut RayCounts::default(), &mut recorder);
        println!(
            "rays traced for pixel ({}, {}), colour {:.5}:",
            px[0], px[1], colour
        );
        print!("{}", recorder.report(&scene));
        match &mut img {
            Some(img) => {
                let camera = raywave::camera::CameraRays::new(
                    &scene.camera,
                    settings.width,
                    settings.height,
                );
                recorder.draw(img, &camera);
            }
            None => eprintln!(
                "note: the rays are drawn only over an 8-bit image; {} holds the linear image alone",
                args.output.display()
            ),
        }
    }
    match &img {
        Some(img) => raywave::film::write_rgb8(img, &args.output)?,
        None => film.write_hdr(&args.output)?,
    }
    if let Some(hdr) = &args.hdr {
        film.write_hdr(hdr)?;
    }
    let run = RunInfo {
        engine: args.engine,
        threads,
        batch_size: args.batch_size,
    };
    if let Some(path) = &args.stats_json {
        let json = stats_json(&scene, &effective, &run, &report);
        raywave::film::write_atomically(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &json)?;
            Ok(writeln!(w)?)
        })?;
    }
    if !args.quiet {
        summary(&scene, &effective, &run, &report)?;
        let extra = args
            .hdr
            .as_ref()
            .map(|h| format!(" and {}", h.display()))
            .unwrap_or_default();
        println!("wrote   {}{extra}", args.output.display());
    }
    if args.stats {
        print_stats(&report)?;
    }
    Ok(())
}

fn progress_bar(len: u64, unit: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    // indicatif draws nothing when stderr is not a terminal.
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} rendering [{{bar:40}}] {{pos}}/{{len}} {unit}, {{elapsed}} (eta {{eta}})"
        ))
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar
}

fn summary(scene: &Scene, effective: &Effective, run: &RunInfo, report: &Report) -> Result<()> {
    let s = &effective.settings;
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
        "raywave {} · engine {} · simd {} · {} thread(s)",
        env!("CARGO_PKG_VERSION"),
        run.engine.name(),
        raywave::simd_path(),
        run.threads
    );
    let rings = match scene.ring_count {
        0 => String::new(),
        n => format!("; {n} ring(s) cut into faces"),
    };
    println!(
        "scene   {}: {} faces ({} triangles{rings}), {} spheres, {} light(s), {} camera",
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
        "render  {}×{}, {} bounces, shadows {shadows}, {} aa sample(s), seed {}, {} faces",
        s.width,
        s.height,
        s.bounces,
        s.aa_samples,
        s.seed,
        if s.two_sided {
            "two-sided"
        } else {
            "one-sided"
        }
    );
    let model = match s.light_model {
        LightModel::Lab => "lab (no fall-off)",
        LightModel::Rpi => "rpi (divided by π·d²)",
    };
    let background = match effective.background {
        BackgroundSource::Flag => "flag",
        BackgroundSource::Scene => "scene",
        BackgroundSource::Defaults => "default",
    };
    let [r, g, b] = s.background;
    let [ar, ag, ab] = s.ambient;
    println!(
        "light   model {model}, ambient {ar} {ag} {ab}, background {r} {g} {b} ({background})"
    );
    let defaulted = if effective.defaulted.is_empty() {
        "none needed: flags set every setting".to_string()
    } else {
        format!(
            "{} (--defaults {}) for {}",
            effective.defaults.owner(),
            effective.defaults.name(),
            effective.defaulted.join(", ")
        )
    };
    println!("default {defaulted}");
    let counts = &report.counts;
    println!(
        "rays    {} total: {} camera, {} shadow, {} reflection",
        counts.total(),
        counts.camera,
        counts.shadow,
        counts.reflection
    );
    println!(
        "time    {:.3} s, {:.2} Mrays/s",
        report.seconds,
        report.rays_per_second() / 1e6
    );
    Ok(())
}

/// How the render ran, for the summary and the JSON.
struct RunInfo {
    engine: Engine,
    threads: usize,
    batch_size: u32,
}

/// What a render measured.
struct Report {
    counts: RayCounts,
    seconds: f64,
    /// Wavefront only: per-stage figures, and the BVH build time if a BVH was used.
    stages: Option<(RenderStats, Option<f64>)>,
}

impl Report {
    fn new(counts: RayCounts, seconds: f64, stages: Option<(RenderStats, Option<f64>)>) -> Report {
        Report {
            counts,
            seconds,
            stages,
        }
    }

    fn rays_per_second(&self) -> f64 {
        self.counts.total() as f64 / self.seconds.max(1e-9)
    }

    /// (kind, rays, rays per wall-clock second).
    fn kinds(&self) -> [(&'static str, u64, f64); 4] {
        let c = &self.counts;
        let per_s = |n: u64| n as f64 / self.seconds.max(1e-9);
        [
            ("camera", c.camera, per_s(c.camera)),
            ("shadow", c.shadow, per_s(c.shadow)),
            ("reflection", c.reflection, per_s(c.reflection)),
            ("total", c.total(), per_s(c.total())),
        ]
    }
}

fn print_stats(report: &Report) -> Result<()> {
    println!("{:<12} {:>14} {:>14}", "kind", "rays", "Mrays/s");
    for (kind, rays, per_s) in report.kinds() {
        println!("{kind:<12} {rays:>14} {:>14.2}", per_s / 1e6);
    }
    if let Some((_, Some(build))) = &report.stages {
        println!("bvh build {build:.3} s");
    }
    if let Some((stats, _)) = &report.stages {
        println!(
            "{:<12} {:>14} {:>14} {:>20}",
            "stage", "rays", "thread-s", "Mrays/thread-s"
        );
        for row in stats.stage_rows() {
            println!(
                "{:<12} {:>14} {:>14.3} {:>20.2}",
                row.stage,
                row.rays,
                row.thread_seconds,
                row.rays_per_thread_second / 1e6
            );
        }
    }
    Ok(())
}

fn stats_json(
    scene: &Scene,
    effective: &Effective,
    run: &RunInfo,
    report: &Report,
) -> serde_json::Value {
    let settings = &effective.settings;
    let kinds: serde_json::Map<String, serde_json::Value> = report
        .kinds()
        .iter()
        .map(|&(kind, rays, per_s)| {
            (
                kind.to_string(),
                serde_json::json!({ "rays": rays, "rays_per_second": per_s }),
            )
        })
        .collect();
    let (stages, bvh) = match &report.stages {
        Some((stats, bvh)) => (serde_json::to_value(stats.stage_rows()).ok(), Some(*bvh)),
        None => (None, None),
    };
    let (bvh, bvh_build_seconds) = match bvh {
        Some(Some(t)) => (Some(true), Some(t)),
        Some(None) => (Some(false), None),
        None => (None, None),
    };
    serde_json::json!({
        "raywave": env!("CARGO_PKG_VERSION"),
        "machine": {
            "cpu": raywave::machine::cpu_model(),
            "logical_cpus": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
            "os": std::env::consts::OS,
            "arch": std::env::consts::ARCH,
        },
        "simd": raywave::simd_path(),
        "threads": run.threads,
        "engine": run.engine,
        "batch_size": run.batch_size,
        "scene": {
            "source": scene.source,
            "triangles": scene.triangles.len(),
            "spheres": scene.spheres.len(),
            "lights": scene.lights.len(),
            "bvh": bvh,
            "bvh_build_seconds": bvh_build_seconds,
        },
        "settings": settings,
        "defaults": { "from": effective.defaults, "for": effective.defaulted },
        "seconds": report.seconds,
        "rays": kinds,
        "stages": stages,
    })
}
