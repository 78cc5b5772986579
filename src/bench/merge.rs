//! `raywave bench merge PARTS...`: the part files of a sharded sweep (shard.rs) put back
//! together, with the reports, exports and saved records of the sweep run whole.
//!
//! ```text
//! crate::shard::merge: every part read and checked, alone and against the others; more
//!                      than one machine refused without --across-machines
//! records in sweep order (grouped by host with --across-machines); --save; the exports
//! ```
//!
//! Rates measured on different machines are never compared as one machine's: with
//! `--across-machines`, every report, row and exported name carries its host (name and CPU).

use super::export::Exports;
use super::running::sweep::record_name;
use super::shard::SweepPoints;
use crate::output::OutputPlan;
use crate::output::bench_record::{self as record, BenchRecord, record_path};
use crate::shard::Machines;
use anyhow::Result;
use std::fmt::Write as _;
use std::path::PathBuf;

/// What `raywave bench merge` is asked to do (its flags, as plain values).
#[derive(Clone, Debug)]
pub struct MergeOptions {
    /// The part files, in any order.
    pub parts: Vec<PathBuf>,
    /// The exports to write.
    pub exports: Exports,
    /// Save each point as DIR/NAME+POINT.json (DIR/NAME.json for a sweep of one point).
    pub save: Option<String>,
    /// Directory of saved records.
    pub dir: PathBuf,
    /// Accept parts measured on different machines, grouping every output by host.
    pub across_machines: bool,
}

/// What a merge put together.
#[derive(Debug)]
pub struct Merged {
    /// One record per point: in sweep order, or grouped by host with `--across-machines`.
    pub records: Vec<BenchRecord>,
    /// Each record's point label.
    pub labels: Vec<String>,
    /// Each record's host, an index into `shards.hosts`.
    pub host_of: Vec<usize>,
    /// The parts and the machines that ran them (their records are in `records`).
    pub shards: crate::shard::Merged<SweepPoints>,
    /// The records saved.
    pub saved: Vec<PathBuf>,
    /// Whether the outputs are grouped by host.
    pub by_host: bool,
}

/// Reads and checks the parts, then saves and exports the merged sweep as asked.
pub fn merge(args: &MergeOptions) -> Result<Merged> {
    let machines = if args.across_machines {
        Machines::Any
    } else {
        Machines::One {
            unless: "--across-machines",
        }
    };
    let mut shards = crate::shard::merge::<SweepPoints>(&args.parts, machines)?;
    let by_host = args.across_machines;
    // In sweep order, or grouped by host (hosts in the order of their first point, each
    // host's points in sweep order).
    let mut rows: Vec<(usize, BenchRecord)> = std::mem::take(&mut shards.results)
        .into_iter()
        .enumerate()
        .collect();
    if by_host {
        rows.sort_by_key(|&(i, _)| (shards.item_host[i], i));
    }
    let points = &shards.identity().work.points;
    let labels: Vec<String> = rows.iter().map(|(i, _)| points[*i].label.clone()).collect();
    let host_of = rows.iter().map(|(i, _)| shards.item_host[*i]).collect();
    let records: Vec<BenchRecord> = rows.into_iter().map(|(_, r)| r).collect();

    // Every output is checked against the parts and each other before anything is written.
    let names = args
        .save
        .iter()
        .flat_map(|n| labels.iter().map(move |l| record_name(n, l)));
    let to_save = names
        .map(|n| record_path(&args.dir, &n))
        .collect::<Result<Vec<_>>>()?;
    let plan = shards
        .parts
        .iter()
        .fold(OutputPlan::new(), |plan, (p, _)| plan.input("PARTS", p));
    let plan = to_save
        .iter()
        .fold(plan, |plan, p| plan.output_in_new_dir("--save", p));
    args.exports.plan(plan).check()?;
    for (path, r) in to_save.iter().zip(&records) {
        record::save(path, r)?;
    }
    args.exports.write(&records, &labels, by_host)?;
    Ok(Merged {
        records,
        labels,
        host_of,
        shards,
        saved: to_save,
        by_host,
    })
}

impl Merged {
    /// The text a merge prints: each point's report as the sweep run whole prints it (under a
    /// heading per host with `--across-machines`), unless `quiet`; the records saved; then what
    /// was merged: shards, points, hosts, and the time summed against the time elapsed.
    pub fn text(&self, quiet: bool) -> String {
        let mut out = String::new();
        if !quiet {
            let mut host = None;
            for ((r, label), &h) in self.records.iter().zip(&self.labels).zip(&self.host_of) {
                if self.by_host && host != Some(h) {
                    let (name, cpu) = (&self.shards.hosts[h].hostname, &self.shards.hosts[h].cpu);
                    let _ = writeln!(out, "\nhost    {name} · {cpu}");
                    host = Some(h);
                }
                if !label.is_empty() {
                    let _ = writeln!(out, "\npoint   {label}");
                }
                out.push_str(&super::report(r));
            }
            for path in &self.saved {
                let _ = writeln!(out, "saved   {}", path.display());
            }
            out.push('\n');
        }
        let _ = writeln!(
            out,
            "merged  {} shard(s), {} point(s) of one sweep, measured on {} host(s)",
            self.shards.parts.len(),
            self.records.len(),
            self.shards.hosts.len()
        );
        let sweep = &self.shards.identity().work;
        for (path, part) in &self.shards.parts {
            let labels: Vec<&str> = part
                .items
                .iter()
                .map(|&i| sweep.points[i].label.as_str())
                .collect();
            let _ = writeln!(
                out,
                "  {} {}: {} on {}, {:.2} s",
                part.shard,
                path.display(),
                super::points_text(&labels, "no points"),
                part.host.hostname,
                part.host.seconds()
            );
        }
        for h in &self.shards.hosts {
            let _ = writeln!(out, "  host {}: {}", h.hostname, h.cpu);
        }
        let _ = writeln!(
            out,
            "time    {:.2} s of benching summed over the shards, {:.2} s elapsed from the \
             first start to the last end",
            self.shards.summed_seconds(),
            self.shards.elapsed_seconds()
        );
        out
    }
}
