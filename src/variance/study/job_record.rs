//! One job's result as a study's part keeps it: the [`JobResult`] with the per-seed values the
//! report leaves out of its rows, so that a merge reproduces a single process's figures.

use crate::variance::Row;
use crate::variance::study::jobs::JobResult;
use serde::{Deserialize, Serialize};

/// A [`JobResult`] with the per-seed values the report leaves out of its rows.
pub type JobRecord = JobResult<RowRecord>;

/// A row and the per-seed values it does not serialise.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RowRecord {
    row: Row,
    seed_mse: Vec<f64>,
    seed_bias: Vec<f64>,
    seed_seconds: Vec<f64>,
    seed_low_band: Vec<f64>,
}

impl From<Row> for RowRecord {
    fn from(mut row: Row) -> RowRecord {
        RowRecord {
            seed_mse: std::mem::take(&mut row.seed_mse),
            seed_bias: std::mem::take(&mut row.seed_bias),
            seed_seconds: std::mem::take(&mut row.seed_seconds),
            seed_low_band: std::mem::take(&mut row.perceived.seed_low_band),
            row,
        }
    }
}

impl From<RowRecord> for Row {
    fn from(rec: RowRecord) -> Row {
        let mut row = rec.row;
        row.seed_mse = rec.seed_mse;
        row.seed_bias = rec.seed_bias;
        row.seed_seconds = rec.seed_seconds;
        row.perceived.seed_low_band = rec.seed_low_band;
        row
    }
}
