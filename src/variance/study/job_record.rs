//! One job's result as a study's part keeps it: the [`JobResult`] with the per-seed values the
//! report leaves out of its rows, so that a merge reproduces a single process's figures.

use crate::variance::Row;
use crate::variance::study::jobs::{Job, JobResult, Thumbnail};
use serde::{Deserialize, Serialize};

/// A [`JobResult`] with the per-seed values the report leaves out of its rows.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobRecord {
    pub(crate) job: Job,
    rows: Vec<RowRecord>,
    heatmap: Option<Vec<f32>>,
    thumbnail: Thumbnail,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct RowRecord {
    row: Row,
    seed_mse: Vec<f64>,
    seed_bias: Vec<f64>,
    seed_seconds: Vec<f64>,
    seed_low_band: Vec<f64>,
}

impl From<JobResult> for JobRecord {
    fn from(r: JobResult) -> JobRecord {
        let rows = r
            .rows
            .into_iter()
            .map(|mut row| RowRecord {
                seed_mse: std::mem::take(&mut row.seed_mse),
                seed_bias: std::mem::take(&mut row.seed_bias),
                seed_seconds: std::mem::take(&mut row.seed_seconds),
                seed_low_band: std::mem::take(&mut row.perceived.seed_low_band),
                row,
            })
            .collect();
        JobRecord {
            job: r.job,
            rows,
            heatmap: r.heatmap,
            thumbnail: r.thumbnail,
        }
    }
}

impl From<JobRecord> for JobResult {
    fn from(r: JobRecord) -> JobResult {
        let rows = r
            .rows
            .into_iter()
            .map(|rec| {
                let mut row = rec.row;
                row.seed_mse = rec.seed_mse;
                row.seed_bias = rec.seed_bias;
                row.seed_seconds = rec.seed_seconds;
                row.perceived.seed_low_band = rec.seed_low_band;
                row
            })
            .collect();
        JobResult {
            job: r.job,
            rows,
            heatmap: r.heatmap,
            thumbnail: r.thumbnail,
        }
    }
}
