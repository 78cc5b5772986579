//! `raywave variance merge PARTS... --out DIR`: the shards' parts joined into the report a
//! single process would have written. Every figure that does not come from a clock is the same
//! bit for bit (`tests/commands/variance_shards.rs` holds it so); the timings keep the host that
//! measured them.
//!
//! A merge refuses, naming the part files: a part that is cut short or corrupt, parts of
//! different studies or raywave builds, a shard missing or given twice, a part whose jobs are
//! not its shard's, and an output directory that is one of its inputs.

use super::command::{Outcome, create_out, write_report};
use super::jobs::{self, CaseFacts, JobResult};
use super::part::{self, Part};
use crate::render::error::UsageError;
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// A finished merge: the report, and what went into it.
pub struct Merged {
    /// The report and the files written.
    pub outcome: Outcome,
    /// The part files read.
    pub parts: Vec<PathBuf>,
    /// Shards in the study.
    pub shards: usize,
    /// Jobs in the study.
    pub jobs: usize,
    /// Per host: its name, the shards and jobs it ran, and its shards' summed wall time.
    pub hosts: Vec<(String, usize, usize, f64)>,
    /// Per shard, in index order: its part, host, jobs and wall time.
    pub shard_times: Vec<(PathBuf, String, usize, f64)>,
    /// Seconds from the first shard's start to the last one's end.
    pub elapsed: f64,
    /// How many times a shard rendered a case's converged reference (not from the cache).
    pub references_rendered: usize,
    /// How many times a shard read a case's converged reference from the cache.
    pub references_cached: usize,
}

impl Merged {
    /// What the merge prints after the report: shards, jobs, hosts, and the shards' wall time
    /// summed against the elapsed time.
    pub fn describe(&self) -> String {
        let summed: f64 = self.hosts.iter().map(|h| h.3).sum();
        let hosts: Vec<String> = self
            .hosts
            .iter()
            .map(|(name, shards, jobs, wall)| {
                format!("{name} ({shards} shards, {jobs} jobs, {wall:.1} s)")
            })
            .collect();
        let shards: String = self
            .shard_times
            .iter()
            .enumerate()
            .map(|(i, (path, host, jobs, wall))| {
                format!(
                    "  {i}/{} {}: {jobs} jobs on {host}, {wall:.1} s\n",
                    self.shards,
                    path.display()
                )
            })
            .collect();
        format!(
            "{shards}merged  {} shards, {} jobs, {} host{}: {}\nwall    {summed:.1} s summed over the shards, {:.1} s from the first start to the last end ({:.2} shards at once on average)\nreferences {} rendered by a shard, {} read from the cache\n",
            self.shards,
            self.jobs,
            self.hosts.len(),
            if self.hosts.len() == 1 { "" } else { "s" },
            hosts.join(", "),
            self.elapsed,
            summed / self.elapsed.max(1e-9),
            self.references_rendered,
            self.references_cached
        )
    }
}

/// Whether `out` names the same file or directory as `input` (both resolved; false when either
/// does not exist).
fn same_place(out: &Path, input: &Path) -> bool {
    match (out.canonicalize(), input.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Reads the parts named by `inputs` (files, or directories of `*.part`), checks that they are
/// every shard of one study exactly once, and writes the study's report into `out`.
pub fn merge(inputs: &[PathBuf], out: &Path, notice: &(dyn Fn(&str) + Sync)) -> Result<Merged> {
    if inputs.is_empty() {
        bail!(
            "no parts given: expected the shard-I-of-N.part files of every shard, or their directory"
        );
    }
    for input in inputs {
        if same_place(out, input) {
            return Err(UsageError(format!(
                "--out {} is one of the merge's inputs: expected a directory of its own for the report, so that no part is overwritten",
                out.display()
            ))
            .into());
        }
    }
    let paths = part::expand(inputs)?;
    for path in &paths {
        if path.parent().is_some_and(|dir| same_place(out, dir)) {
            return Err(UsageError(format!(
                "--out {} holds the part {}: expected a directory of its own for the report, so that no part is overwritten",
                out.display(),
                path.display()
            ))
            .into());
        }
    }
    let mut parts: Vec<(PathBuf, Part)> = Vec::new();
    for path in &paths {
        if let Some((earlier, _)) = parts.iter().find(|(p, _)| same_place(p, path)) {
            bail!(
                "{} is given twice (also as {}): expected each part once",
                path.display(),
                earlier.display()
            );
        }
        parts.push((path.clone(), part::read(path)?));
    }
    let (first_path, first) = &parts[0];
    let identity = first.identity.clone();
    let count = first.shard.count;
    for (path, p) in &parts[1..] {
        if let Some(what) = identity.difference(&p.identity) {
            bail!(
                "{} and {} are not parts of the same study: {what}",
                first_path.display(),
                path.display()
            );
        }
        if p.shard.count != count {
            bail!(
                "{} is shard {} but {} is shard {}: expected every part to come from the same --shard count",
                first_path.display(),
                first.shard,
                path.display(),
                p.shard
            );
        }
    }
    let mut by_index: Vec<Option<&PathBuf>> = vec![None; count];
    for (path, p) in &parts {
        let slot = &mut by_index[p.shard.index];
        if let Some(other) = slot {
            bail!(
                "{} and {} are both shard {}: expected each shard once",
                other.display(),
                path.display(),
                p.shard
            );
        }
        *slot = Some(path);
    }
    let missing: Vec<String> = by_index
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_none())
        .map(|(i, _)| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        let given: Vec<String> = parts.iter().map(|(p, _)| p.display().to_string()).collect();
        bail!(
            "shard{} {} missing: expected all {count} shards, got {} ({}); run the missing shard{} with the same flags",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", ") + if missing.len() == 1 { " is" } else { " are" },
            parts.len(),
            given.join(", "),
            if missing.len() == 1 { "" } else { "s" },
        );
    }
    let assignment = identity.assignment(count);
    let all = identity.jobs();
    for (path, p) in &parts {
        let expected = &assignment[p.shard.index];
        let results: Vec<_> = p.results.iter().map(|r| r.job()).collect();
        let wanted: Vec<_> = expected.iter().map(|&j| all[j]).collect();
        if &p.jobs != expected || results != wanted {
            bail!(
                "{}: its jobs are not those of shard {} of this study (expected {} jobs, found {} results): was it edited, or written by another raywave?",
                path.display(),
                p.shard,
                expected.len(),
                p.results.len()
            );
        }
    }
    create_out(out)?;
    let cases = identity.cases.len();
    let mut facts: Vec<Option<(CaseFacts, String, usize, PathBuf)>> = vec![None; cases];
    let mut results: Vec<Vec<JobResult>> = vec![Vec::new(); cases];
    let mut rendered = 0;
    for (path, p) in parts.iter_mut() {
        for (c, source, f) in &p.cases {
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
                    identity.cases[*c].name
                ),
                // The reference counts as cached only when every shard read it from the cache.
                Some((known, ..)) => known.reference_cached &= f.reference_cached,
                None => *slot = Some((f.clone(), source.clone(), p.host.threads, path.clone())),
            }
            rendered += usize::from(!f.reference_cached);
        }
        // Moved, not copied: the parts' results are not needed after this.
        for r in std::mem::take(&mut p.results) {
            let r = JobResult::from(r);
            results[r.job.case].push(r);
        }
    }
    let mut studies = Vec::new();
    for (c, case) in identity.cases.iter().enumerate() {
        let Some((f, source, threads, _)) = &facts[c] else {
            bail!("no part holds the setup of case {}", case.name);
        };
        let jobs = std::mem::take(&mut results[c]);
        studies.push(jobs::assemble(
            &case.config,
            source,
            &identity.engine,
            *threads,
            f,
            jobs,
        ));
    }
    let names: Vec<String> = identity.cases.iter().map(|c| c.name.clone()).collect();
    let outcome = write_report(&names, studies, out, notice)?;
    let mut hosts: Vec<(String, usize, usize, f64)> = Vec::new();
    for (_, p) in &parts {
        let wall = (p.host.finished - p.host.started).max(0.0);
        match hosts.iter_mut().find(|h| h.0 == p.host.hostname) {
            Some(h) => {
                h.1 += 1;
                h.2 += p.jobs.len();
                h.3 += wall;
            }
            None => hosts.push((p.host.hostname.clone(), 1, p.jobs.len(), wall)),
        }
    }
    let mut by_shard: Vec<&(PathBuf, Part)> = parts.iter().collect();
    by_shard.sort_by_key(|(_, p)| p.shard.index);
    let shard_times = by_shard
        .iter()
        .map(|(path, p)| {
            let wall = (p.host.finished - p.host.started).max(0.0);
            (path.clone(), p.host.hostname.clone(), p.jobs.len(), wall)
        })
        .collect();
    let start = parts
        .iter()
        .map(|(_, p)| p.host.started)
        .fold(f64::INFINITY, f64::min);
    let end = parts
        .iter()
        .map(|(_, p)| p.host.finished)
        .fold(f64::NEG_INFINITY, f64::max);
    Ok(Merged {
        outcome,
        parts: paths,
        shards: count,
        jobs: all.len(),
        hosts,
        shard_times,
        elapsed: (end - start).max(0.0),
        references_rendered: rendered,
        references_cached: parts.iter().map(|(_, p)| p.cases.len()).sum::<usize>() - rendered,
    })
}
