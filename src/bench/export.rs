//! `--export-json`, `--export-csv` and `--export-markdown`: every point's headline figures
//! (median, its 95% interval, min, max) in a file for scripts, spreadsheets or a pull request.
//! JSON holds the whole records; CSV and Markdown one row per point, engine and figure.

use crate::output::bench_record::BenchRecord;
use anyhow::Result;
use std::io::Write;
use std::path::Path;

/// The CSV header (one row per point, engine and figure follows).
pub(crate) const CSV_HEADER: &str = "point,scene,width,height,bounces,shadow_samples,threads,engine,\
                              figure,unit,runs,min,median,low,high,max,outliers";

/// The records as a JSON array, one record per point.
pub(crate) fn json(records: &[BenchRecord]) -> Result<String> {
    Ok(format!("{}\n", serde_json::to_string_pretty(records)?))
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), |x| x.to_string())
}

/// One row per point, engine and headline figure; rates in rays/s or rays/thread-s (`unit`),
/// `low` and `high` empty without an interval, `outliers` the outlier runs (1-based) joined by
/// spaces. `labels[i]` names point i (empty for a single point).
pub(crate) fn csv(records: &[BenchRecord], labels: &[String]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for (r, label) in records.iter().zip(labels) {
        let s = &r.setup.settings;
        for e in &r.engines {
            for f in &e.summary {
                let outliers: Vec<String> =
                    f.outliers.iter().map(|i| (i + 1).to_string()).collect();
                let row = [
                    field(label),
                    field(&r.setup.scene.source),
                    s.width.to_string(),
                    s.height.to_string(),
                    s.bounces.to_string(),
                    s.shadow_samples.to_string(),
                    r.setup.threads.to_string(),
                    field(&e.engine),
                    field(&f.figure),
                    field(&f.unit),
                    f.runs.to_string(),
                    f.min.to_string(),
                    f.median.to_string(),
                    opt(f.low),
                    opt(f.high),
                    f.max.to_string(),
                    outliers.join(" "),
                ];
                out.push_str(&row.join(","));
                out.push('\n');
            }
        }
    }
    out
}

/// A Markdown table to paste into a pull request: per point, engine and figure, the median,
/// its 95% interval, min and max in Mrays/s (total) or Mrays/thread-s (stages).
pub(crate) fn markdown(records: &[BenchRecord], labels: &[String]) -> String {
    let mut out = String::from(
        "| point | engine | figure | median | 95% interval | min | max | unit |\n\
         |---|---|---|---:|---:|---:|---:|---|\n",
    );
    for (r, label) in records.iter().zip(labels) {
        let s = &r.setup.settings;
        let point = if label.is_empty() {
            format!("{}×{}, {} thread(s)", s.width, s.height, r.setup.threads)
        } else {
            label.clone()
        };
        for e in &r.engines {
            for f in &e.summary {
                out.push_str(&format!(
                    "| {point} | {} | {} | {:.2} | {} | {:.2} | {:.2} | M{} |\n",
                    e.engine,
                    f.figure,
                    f.median / 1e6,
                    f.interval_text(1e-6, 2),
                    f.min / 1e6,
                    f.max / 1e6,
                    f.unit
                ));
            }
        }
    }
    let first = records.first();
    out.push_str(&format!(
        "\n{} timed run(s) per engine after {} warm-up, engines alternating; commit {}; {}\n",
        first.map_or(0, |r| r.runs),
        first.map_or(0, |r| r.warmup),
        first.map_or(String::new(), |r| r.build.short_commit()),
        first.map_or(String::new(), |r| r.machine.cpu.clone())
    ));
    out
}

/// Writes `text` to `path` through `crate::output` (atomically; `-` is standard output).
pub(crate) fn write(path: &Path, text: &str) -> Result<()> {
    crate::output::write_output(path, |w| Ok(w.write_all(text.as_bytes())?))
}
