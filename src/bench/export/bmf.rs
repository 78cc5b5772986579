//! `--export-bmf`: Bencher Metric Format, for `bencher run --adapter json` (continuous.rs names
//! the figures).

use super::Format;
use super::continuous::figures;
use crate::output::bench_record::{BenchRecord, FigureSummary};
use anyhow::{Result, bail};
use serde::Serialize;
use std::collections::BTreeMap;

/// Bencher Metric Format.
pub(super) struct Bmf;

impl Format for Bmf {
    fn flag(&self) -> &'static str {
        "--export-bmf"
    }

    fn text(&self, records: &[BenchRecord], _labels: &[String], by_host: bool) -> Result<String> {
        bmf(records, by_host)
    }
}

/// One measure's value in Bencher Metric Format.
#[derive(Serialize)]
struct Metric {
    value: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    lower_value: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    upper_value: Option<f64>,
}

/// The measure a figure goes under in Bencher: one per unit.
fn measure(f: &FigureSummary) -> &'static str {
    if f.unit == "rays/s" {
        "rays-per-second"
    } else {
        "rays-per-thread-second"
    }
}

/// The records in Bencher Metric Format; two figures with one name (two machines of one host
/// name, say) are an error rather than one overwriting the other.
fn bmf(records: &[BenchRecord], by_host: bool) -> Result<String> {
    let mut out = BTreeMap::new();
    for (name, _, f) in figures(records, by_host) {
        let (lower_value, upper_value) = match (f.low, f.high) {
            (Some(low), Some(high)) => (Some(low), Some(high)),
            _ => (None, None),
        };
        let metric = Metric {
            value: f.median,
            lower_value,
            upper_value,
        };
        let measures = BTreeMap::from([(measure(f), metric)]);
        if out.insert(name.clone(), measures).is_some() {
            bail!(
                "two figures share the benchmark name `{name}`: give each machine its own host name"
            );
        }
    }
    Ok(format!("{}\n", serde_json::to_string_pretty(&out)?))
}
