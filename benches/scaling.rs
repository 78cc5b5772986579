//! Thread scaling of the wavefront engine, beside the machine's own ceiling.
//!
//! ```text
//! for round in 0..=ROUNDS (round 0 warms up and is not counted):
//!     lab frame   1024², 5 bounces, 64 stratified soft-shadow points, wavefront engine,
//!                 on 1 thread, then on 2                      → speed-up t₁ / t₂
//!     ceiling     each thread runs the same fixed loop of independent f32x8 FMAs (no memory,
//!                 no sharing), on 1 thread, then on 2         → speed-up 2 · t₁ / t₂
//! print the medians of the per-round speed-ups, and how busy the 2 threads were in the frame
//! ```
//!
//! The ceiling loop is perfectly parallel by construction, so its speed-up is what this
//! machine gives two threads of SIMD work; a frame can only come close to it. Busy is the
//! frame's thread-seconds (the sum of every stage's time on every worker) over 2 × wall time:
//! the share of the two threads' time spent rendering rather than waiting.
//!
//! `cargo bench --bench scaling` (rounds: `RAYWAVE_ROUNDS`, default 9); under `cargo test` or
//! `-- --test` it runs one round at 64² with a short loop, to keep the code from rotting.

mod common;

use raywave::render::progress::Progress;
use raywave::render::scene::Scene;
use raywave::render::settings::RenderSettings;
use raywave::render::wavefront::{DEFAULT_BATCH_SIZE, Wavefront};
use raywave::stats::median;
use std::hint::black_box;
use std::time::{Duration, Instant};
use wide::f32x8;

/// Camera samples per tile tried in each round (the engine's default is 4096).
const BATCH_SIZES: [usize; 3] = [1024, 2048, DEFAULT_BATCH_SIZE];

/// FMA steps per ceiling loop at full size: about half a second on one thread here.
const CEILING_STEPS: u64 = 300_000_000;

fn main() {
    let (size, steps, rounds) = if common::test_mode() {
        (64, 100_000, 1)
    } else {
        let rounds = match std::env::var("RAYWAVE_ROUNDS") {
            Err(_) => 9,
            Ok(r) => match r.parse::<usize>() {
                Ok(n) if n > 0 => n,
                _ => {
                    eprintln!(
                        "scaling: RAYWAVE_ROUNDS={r}: expected a number of rounds, 1 or more"
                    );
                    std::process::exit(2)
                }
            },
        };
        (1024, CEILING_STEPS, rounds)
    };
    let scene = Scene::builtin_default();
    let settings = RenderSettings::lab_benchmark(size);
    let engines: Vec<(usize, Wavefront)> = BATCH_SIZES
        .iter()
        .map(|&b| (b, Wavefront::new(&scene, &settings, b)))
        .collect();
    let pools: Vec<rayon::ThreadPool> = [1, 2]
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("a thread pool")
        })
        .collect();
    println!(
        "scaling: lab frame {size}², 5 bounces, 64 stratified; simd {}; {rounds} round(s); \
         batch sizes {BATCH_SIZES:?} (default {DEFAULT_BATCH_SIZE})",
        raywave::simd_path()
    );
    // Per batch size, per counted round: (speed-up, busy, work inflation).
    let mut frame: Vec<Vec<[f64; 3]>> = vec![Vec::new(); engines.len()];
    let mut ceiling = Vec::new();
    for round in 0..=rounds {
        let mut line = format!("round {round}:");
        for (e, (batch, engine)) in engines.iter().enumerate() {
            let mut wall = [0.0; 2];
            let mut thread_s = [0.0; 2];
            for (k, pool) in pools.iter().enumerate() {
                let start = Instant::now();
                let (film, stats) = pool.install(|| engine.render(&Progress::SILENT));
                wall[k] = start.elapsed().as_secs_f64();
                black_box(film);
                thread_s[k] = stats.stage_time.iter().sum::<Duration>().as_secs_f64();
            }
            let speed_up = wall[0] / wall[1];
            let busy = thread_s[1] / (2.0 * wall[1]);
            let inflation = thread_s[1] / thread_s[0];
            if round > 0 {
                frame[e].push([speed_up, busy, inflation]);
            }
            line += &format!(
                " batch {batch}: {:.3} s → {:.3} s {speed_up:.2}x (busy {busy:.3}, work ×{inflation:.2});",
                wall[0], wall[1]
            );
        }
        let mut loop_wall = [0.0; 2];
        for (k, pool) in pools.iter().enumerate() {
            let start = Instant::now();
            black_box(pool.broadcast(|_| fma_loop(black_box(steps))));
            loop_wall[k] = start.elapsed().as_secs_f64();
        }
        let c = 2.0 * loop_wall[0] / loop_wall[1];
        line += &format!(
            " ceiling {:.3} s, {:.3} s each: {c:.2}x",
            loop_wall[0], loop_wall[1]
        );
        if round > 0 {
            // round 0 warms up (pools, workspaces, caches) and is not counted
            ceiling.push(c);
            println!("{line}");
        }
    }
    println!(
        "median over {rounds} round(s): ceiling {:.2}x",
        median(&ceiling)
    );
    for (e, (batch, _)) in engines.iter().enumerate() {
        let column = |i: usize| median(&frame[e].iter().map(|r| r[i]).collect::<Vec<_>>());
        println!(
            "  batch {batch}: frame 2 threads / 1 thread {:.2}x, busy {:.3}, work on 2 threads \
             ×{:.2} of 1",
            column(0),
            column(1),
            column(2)
        );
    }
}

/// Ten independent chains of f32x8 fused multiply-adds: enough in flight to keep the FMA
/// units busy, nothing in memory.
fn fma_loop(steps: u64) -> f32 {
    let mut x: [f32x8; 10] =
        black_box(std::array::from_fn(|i| f32x8::splat(1.0 + i as f32 * 1e-3)));
    let (m, c) = black_box((f32x8::splat(0.999_999_9), f32x8::splat(1e-7)));
    for _ in 0..steps {
        for v in &mut x {
            *v = v.mul_add(m, c);
        }
    }
    x.iter().map(|v| v.reduce_add()).sum()
}
