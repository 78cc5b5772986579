//! What the exports for continuous-benchmarking services (`--export-bmf`,
//! `--export-github-action-benchmark`) share, so that a CI job can track raywave's rays/s commit
//! after commit: each headline figure's name. Each holds every headline figure of every point
//! and engine: the median and the bounds of its 95% interval.
//!
//! ```text
//! name     = SCENE WxH+sS+tT ENGINE FIGURE [@ HOST]    e.g. "cornell_box 512x512+s16+t2 wavefront total"
//! BMF      { name: { MEASURE: { value: median, lower_value: low, upper_value: high } } }
//!          MEASURE = rays-per-second (total) or rays-per-thread-second (a stage)
//! github-action-benchmark
//!          [ { name, unit: "rays/s" | "rays/thread-s", value: median,
//!              range: "± H" (H the larger distance from the median to an interval bound),
//!              extra: the interval's bounds, runs, min, max, host, commit } ]
//! ```
//!
//! Without an interval (fewer than 6 runs) the bounds and `range` are left out; the formats
//! make them optional.

use crate::output::bench_record::{BenchRecord, FigureSummary};
use crate::render::settings::ShadowMode;
use anyhow::{Result, bail};

/// The scene's short name: a built-in scene's name, else the file name without extension.
fn scene_name(source: &str) -> String {
    if let Some(inner) = source
        .strip_prefix("<built-in ")
        .and_then(|s| s.strip_suffix('>'))
    {
        return inner.to_string();
    }
    std::path::Path::new(source)
        .file_stem()
        .map_or_else(|| source.to_string(), |s| s.to_string_lossy().into_owned())
}

/// The name a tracker keeps a headline figure under: the scene, the values a sweep may vary
/// (size, shadow points, threads), the engine and the figure; ` @ HOST` when `by_host`.
fn figure_name(r: &BenchRecord, engine: &str, figure: &str, by_host: bool) -> String {
    let s = &r.setup.settings;
    let shadows = match s.shadows {
        ShadowMode::Soft => format!("s{}", s.shadow_samples),
        mode => format!("shadows-{}", mode.name()),
    };
    let mut name = format!(
        "{} {}x{}+{shadows}+t{} {engine} {figure}",
        scene_name(&r.setup.scene.source),
        s.width,
        s.height,
        r.setup.threads
    );
    if by_host {
        name.push_str(&format!(" @ {}", r.machine.hostname));
    }
    name
}

/// Every headline figure of every record, with its name; two figures with one name (two
/// machines of one host name, say) are an error rather than one overwriting the other.
pub(super) fn figures(
    records: &[BenchRecord],
    by_host: bool,
) -> Result<Vec<(String, &BenchRecord, &FigureSummary)>> {
    let mut out = Vec::new();
    let mut names = std::collections::HashSet::new();
    for r in records {
        for e in &r.engines {
            for f in &e.summary {
                let name = figure_name(r, &e.engine, &f.figure, by_host);
                if !names.insert(name.clone()) {
                    bail!(
                        "two figures share the benchmark name `{name}`: give each machine its own \
                         host name"
                    );
                }
                out.push((name, r, f));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_names_are_short() {
        assert_eq!(
            scene_name("<built-in cornell_box_reflective_spheres>"),
            "cornell_box_reflective_spheres"
        );
        assert_eq!(scene_name("scenes/cornell_box.obj"), "cornell_box");
        assert_eq!(scene_name("/tmp/x/scene.obj"), "scene");
        assert_eq!(scene_name("-"), "-");
    }
}
