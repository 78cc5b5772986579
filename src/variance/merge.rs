//! `raywave variance merge PARTS... --out DIR`: the shards' parts joined into the report a
//! single process would have written. Every figure that does not come from a clock is the same
//! bit for bit (`tests/commands/variance_shards.rs` holds it so); the timings keep the host that
//! measured them.
//!
//! A merge refuses, naming the part files: a part that is cut short or corrupt, parts of
//! different studies or raywave builds, a shard missing or given twice, a part whose jobs are
//! not its shard's, and an output directory that is one of its inputs.

use super::command::{Outcome, create_out, write_report};
use super::study::jobs::{self, CaseFacts, JobResult};
use super::study::plan::Study;
use crate::render::error::UsageError;
use crate::shard::{Machines, same_file};
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// A finished merge: the report, and what went into it.
pub struct Merged {
    /// The report and the files written.
    pub outcome: Outcome,
    /// The parts read, by shard index, and their machines (the results moved into the report).
    shards: crate::shard::Merged<Study>,
}

impl Merged {
    /// What the merge prints after the report: shards, jobs, hosts, and the shards' wall time
    /// summed against the elapsed time.
    pub fn describe(&self) -> String {
        let (parts, hosts) = (&self.shards.parts, &self.shards.hosts);
        let (summed, elapsed) = (self.shards.summed_seconds(), self.shards.elapsed_seconds());
        // Each case a shard touched, by whether it read the converged reference from the cache.
        let touched = parts.iter().flat_map(|(_, p)| &p.extra);
        let (cached, rendered): (Vec<_>, Vec<_>) = touched.partition(|(.., f)| f.reference_cached);
        let host_list: Vec<String> = hosts
            .iter()
            .map(|h| {
                format!(
                    "{} ({} shards, {} jobs, {:.1} s)",
                    h.hostname, h.shards, h.items, h.seconds
                )
            })
            .collect();
        let shards: String = parts
            .iter()
            .enumerate()
            .map(|(i, (path, p))| {
                format!(
                    "  {i}/{} {}: {} jobs on {}, {:.1} s\n",
                    parts.len(),
                    path.display(),
                    p.items.len(),
                    p.host.hostname,
                    p.host.seconds()
                )
            })
            .collect();
        format!(
            "{shards}merged  {} shards, {} jobs, {} host{}: {}\nwall    {summed:.1} s summed over the shards, {:.1} s from the first start to the last end ({:.2} shards at once on average)\nreferences {} rendered by a shard, {} read from the cache\n",
            parts.len(),
            self.shards.identity().work.jobs().len(),
            hosts.len(),
            if hosts.len() == 1 { "" } else { "s" },
            host_list.join(", "),
            elapsed,
            summed / elapsed.max(1e-9),
            rendered.len(),
            cached.len()
        )
    }
}

/// Reads the parts named by `inputs` (files, or directories of parts), checks that they are
/// every shard of one study exactly once (`crate::shard::merge`), and writes the study's report
/// into `out`.
pub fn merge(inputs: &[PathBuf], out: &Path, notice: &(dyn Fn(&str) + Sync)) -> Result<Merged> {
    let beside = |what: String| -> anyhow::Error {
        UsageError(format!(
            "--out {} {what}: expected a directory of its own for the report, so that no part \
             is overwritten",
            out.display()
        ))
        .into()
    };
    if inputs.iter().any(|input| same_file(out, input)) {
        return Err(beside("is one of the merge's inputs".into()));
    }
    let mut merged = crate::shard::merge::<Study>(inputs, Machines::Any)?;
    if let Some((path, _)) = merged
        .parts
        .iter()
        .find(|(p, _)| p.parent().is_some_and(|dir| same_file(out, dir)))
    {
        return Err(beside(format!("holds the part {}", path.display())));
    }
    create_out(out)?;
    let study = merged.identity().work.clone();
    let cases = study.cases.len();
    let mut facts: Vec<Option<(CaseFacts, String, usize, PathBuf)>> = vec![None; cases];
    for (path, p) in &merged.parts {
        for (c, source, f) in &p.extra {
            let Some(slot) = facts.get_mut(*c) else {
                bail!(
                    "{}: names case {c}, but the study has {cases}",
                    path.display()
                );
            };
            let same = |a: &CaseFacts| {
                a.region_pixels == f.region_pixels && a.reference_mse == f.reference_mse
            };
            match slot {
                Some((known, _, _, from)) if !same(known) => bail!(
                    "{} and {} disagree on case {}'s converged reference or regions: expected the same figures from the same scene and settings",
                    from.display(),
                    path.display(),
                    study.cases[*c].name
                ),
                // The reference counts as cached only when every shard read it from the cache.
                Some((known, ..)) => known.reference_cached &= f.reference_cached,
                None => *slot = Some((f.clone(), source.clone(), p.host.threads, path.clone())),
            }
        }
    }
    let mut results: Vec<Vec<JobResult>> = vec![Vec::new(); cases];
    // Moved, not copied: the parts' results are not needed after this.
    for r in std::mem::take(&mut merged.results) {
        let r: JobResult = r.convert();
        results[r.job.case].push(r);
    }
    let mut studies = Vec::new();
    for ((facts, jobs), case) in facts.into_iter().zip(results).zip(&study.cases) {
        let Some((f, source, threads, _)) = facts else {
            bail!("no part holds the setup of case {}", case.name);
        };
        let result = jobs::assemble(&case.config, &source, &study.engine, threads, f, jobs);
        studies.push(result);
    }
    let names: Vec<String> = study.cases.iter().map(|c| c.name.clone()).collect();
    let outcome = write_report(&names, studies, out, notice)?;
    Ok(Merged {
        outcome,
        shards: merged,
    })
}
