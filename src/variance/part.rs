//! The partial result of one shard of a study (`raywave variance --shard I/N` writes
//! `shard-I-of-N.part`; `raywave variance merge` reads them): self-describing, checked whole,
//! written whole or not at all.
//!
//! ```text
//! magic    8 bytes  "RWPART1\n"
//! length   u64 LE   bytes of the payload
//! fnv      u64 LE   FNV-1a of the payload
//! payload  CBOR of `Part`: the study's identity, the shard, the jobs it ran, its host and
//!          clock, each case's facts, and every job's rows with their per-seed values
//! ```
//!
//! CBOR keeps every f64 bit for bit, NaN and infinities included, which is what lets a merge
//! reproduce a single process's figures exactly.

use super::Row;
use super::jobs::{CaseFacts, Job, JobResult, Thumbnail};
use super::plan::StudyIdentity;
use crate::output::shard::Shard;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// The first bytes of every part.
pub const MAGIC: &[u8; 8] = b"RWPART1\n";

/// Bytes before the payload.
const HEADER_LEN: usize = 24;

/// Where and when a shard ran.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Host {
    /// Host name.
    pub hostname: String,
    /// CPU model.
    pub cpu: String,
    /// Worker threads the renders ran on.
    pub threads: usize,
    /// Start, in seconds since the Unix epoch.
    pub started: f64,
    /// End, in seconds since the Unix epoch.
    pub finished: f64,
}

/// One shard's partial result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Part {
    /// The study it belongs to.
    pub identity: StudyIdentity,
    /// Which shard.
    pub shard: Shard,
    /// The numbers of the jobs it ran (in `StudyIdentity::jobs`).
    pub jobs: Vec<usize>,
    /// Where and when.
    pub host: Host,
    /// Per case it touched: the case's number, where its scene came from, and its facts.
    pub cases: Vec<(usize, String, CaseFacts)>,
    /// What each job measured.
    pub results: Vec<JobRecord>,
}

/// A [`JobResult`] with the per-seed values the report leaves out of its rows.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobRecord {
    job: Job,
    rows: Vec<RowRecord>,
    heatmap: Option<Vec<f32>>,
    thumbnail: Thumbnail,
    host: String,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct RowRecord {
    row: Row,
    seed_mse: Vec<f64>,
    seed_bias: Vec<f64>,
    seed_seconds: Vec<f64>,
    seed_low_band: Vec<f64>,
    seed_lowpass: [Vec<f64>; 2],
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
                seed_lowpass: std::mem::take(&mut row.perceived.seed_lowpass),
                row,
            })
            .collect();
        JobRecord {
            job: r.job,
            rows,
            heatmap: r.heatmap,
            thumbnail: r.thumbnail,
            host: r.host,
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
                row.perceived.seed_lowpass = rec.seed_lowpass;
                row
            })
            .collect();
        JobResult {
            job: r.job,
            rows,
            heatmap: r.heatmap,
            thumbnail: r.thumbnail,
            host: r.host,
        }
    }
}

impl JobRecord {
    /// The job.
    pub fn job(&self) -> Job {
        self.job
    }
}

/// The file name of `shard`'s part.
pub fn file_name(shard: Shard) -> String {
    format!("shard-{}-of-{}.part", shard.index, shard.count)
}

/// Writes `part` to `path` atomically (a temporary file renamed into place).
pub fn write(path: &Path, part: &Part) -> Result<()> {
    let mut payload = Vec::new();
    ciborium::into_writer(part, &mut payload).context("cannot encode the part")?;
    crate::output::image_file::write_atomically(path, |w| {
        w.write_all(MAGIC)?;
        w.write_all(&(payload.len() as u64).to_le_bytes())?;
        w.write_all(&crate::render::digest::of(&payload).to_le_bytes())?;
        w.write_all(&payload)?;
        Ok(())
    })
}

/// Reads and checks the part at `path`; errors name the file and what is wrong with it.
pub fn read(path: &Path) -> Result<Part> {
    let shown = path.display();
    let meta = std::fs::metadata(path).with_context(|| format!("cannot read the part {shown}"))?;
    if !meta.is_file() {
        anyhow::bail!("{shown}: expected a part file, found a directory or device");
    }
    let not_a_part = || {
        anyhow::anyhow!(
            "{shown}: not a raywave study part (expected a file written by `raywave variance --shard`, starting {:?})",
            String::from_utf8_lossy(MAGIC).trim_end()
        )
    };
    let mut file =
        std::fs::File::open(path).with_context(|| format!("cannot read the part {shown}"))?;
    let mut header = [0u8; HEADER_LEN];
    if meta.len() < HEADER_LEN as u64 {
        return Err(not_a_part());
    }
    file.read_exact(&mut header)
        .with_context(|| format!("cannot read the part {shown}"))?;
    if &header[..8] != MAGIC {
        return Err(not_a_part());
    }
    let u64_at = |i: usize| u64::from_le_bytes(header[i..i + 8].try_into().unwrap_or_default());
    let (length, sum) = (u64_at(8), u64_at(16));
    let found = meta.len() - HEADER_LEN as u64;
    if found != length {
        anyhow::bail!(
            "{shown}: truncated or padded: the header says {length} bytes of results, the file holds {found}; was it cut off mid-write or mid-copy? Run its shard again"
        );
    }
    let mut payload = Vec::new();
    file.take(length)
        .read_to_end(&mut payload)
        .with_context(|| format!("cannot read the part {shown}"))?;
    if payload.len() as u64 != length {
        anyhow::bail!("{shown}: it shrank while being read");
    }
    if crate::render::digest::of(&payload) != sum {
        anyhow::bail!(
            "{shown}: corrupt: its checksum does not match its contents; run its shard again"
        );
    }
    let payload = payload.as_slice();
    let part: Part = ciborium::from_reader(payload)
        .with_context(|| format!("{shown}: its results cannot be decoded"))?;
    Ok(part)
}

/// The part files named by `inputs`: each file as given, and each directory's `*.part` files
/// in name order.
pub fn expand(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    crate::output::shard::expand_parts(inputs, |n| n.ends_with(".part"), "shard parts (*.part)")
}
