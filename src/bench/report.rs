//! What `raywave bench` prints for one record: the header, the medians by kind and by stage,
//! the headline figures with min, median, 95% interval and max; and the warnings a noisy
//! measurement deserves (outlier runs, wide intervals, a loaded machine).

use crate::output::bench_record::{BenchRecord, FigureSummary};
use crate::output::terminal::table_line;
use crate::render::settings::{RenderSettings, ShadowMode};
use std::fmt::Write as _;

/// A median whose 95% interval is wider than this share of it, in percent, is called noisy.
const NOISY_WIDTH_PCT: f64 = 10.0;

/// The printed report of one record: header, then per engine its kinds and stages, then the
/// headline figures.
pub fn report(r: &BenchRecord) -> String {
    let (s, b, commit) = (&r.setup.settings, &r.build, r.build.short_commit());
    let mut out = String::new();
    let _ = writeln!(
        out,
        "raywave {} · commit {commit} · {} {} · simd {} · {} thread(s) · {}",
        r.raywave, b.profile, b.target, r.simd, r.setup.threads, r.machine.cpu
    );
    let shadows = match s.shadows {
        ShadowMode::Soft => format!("soft, {} {} points", s.shadow_samples, s.sampler.name()),
        mode => mode.name().to_string(),
    };
    // The lighting is named only when it is not the lab's.
    let lab = RenderSettings::default();
    let lighting = if (s.light_model, s.ambient) == (lab.light_model, lab.ambient) {
        String::new()
    } else {
        let [r, g, b] = s.ambient;
        format!(
            ", light model {}, ambient {r} {g} {b}",
            s.light_model.name()
        )
    };
    let _ = writeln!(
        out,
        "scene   {} · {}×{}, {} bounces, shadows {shadows}, {} aa{lighting}",
        r.setup.scene.source, s.width, s.height, s.bounces, s.aa_samples
    );
    let _ = writeln!(
        out,
        "runs    {} warm-up + {} timed per engine, engines alternating; medians below",
        r.warmup, r.runs
    );
    // Each kind over the thread-time of its own work (`-`: not measured, as for the reference,
    // timed without timers), the total over the wall clock.
    let kinds = |cells: [&str; 5]| table_line(&[-10, -12, 12, 10, 16], cells);
    let header = ["engine", "kind", "rays", "seconds", "Mrays/thread-s"];
    let _ = writeln!(out, "{}", kinds(header));
    for e in &r.engines {
        let (m, total) = (&e.median, &e.median.rays.total);
        for (kind, figure) in m.rays.kinds.iter() {
            let rate = figure
                .rays_per_thread_second
                .map_or("-".to_string(), |r| format!("{:.2}", r / 1e6));
            let rays = figure.rays.to_string();
            let _ = writeln!(out, "{}", kinds([&e.engine, kind.name(), &rays, "", &rate]));
        }
        let rays = total.rays.to_string();
        let seconds = format!("{:.3}", total.seconds);
        let rate = format!("{:.2}", total.rays_per_second / 1e6);
        let row = kinds([&e.engine, "total", &rays, &seconds, &rate]);
        let _ = writeln!(out, "{row}  (Mrays/s, wall clock)");
    }
    if r.engines.iter().any(|e| !e.median.stages.is_empty()) {
        let header = ["engine", "stage", "rays", "thread-s", "Mrays/thread-s"];
        let _ = writeln!(out, "{}", kinds(header));
    }
    for e in &r.engines {
        for st in &e.median.stages {
            let rays = st.rays.to_string();
            let seconds = format!("{:.4}", st.thread_seconds);
            let rate = format!("{:.2}", st.rays_per_thread_second / 1e6);
            let _ = writeln!(
                out,
                "{}",
                kinds([&e.engine, &st.stage, &rays, &seconds, &rate])
            );
        }
    }
    let figures = |cells: [&str; 6]| table_line(&[-10, -17, 8, 8, 18, 8], cells);
    let header = ["engine", "figure", "min", "median", "95% interval", "max"];
    let _ = writeln!(out, "{}  outliers", figures(header));
    for e in &r.engines {
        for f in &e.summary {
            let [min, median, max] = [f.min, f.median, f.max].map(|v| format!("{:.2}", v / 1e6));
            let interval = f.interval_text(1e-6, 2);
            let row = figures([&e.engine, &f.figure, &min, &median, &interval, &max]);
            let _ = writeln!(out, "{row}  {}", outlier_text(f));
        }
    }
    let _ = writeln!(
        out,
        "totals in Mrays/s (wall clock), kinds and stages in Mrays/thread-s (the reference has no stages)"
    );
    out
}

fn outlier_text(f: &FigureSummary) -> String {
    let runs: Vec<String> = f
        .outliers
        .iter()
        .map(|i| format!("run {}", i + 1))
        .collect();
    if runs.is_empty() {
        "-".to_string()
    } else {
        runs.join(", ")
    }
}

/// The warnings for one record: each figure with outlier runs (by the modified Z-score) and
/// each whose interval is wider than [`NOISY_WIDTH_PCT`] of its median, named.
pub(crate) fn warnings(r: &BenchRecord, point: &str) -> Vec<String> {
    let at = if point.is_empty() {
        String::new()
    } else {
        format!(" at {point}")
    };
    let mut out = Vec::new();
    let mut noisy = Vec::new();
    for e in &r.engines {
        for f in &e.summary {
            if !f.outliers.is_empty() {
                let values: Vec<String> = f
                    .outliers
                    .iter()
                    .map(|&i| {
                        let run = &e.runs[i.min(e.runs.len().saturating_sub(1))];
                        let v = if f.figure == "total" {
                            run.rays.total.rays_per_second
                        } else {
                            let name = f.figure.trim_start_matches("stage ");
                            run.stages
                                .iter()
                                .find(|s| s.stage == name)
                                .map_or(f64::NAN, |s| s.rays_per_thread_second)
                        };
                        format!("run {} at {:.2}", i + 1, v / 1e6)
                    })
                    .collect();
                out.push(format!(
                    "{} {}{at}: outlier run(s) {} against a median of {:.2} (modified Z-score \
                     above {}): something else ran during them?",
                    e.engine,
                    f.figure,
                    values.join(", "),
                    f.median / 1e6,
                    crate::stats::OUTLIER_Z
                ));
            }
            if let Some(w) = f.relative_width_pct().filter(|w| *w > NOISY_WIDTH_PCT) {
                noisy.push(format!(
                    "{} {} {} ({w:.0}%)",
                    e.engine,
                    f.figure,
                    f.interval_text(1e-6, 2)
                ));
            }
        }
    }
    if !noisy.is_empty() {
        out.push(format!(
            "noisy{at}: the 95% interval of the median is wider than {NOISY_WIDTH_PCT}% of it \
             for {}; a quieter machine, more --runs or a larger image narrow it",
            noisy.join(", ")
        ));
    }
    out
}

/// A warning when the machine's 1-minute load average exceeds its logical CPUs (read from
/// /proc/loadavg before the bench starts): other processes then compete for every core.
pub(crate) fn load_warning() -> Option<String> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let load: f64 = text.split_whitespace().next()?.parse().ok()?;
    let cpus = crate::output::machine::logical_cpus();
    (load > cpus as f64).then(|| {
        format!(
            "the load average is {load:.2} on {cpus} logical CPU(s) before the bench: other \
             processes compete for the cores, so expect noisy figures"
        )
    })
}
