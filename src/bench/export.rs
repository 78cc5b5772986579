//! `--export-json`, `--export-csv` and `--export-markdown`: every point's headline figures
//! (median, its 95% interval, min, max) in a file for scripts, spreadsheets or a pull request.
//! JSON holds the whole records; CSV and Markdown one row per point, engine and figure. The
//! formats of continuous-benchmarking services are in continuous.rs. [`Exports`] writes them
//! all, for `raywave bench` and `raywave bench merge` alike.

use crate::output::bench_record::BenchRecord;
use anyhow::Result;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where each export goes (`--export-*`; `-` is standard output), `None` when not asked for.
#[derive(Clone, Debug, Default)]
pub struct Exports {
    /// `--export-json`: the records as a JSON array.
    pub json: Option<PathBuf>,
    /// `--export-csv`: one row per point, engine and figure.
    pub csv: Option<PathBuf>,
    /// `--export-markdown`: a table for a pull request.
    pub markdown: Option<PathBuf>,
    /// `--export-bmf`: Bencher Metric Format.
    pub bmf: Option<PathBuf>,
    /// `--export-github-action-benchmark`: github-action-benchmark's `customBiggerIsBetter`.
    pub github_action_benchmark: Option<PathBuf>,
}

impl Exports {
    /// Each export asked for, with its flag.
    pub fn flags(&self) -> Vec<(&'static str, &Path)> {
        [
            ("--export-json", &self.json),
            ("--export-csv", &self.csv),
            ("--export-markdown", &self.markdown),
            ("--export-bmf", &self.bmf),
            (
                "--export-github-action-benchmark",
                &self.github_action_benchmark,
            ),
        ]
        .into_iter()
        .filter_map(|(flag, p)| Some((flag, p.as_deref()?)))
        .collect()
    }

    /// Writes every export asked for, each atomically. `labels[i]` names point i; `by_host`
    /// adds the host to every row and name (points measured on several machines).
    pub fn write(&self, records: &[BenchRecord], labels: &[String], by_host: bool) -> Result<()> {
        if let Some(p) = &self.json {
            write(p, &json(records)?)?;
        }
        if let Some(p) = &self.csv {
            write(p, &csv(records, labels, by_host))?;
        }
        if let Some(p) = &self.markdown {
            write(p, &markdown(records, labels, by_host))?;
        }
        if let Some(p) = &self.bmf {
            write(p, &super::continuous::bmf(records, by_host)?)?;
        }
        if let Some(p) = &self.github_action_benchmark {
            write(
                p,
                &super::continuous::github_action_benchmark(records, by_host)?,
            )?;
        }
        Ok(())
    }
}

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
/// spaces. `labels[i]` names point i (empty for a single point). `by_host` adds a last column,
/// `host`: the host name of the machine that measured the row.
pub(crate) fn csv(records: &[BenchRecord], labels: &[String], by_host: bool) -> String {
    let host_column = if by_host { ",host" } else { "" };
    let mut out = format!("{CSV_HEADER}{host_column}\n");
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
                if by_host {
                    out.push(',');
                    out.push_str(&field(&r.machine.hostname));
                }
                out.push('\n');
            }
        }
    }
    out
}

/// A Markdown table to paste into a pull request: per point, engine and figure, the median,
/// its 95% interval, min and max in Mrays/s (total) or Mrays/thread-s (stages). `by_host`
/// adds a first column, `host`, and names every host's CPU under the table.
pub(crate) fn markdown(records: &[BenchRecord], labels: &[String], by_host: bool) -> String {
    let mut out = String::from(if by_host { "| host " } else { "" });
    out.push_str("| point | engine | figure | median | 95% interval | min | max | unit |\n");
    out.push_str(if by_host { "|---" } else { "" });
    out.push_str("|---|---|---|---:|---:|---:|---:|---|\n");
    for (r, label) in records.iter().zip(labels) {
        let s = &r.setup.settings;
        let point = if label.is_empty() {
            format!("{}×{}, {} thread(s)", s.width, s.height, r.setup.threads)
        } else {
            label.clone()
        };
        for e in &r.engines {
            for f in &e.summary {
                if by_host {
                    out.push_str(&format!("| {} ", r.machine.hostname));
                }
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
    let mut machines: Vec<String> = Vec::new();
    for r in records {
        let m = if by_host {
            format!("{}: {}", r.machine.hostname, r.machine.cpu)
        } else {
            r.machine.cpu.clone()
        };
        if !machines.contains(&m) {
            machines.push(m);
        }
    }
    if !by_host {
        machines.truncate(1);
    }
    out.push_str(&format!(
        "\n{} timed run(s) per engine after {} warm-up, engines alternating; commit {}; {}\n",
        first.map_or(0, |r| r.runs),
        first.map_or(0, |r| r.warmup),
        first.map_or(String::new(), |r| r.build.short_commit()),
        machines.join("; ")
    ));
    out
}

/// Writes `text` to `path` through `crate::output` (atomically; `-` is standard output).
pub(crate) fn write(path: &Path, text: &str) -> Result<()> {
    crate::output::write_output(path, |w| Ok(w.write_all(text.as_bytes())?))
}
