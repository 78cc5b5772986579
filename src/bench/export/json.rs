//! `--export-json`: the whole records, one per point, as a JSON array.

use super::Format;
use crate::output::bench_record::BenchRecord;
use anyhow::Result;

/// The records as a JSON array.
pub(super) struct Json;

impl Format for Json {
    fn text(&self, records: &[BenchRecord], _labels: &[String], _by_host: bool) -> Result<String> {
        Ok(format!("{}\n", serde_json::to_string_pretty(records)?))
    }
}
