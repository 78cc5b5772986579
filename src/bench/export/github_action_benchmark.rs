//! `--export-github-action-benchmark`: the JSON of github-action-benchmark's
//! `customBiggerIsBetter` tool (continuous.rs names the figures).

use super::Format;
use super::continuous::figures;
use crate::output::bench_record::BenchRecord;
use anyhow::Result;
use serde::Serialize;

/// One entry of github-action-benchmark's custom JSON.
#[derive(Serialize)]
struct Entry {
    name: String,
    unit: String,
    value: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    range: Option<String>,
    extra: String,
}

/// github-action-benchmark's `customBiggerIsBetter` input (rates: bigger is better); one entry
/// per headline figure, in record order.
pub(super) struct GithubActionBenchmark;

impl Format for GithubActionBenchmark {
    fn text(&self, records: &[BenchRecord], _labels: &[String], by_host: bool) -> Result<String> {
        let mut out = Vec::new();
        for (name, r, f) in figures(records, by_host)? {
            let (range, interval) = match (f.low, f.high) {
                (Some(low), Some(high)) => (
                    Some(format!("± {}", (high - f.median).max(f.median - low))),
                    format!("95% interval of the median: [{low}, {high}] {}", f.unit),
                ),
                _ => (
                    None,
                    format!(
                        "no 95% interval of the median: {} run(s) < {}",
                        f.runs,
                        crate::stats::MIN_FOR_INTERVAL
                    ),
                ),
            };
            let commit = r.build.short_commit();
            out.push(Entry {
                name,
                unit: f.unit.clone(),
                value: f.median,
                range,
                extra: format!(
                    "{interval}\n{} runs, min {}, max {}\nhost {} ({})\nraywave {}, commit {commit}",
                    f.runs, f.min, f.max, r.machine.hostname, r.machine.cpu, r.raywave
                ),
            });
        }
        Ok(format!("{}\n", serde_json::to_string_pretty(&out)?))
    }
}
