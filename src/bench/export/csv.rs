//! `--export-csv`: one row per point, engine and headline figure, for scripts and spreadsheets.

use super::Format;
use crate::output::bench_record::BenchRecord;
use anyhow::Result;

/// The CSV header (one row per point, engine and figure follows).
const CSV_HEADER: &str = "point,scene,width,height,bounces,shadow_samples,threads,engine,\
                              figure,unit,runs,min,median,low,high,max,outliers";

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
pub(super) struct Csv;

impl Format for Csv {
    fn text(&self, records: &[BenchRecord], labels: &[String], by_host: bool) -> Result<String> {
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
        Ok(out)
    }
}
