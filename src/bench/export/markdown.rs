//! `--export-markdown`: a table of every point's headline figures to paste into a pull request.

use super::Format;
use crate::output::bench_record::BenchRecord;
use anyhow::Result;

/// A Markdown table to paste into a pull request: per point, engine and figure, the median,
/// its 95% interval, min and max in Mrays/s (total) or Mrays/thread-s (stages), and the machine
/// under it. `by_host` adds a first column, `host`, and names every host's CPU under the table.
pub(super) struct Markdown;

impl Format for Markdown {
    fn text(&self, records: &[BenchRecord], labels: &[String], by_host: bool) -> Result<String> {
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
                    let [median, min, max] = [f.median, f.min, f.max].map(|v| v / 1e6);
                    let interval = f.interval_text(1e-6, 2);
                    out.push_str(&format!(
                        "| {point} | {} | {} | {median:.2} | {interval} | {min:.2} | {max:.2} | M{} |\n",
                        e.engine, f.figure, f.unit
                    ));
                }
            }
        }
        // The CPU (one machine), or every host's name and CPU, each once.
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
        let first = records.first();
        out.push_str(&format!(
            "\n{} timed run(s) per engine after {} warm-up, engines alternating; commit {}; {}\n",
            first.map_or(0, |r| r.runs),
            first.map_or(0, |r| r.warmup),
            first.map_or(String::new(), |r| r.build.short_commit()),
            machines.join("; ")
        ));
        Ok(out)
    }
}
