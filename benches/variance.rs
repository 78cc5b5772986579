//! The noise side of the benchmarks: for each light sampler, the MSE against a converged
//! reference at fixed budgets, printed beside criterion's timing of the same render and
//! checked against a committed record (`benches/baselines/variance.json`).
//!
//! ```text
//! scene     = the built-in lab Cornell box, 64×64, 5 bounces, 1 aa sample   (CONFIG below)
//! reference = converged_reference(...)        src/variance, cached under the target dir
//! penumbra  = penumbra_mask(...)              src/variance
//! for sampler in random, stratified, sobol, lab; for N in 16, 64:
//!     images = wavefront render, seeds 1..=SEEDS                  (fixed: pure hash of seed)
//!     MSE    = error_stats(images, reference, penumbra)          src/variance
//!     compare with the record; criterion times one render (seed 1)
//! table: sampler, N, penumbra MSE, its 95% interval over seeds (bootstrap, as the study),
//!        record, change, whole-image MSE, ms/image
//! ```
//!
//! With fixed seeds every MSE is a deterministic function of the code, so a change is a real
//! change, never noise. **Any rise fails** (exit code 1, after the timings, in `cargo bench`
//! and in CI's one-shot test mode alike); a fall passes with a note to re-record. Re-record
//! deliberately, after checking that the change is meant:
//!
//! `RAYWAVE_RECORD=1 cargo bench --bench variance -- --test`
//!
//! See docs/BENCHMARKING.md ("The variance suite").

mod common;

use criterion::{BenchmarkId, Throughput};
use raywave::render::engine::Engine;
use raywave::render::film::Film;
use raywave::render::per_kind::RayCounts;
use raywave::render::sampling::LightSampler;
use raywave::render::scene::Scene;
use raywave::render::settings::RenderSettings;
use raywave::stats::{BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, bootstrap_interval};
use raywave::variance::{
    StudyConfig, converged_reference, error_stats, penumbra_mask, per_image_errors,
};
use serde::{Deserialize, Serialize};
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The committed record.
const RECORD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/benches/baselines/variance.json"
);
/// The command that rewrites it (printed wherever the record is refused).
const RECORD_COMMAND: &str = "RAYWAVE_RECORD=1 cargo bench --bench variance -- --test";
/// Image size: 4096 pixels keep CI's one-shot run to a few seconds on 2 cores.
const SIZE: u32 = 64;
/// The study's budgets on the penumbra.
const BUDGETS: [u32; 2] = [16, 64];
/// Seeds (independent images) per (sampler, N) in each MSE.
const SEEDS: u32 = 4;
/// A figure may differ from a record made on the same SIMD path by this much (relative):
/// nothing but the last digit of a decimal round trip.
const SAME_PATH_TOLERANCE: f64 = 1e-9;
/// On another SIMD path. An sse2 build (no FMA) gave every figure identical to the last bit to
/// the avx2+fma record; this margin is for paths not tried (another architecture, another
/// libm's `powf`), and still catches any change of sampling (those move the MSE by percents).
const OTHER_PATH_TOLERANCE: f64 = 1e-3;

/// What the figures depend on, stored in the record; a record made with another one is
/// refused rather than compared.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct BenchConfig {
    scene: String,
    engine: String,
    width: u32,
    height: u32,
    bounces: u32,
    samplers: Vec<String>,
    budgets: Vec<u32>,
    seeds: Vec<u32>,
    reference_samples: u32,
    mask_samples: u32,
}

/// One (sampler, N).
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Figure {
    sampler: String,
    n: u32,
    penumbra_mse: f64,
    whole_mse: f64,
}

/// `benches/baselines/variance.json`.
#[derive(Debug, Serialize, Deserialize)]
struct Record {
    /// How to rewrite this file.
    how_to_update: String,
    /// The SIMD path it was made on (decides the tolerance).
    simd: String,
    config: BenchConfig,
    penumbra_pixels: usize,
    figures: Vec<Figure>,
}

fn study_config(scene: &Scene) -> StudyConfig {
    let base = RenderSettings {
        width: SIZE,
        height: SIZE,
        bounces: 5,
        background: scene
            .background
            .map(|c| c.to_array())
            .unwrap_or(RenderSettings::default().background),
        ..RenderSettings::default()
    };
    StudyConfig {
        budgets: BUDGETS.to_vec(),
        seeds: SEEDS,
        ..StudyConfig::standard(base)
    }
}

fn render(scene: &Scene, settings: &RenderSettings) -> (Film, RayCounts) {
    Engine::Wavefront.image(scene, settings)
}

/// The converged reference is cached next to the bench executable (`target/release/`); its
/// key includes the executable's bytes, so a rebuild renders it again (about a second).
fn cache_dir() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    Some(exe.parent()?.parent()?.join("raywave-variance-cache"))
}

/// Removes the cached references of earlier builds (every rebuild makes a new key), so the
/// cache holds one reference, not one per build.
fn prune_cache(before: std::time::SystemTime) {
    let Some(dir) = cache_dir() else { return };
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let old = entry
            .metadata()
            .and_then(|m| m.modified())
            .is_ok_and(|t| t < before);
        if old && path.extension().is_some_and(|e| e == "rwref" || e == "pfm") {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// Criterion's mean time of `variance/<sampler>/<n>` from this run, in seconds: read from its
/// `estimates.json` under the target directory (`target/criterion/`), if written after `since`
/// (in test mode criterion times nothing and this is None).
fn criterion_mean(sampler: &str, n: u32, since: std::time::SystemTime) -> Option<f64> {
    let exe = std::env::current_exe().ok()?;
    let target = exe.parent()?.parent()?.parent()?;
    let path = target.join(format!(
        "criterion/variance/{sampler}/{n}/new/estimates.json"
    ));
    if std::fs::metadata(&path).ok()?.modified().ok()? < since {
        return None;
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    Some(json["mean"]["point_estimate"].as_f64()? * 1e-9)
}

/// A measured (sampler, N): its figure and the rays per image.
struct Measured {
    figure: Figure,
    rays: u64,
    /// 95% interval of the penumbra MSE by bootstrap over the seeds (the study's statistics):
    /// how far another set of seeds could move the figure, beside the exact gate.
    penumbra_interval: Option<(f64, f64)>,
}

fn measure(scene: &Scene, config: &StudyConfig) -> (usize, Vec<Measured>) {
    let start = Instant::now();
    let start_time = std::time::SystemTime::now();
    let reference = converged_reference(
        scene,
        raywave::render::scene::BUILTIN_CORNELL_BOX.as_bytes(),
        config,
        &render,
        cache_dir()
            .map(|d| {
                raywave::variance::Cache::new(
                    &d,
                    raywave::variance::study::cache::DEFAULT_LIMIT_MIB,
                )
            })
            .as_ref(),
        &|line| eprintln!("{line}"),
    )
    .expect("the converged reference");
    if !reference.cached {
        prune_cache(start_time);
    }
    let regions = penumbra_mask(scene, &config.base, config.mask_samples);
    let whole = regions.whole();
    let penumbra_pixels = regions.penumbra.iter().filter(|&&p| p).count();
    // The reference's own error on the penumbra: it must lie far below every measured MSE.
    let reference_mse = reference
        .noise
        .iter()
        .zip(&regions.penumbra)
        .filter(|(_, p)| **p)
        .map(|(v, _)| *v as f64)
        .sum::<f64>()
        / penumbra_pixels.max(1) as f64;
    println!(
        "variance: converged reference {} and penumbra mask ({penumbra_pixels} of {} pixels) in {:.2?}; the reference's own penumbra MSE is {reference_mse:.2e}",
        if reference.cached {
            "from the cache"
        } else {
            "rendered"
        },
        whole.len(),
        start.elapsed()
    );
    let mut out = Vec::new();
    for &sampler in &config.samplers {
        for &n in &config.budgets {
            let mut films = Vec::new();
            let mut rays = 0;
            for seed in 1..=config.seeds {
                let (film, counts) = render(scene, &config.run_settings(sampler, n, seed));
                rays = counts.total();
                films.push(film);
            }
            let images: Vec<&[glam::Vec3]> = films.iter().map(|f| f.pixels.as_slice()).collect();
            let mse = |mask: &[bool]| {
                error_stats(&images, &reference.film.pixels, &reference.noise, mask).mse
            };
            let seed_mse: Vec<f64> =
                per_image_errors(&images, &reference.film.pixels, &regions.penumbra)
                    .iter()
                    .map(|e| e.0)
                    .collect();
            let penumbra_interval =
                bootstrap_interval(seed_mse.len(), BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, |idx| {
                    idx.iter().map(|&i| seed_mse[i]).sum::<f64>() / idx.len() as f64
                });
            out.push(Measured {
                penumbra_interval,
                figure: Figure {
                    sampler: sampler.name().to_string(),
                    n,
                    penumbra_mse: mse(&regions.penumbra),
                    whole_mse: mse(&whole),
                },
                rays,
            });
        }
    }
    (penumbra_pixels, out)
}

/// The outcome of one figure against the record.
#[derive(Clone, Copy, PartialEq)]
enum Verdict {
    Same,
    Fell,
    Rose,
}

/// Relative change of `now` against `before`, and its verdict under `tolerance`.
fn judge(before: f64, now: f64, tolerance: f64) -> (f64, Verdict) {
    let change = (now - before) / before.abs().max(f64::MIN_POSITIVE);
    let verdict = if change > tolerance {
        Verdict::Rose
    } else if change < -tolerance {
        Verdict::Fell
    } else {
        Verdict::Same
    };
    (change, verdict)
}

fn main() {
    let mut c = common::criterion_for_frames(Duration::from_millis(500));
    let scene = Scene::builtin_default();
    let config = study_config(&scene);
    let bench_config = BenchConfig {
        scene: scene.source.clone(),
        engine: "wavefront".into(),
        width: config.base.width,
        height: config.base.height,
        bounces: config.base.bounces,
        samplers: config.samplers.iter().map(|s| s.name().into()).collect(),
        budgets: config.budgets.clone(),
        seeds: (1..=config.seeds).collect(),
        reference_samples: config.reference_samples,
        mask_samples: config.mask_samples,
    };
    let started = std::time::SystemTime::now();
    let (penumbra_pixels, measured) = measure(&scene, &config);
    let simd = raywave::simd_path().to_string();

    // The record, or why there is none to compare with.
    let record: Result<Record, String> = std::fs::read_to_string(RECORD)
        .map_err(|e| format!("cannot read {RECORD} ({e})"))
        .and_then(|text| {
            serde_json::from_str::<Record>(&text).map_err(|e| format!("{RECORD}: {e}"))
        })
        .and_then(|r| {
            if r.config == bench_config {
                Ok(r)
            } else {
                Err(format!(
                    "{RECORD} was made with another configuration:\n  record: {:?}\n  now:    {:?}",
                    r.config, bench_config
                ))
            }
        });
    let tolerance = match &record {
        Ok(r) if r.simd == simd => SAME_PATH_TOLERANCE,
        _ => OTHER_PATH_TOLERANCE,
    };
    let find = |m: &Measured| {
        record.as_ref().ok().and_then(|r| {
            r.figures
                .iter()
                .find(|f| f.sampler == m.figure.sampler && f.n == m.figure.n)
                .cloned()
        })
    };

    // Criterion times one render per (sampler, N); its MSE is printed just above its timing.
    let mut g = c.benchmark_group("variance");
    for m in &measured {
        let sampler = LightSampler::ALL
            .into_iter()
            .find(|s| s.name() == m.figure.sampler)
            .expect("a known sampler");
        let settings = config.run_settings(sampler, m.figure.n, 1);
        println!(
            "variance/{}/{}: penumbra MSE {:.6e}, whole-image MSE {:.6e} (seeds 1..={SEEDS})",
            m.figure.sampler, m.figure.n, m.figure.penumbra_mse, m.figure.whole_mse
        );
        g.throughput(Throughput::Elements(m.rays));
        g.bench_function(BenchmarkId::new(&m.figure.sampler, m.figure.n), |b| {
            b.iter(|| black_box(render(&scene, black_box(&settings))))
        });
    }
    g.finish();
    c.final_summary();

    // The table, and the verdict.
    let mut problems = Vec::new();
    let mut improved = false;
    println!(
        "\nvariance: MSE against the converged reference ({SIZE}×{SIZE}, {} penumbra pixels, seeds 1..={SEEDS}); record {}",
        penumbra_pixels,
        match &record {
            Ok(r) if r.simd == simd => format!("made on this SIMD path, tolerance {tolerance:e}"),
            Ok(r) => format!(
                "made on another SIMD path ({}), tolerance {tolerance:e}",
                r.simd
            ),
            Err(_) => "unusable (below)".into(),
        }
    );
    println!(
        "{:<11} {:>4} {:>14} {:>22} {:>14} {:>10} {:>14} {:>9} {:>8}",
        "sampler",
        "N",
        "penumbra MSE",
        "95% over seeds",
        "record",
        "change",
        "whole MSE",
        "ms",
        "Mrays/s"
    );
    for m in &measured {
        let f = &m.figure;
        let before = find(m);
        let mut cells = (String::from("-"), String::from("-"), "");
        if let Some(before) = &before {
            let mut worst = Verdict::Same;
            let mut shown = 0.0;
            for (region, b, n) in [
                ("penumbra", before.penumbra_mse, f.penumbra_mse),
                ("whole", before.whole_mse, f.whole_mse),
            ] {
                let (change, verdict) = judge(b, n, tolerance);
                if region == "penumbra" {
                    shown = change;
                }
                match verdict {
                    Verdict::Rose => {
                        problems.push(format!(
                            "{} N={} {region} MSE rose {:+.4}% ({b:.6e} -> {n:.6e})",
                            f.sampler,
                            f.n,
                            change * 100.0
                        ));
                        worst = Verdict::Rose;
                    }
                    Verdict::Fell => {
                        improved = true;
                        if worst == Verdict::Same {
                            worst = Verdict::Fell;
                        }
                    }
                    Verdict::Same => {}
                }
            }
            cells = (
                format!("{:.6e}", before.penumbra_mse),
                format!("{:+.4}%", shown * 100.0),
                match worst {
                    Verdict::Same => "",
                    Verdict::Fell => "  fell",
                    Verdict::Rose => "  ROSE",
                },
            );
        } else if record.is_ok() {
            problems.push(format!("{} N={} is not in the record", f.sampler, f.n));
        }
        let (ms, rate) = match criterion_mean(&f.sampler, f.n, started) {
            Some(t) => (
                format!("{:.3}", t * 1e3),
                format!("{:.2}", m.rays as f64 / t.max(1e-12) / 1e6),
            ),
            None => ("-".into(), "-".into()),
        };
        let spread = m
            .penumbra_interval
            .map(|(a, b)| format!("[{a:.3e}, {b:.3e}]"))
            .unwrap_or_else(|| "-".into());
        println!(
            "{:<11} {:>4} {:>14.6e} {spread:>22} {:>14} {:>10} {:>14.6e} {ms:>9} {rate:>8}{}",
            f.sampler, f.n, f.penumbra_mse, cells.0, cells.1, f.whole_mse, cells.2
        );
    }
    println!(
        "ms and Mrays/s: criterion's mean time of one render (seed 1, all cores); `-` when nothing was timed (test mode)"
    );

    if std::env::var_os("RAYWAVE_RECORD").is_some_and(|v| !v.is_empty() && v != "0") {
        let new = Record {
            how_to_update: format!(
                "Exact figures of benches/variance.rs, re-recorded deliberately with `{RECORD_COMMAND}`; see docs/BENCHMARKING.md"
            ),
            simd,
            config: bench_config,
            penumbra_pixels,
            figures: measured.into_iter().map(|m| m.figure).collect(),
        };
        let text = serde_json::to_string_pretty(&new).expect("a record serialises") + "\n";
        write_record(Path::new(RECORD), &text);
        println!("variance: RAYWAVE_RECORD is set: wrote {RECORD}");
        return;
    }
    if let Err(why) = &record {
        problems.push(why.clone());
    }
    if problems.is_empty() {
        if improved {
            println!(
                "variance: no MSE rose; some FELL below the record: if the change is meant, re-record so the gate stays tight: {RECORD_COMMAND}"
            );
        } else {
            println!("variance: every MSE equals the record");
        }
    } else {
        eprintln!("\nvariance: FAILED against {RECORD}:");
        for p in &problems {
            eprintln!("  {p}");
        }
        eprintln!(
            "A rise in MSE with fixed seeds is a real change in noise, not measurement noise. If it is meant, re-record: {RECORD_COMMAND}"
        );
        std::process::exit(1);
    }
}

fn write_record(path: &Path, text: &str) {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).expect("create benches/baselines");
    }
    let tmp = path.with_extension("json.tmp");
    std::fs::write(&tmp, text).expect("write the record");
    std::fs::rename(&tmp, path).expect("replace the record");
}
