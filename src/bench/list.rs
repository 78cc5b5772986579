//! `raywave bench list` and `raywave bench compare A B`: the saved records, read offline.

use super::compare::{Refusal, compare};
use crate::output::bench_record::{self as record, BenchRecord};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// Loads `compare`'s argument `name`: the file `name` when it ends in `.json`, else the record
/// `name` in `dir` (`record::record_path`).
fn load(dir: &Path, name: &str) -> Result<BenchRecord> {
    let path = if name.ends_with(".json") {
        PathBuf::from(name)
    } else {
        record::record_path(dir, name)?
    };
    record::load(&path, name.trim_end_matches(".json"))
}

/// `raywave bench compare A B`: the table of B against A and whether B regressed. Refused,
/// naming both records, when they cannot be compared.
pub fn compare_saved(dir: &Path, a: &str, b: &str, threshold_pct: f64) -> Result<(String, bool)> {
    let (ra, rb) = (load(dir, a)?, load(dir, b)?);
    let c = compare(&ra, &rb, threshold_pct).map_err(|r| {
        let (why, lines) = match &r {
            Refusal::Setup(_) => (
                "they were measured with different setups",
                super::compare::setup_differences(&ra.setup, &rb.setup, "in A", "in B"),
            ),
            Refusal::Incomparable(l) => (
                "expected figures for every engine and stage of B, each a positive rate with \
                 a 95% interval, in both",
                l.clone(),
            ),
        };
        anyhow::anyhow!(
            "cannot compare A = {a} with B = {b}: {why}:\n  {}",
            lines.join("\n  ")
        )
    })?;
    let header = format!(
        "A = {a} ({}, commit {}), B = {b} ({}, commit {})\n",
        ra.timestamp,
        ra.build.short_commit(),
        rb.timestamp,
        rb.build.short_commit()
    );
    Ok((header + &c.table("A", "B"), c.regressed()))
}

/// `raywave bench list`: one line per record in `dir`, oldest first, and one warning per file
/// that is not a usable record.
pub fn list(dir: &Path) -> Result<(String, Vec<String>)> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
            "no bench records: {} does not exist; save one with `raywave bench --save NAME`",
            dir.display()
        ),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", dir.display())),
    };
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    for path in paths {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        match record::load(&path, &name) {
            Ok(r) => rows.push((name, r)),
            Err(e) => warnings.push(format!("skipped {}: {e:#}", path.display())),
        }
    }
    rows.sort_by(|a, b| (&a.1.timestamp, &a.0).cmp(&(&b.1.timestamp, &b.0)));
    if rows.is_empty() {
        return Ok((format!("no bench records in {}\n", dir.display()), warnings));
    }
    let mut out = format!(
        "{:<24} {:<20} {:<20} {:<28} {:<24} {:>7} {:>10} {:>10}\n",
        "name", "date", "commit", "scene", "settings", "threads", "ref Mr/s", "wave Mr/s"
    );
    for (name, r) in rows {
        let s = &r.setup.settings;
        let total = |engine: &str| {
            r.engines
                .iter()
                .find(|e| e.engine == engine)
                .and_then(|e| e.summary.iter().find(|f| f.figure == "total"))
                .map_or("-".to_string(), |f| format!("{:.2}", f.median / 1e6))
        };
        let source = crate::render::quote::escape(&r.setup.scene.source);
        let scene: String = if source.chars().count() > 28 {
            format!("{}…", source.chars().take(27).collect::<String>())
        } else {
            source
        };
        out.push_str(&format!(
            "{:<24} {:<20} {:<20} {:<28} {:<24} {:>7} {:>10} {:>10}\n",
            name,
            r.timestamp,
            r.build.short_commit(),
            scene,
            format!(
                "{}x{} b{} s{} aa{}",
                s.width, s.height, s.bounces, s.shadow_samples, s.aa_samples
            ),
            r.setup.threads,
            total("reference"),
            total("wavefront")
        ));
    }
    Ok((out, warnings))
}
