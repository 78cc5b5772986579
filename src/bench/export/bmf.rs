//! `--export-bmf`: Bencher Metric Format, for `bencher run --adapter json` (continuous.rs names
//! the figures).

use super::Format;
use super::continuous::figures;
use crate::output::bench_record::BenchRecord;
use anyhow::Result;
use serde::Serialize;
use std::collections::BTreeMap;

/// One measure's value in Bencher Metric Format.
#[derive(Serialize)]
struct Metric {
    value: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    lower_value: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    upper_value: Option<f64>,
}

/// Bencher Metric Format: each figure under one measure per unit.
pub(super) struct Bmf;

impl Format for Bmf {
    fn text(&self, records: &[BenchRecord], _labels: &[String], by_host: bool) -> Result<String> {
        let mut out = BTreeMap::new();
        for (name, _, f) in figures(records, by_host)? {
            let bounds = f.low.zip(f.high);
            let metric = Metric {
                value: f.median,
                lower_value: bounds.map(|(low, _)| low),
                upper_value: bounds.map(|(_, high)| high),
            };
            let measure = if f.unit == "rays/s" {
                "rays-per-second"
            } else {
                "rays-per-thread-second"
            };
            out.insert(name, BTreeMap::from([(measure, metric)]));
        }
        Ok(format!("{}\n", serde_json::to_string_pretty(&out)?))
    }
}
