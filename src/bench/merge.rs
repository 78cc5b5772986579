//! `raywave bench merge PARTS...`: the part files of a sharded sweep (shard.rs) put back
//! together, with the reports, exports and saved records of the sweep run whole.
//!
//! ```text
//! read every part (whole, checksum, consistent with itself; errors name the file)
//! refuse: shard counts that disagree; another SIMD path; another build; another sweep; a shard
//!         missing or twice; more than one machine without --across-machines
//! records in sweep order (grouped by host with --across-machines); --save; the exports
//! ```
//!
//! Rates measured on different machines are never compared as one machine's: a merge of parts
//! from more than one host (host name and CPU) is refused unless `--across-machines` is given,
//! and then every report, row and exported name carries its host, the points grouped by host.

use super::export::Exports;
use super::shard::{Part, read_part};
use super::sweep::record_name;
use crate::output::OutputPlan;
use crate::output::bench_record::{self as record, BenchRecord};
use crate::output::machine::Machine;
use anyhow::{Result, bail};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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

/// A machine that ran shards: its host name and CPU.
#[derive(Clone, Debug, PartialEq)]
pub struct Host {
    /// Host name.
    pub hostname: String,
    /// CPU model.
    pub cpu: String,
}

impl Host {
    fn of(m: &Machine) -> Host {
        Host {
            hostname: m.hostname.clone(),
            cpu: m.cpu.clone(),
        }
    }
}

/// What a merge put together.
#[derive(Debug)]
pub struct Merged {
    /// One record per point: in sweep order, or grouped by host with `--across-machines`.
    pub records: Vec<BenchRecord>,
    /// Each record's point label.
    pub labels: Vec<String>,
    /// Each record's host, an index into `hosts`.
    pub host_of: Vec<usize>,
    /// The machines, in the order of the first point each ran.
    pub hosts: Vec<Host>,
    /// The part files, by shard index.
    pub parts: Vec<(PathBuf, Part)>,
    /// Seconds of benching, summed over the shards.
    pub wall_seconds: f64,
    /// Seconds from the first shard's start to the last one's end (clocks of different
    /// machines may disagree).
    pub elapsed_seconds: f64,
    /// The records saved.
    pub saved: Vec<PathBuf>,
    /// Whether the outputs are grouped by host.
    pub by_host: bool,
}

/// Reads and checks the parts, then saves and exports the merged sweep as asked.
pub fn merge(args: &MergeOptions) -> Result<Merged> {
    let mut parts = Vec::new();
    let paths = crate::output::shard::expand_parts(
        &args.parts,
        |n| n.starts_with("bench-shard-") && n.ends_with(".json"),
        "bench shard parts (bench-shard-I-of-N.json)",
    )?;
    for path in &paths {
        parts.push((path.clone(), read_part(path)?));
    }
    let Some((first_path, first)) = parts.first() else {
        bail!("nothing to merge: expected the part files of `raywave bench --shard I/N`");
    };
    let shown = |p: &Path| p.display().to_string();
    let count = first.shard.count;
    if let Some((p, part)) = parts.iter().find(|(_, q)| q.shard.count != count) {
        bail!(
            "the parts disagree on the number of shards: {} is shard {}, {} is shard {}; \
             expected the N shards of one `--shard I/N` split",
            shown(first_path),
            first.shard,
            shown(p),
            part.shard
        );
    }
    for (p, part) in &parts[1..] {
        let (a, b) = (shown(first_path), shown(p));
        let build =
            first
                .sweep
                .build_differences(&part.sweep, &format!("in {a}"), &format!("in {b}"));
        // The SIMD path first: binaries built for two CPUs (`target-cpu=native` on two kinds of
        // node) can share a commit and differ only there, and their kernels are not the same.
        if first.sweep.simd != part.sweep.simd {
            bail!(
                "{a} and {b} were run by binaries with different SIMD paths, {} and {}, so \
                 their figures do not time the same kernels:\n  {}\nrun every shard with one \
                 build (for nodes of several CPUs, one built for the oldest: docs/SCALING.md)",
                first.sweep.simd,
                part.sweep.simd,
                build.join("\n  ")
            );
        }
        if !build.is_empty() {
            bail!(
                "{a} and {b} come from different raywave builds, so their figures do not \
                 describe the same code:\n  {}\nrun every shard with one build",
                build.join("\n  ")
            );
        }
        let sweep =
            first
                .sweep
                .sweep_differences(&part.sweep, &format!("in {a}"), &format!("in {b}"));
        if !sweep.is_empty() {
            bail!(
                "{a} and {b} are shards of different sweeps:\n  {}\nrun every shard with the \
                 same scene and flags (give --threads when the machines' core counts differ)",
                sweep.join("\n  ")
            );
        }
    }
    let mut by_index: Vec<Option<usize>> = vec![None; count];
    for (k, (p, part)) in parts.iter().enumerate() {
        if let Some(j) = by_index[part.shard.index] {
            bail!(
                "shard {} is given twice: {} and {}; expected each shard once",
                part.shard,
                shown(&parts[j].0),
                shown(p)
            );
        }
        by_index[part.shard.index] = Some(k);
    }
    let missing: Vec<String> = (0..count)
        .filter(|&i| by_index[i].is_none())
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        let given: Vec<String> = parts
            .iter()
            .map(|(p, part)| format!("{} ({})", shown(p), part.shard))
            .collect();
        bail!(
            "shard(s) {} missing: got {}; run `raywave bench` with the same flags and \
             --shard {} to make it",
            missing.join(", "),
            given.join(", "),
            missing[0]
        );
    }
    let mut parts: Vec<(PathBuf, Part)> = {
        let mut v: Vec<Option<(PathBuf, Part)>> = parts.into_iter().map(Some).collect();
        by_index
            .iter()
            .filter_map(|k| k.and_then(|k| v[k].take()))
            .collect()
    };

    let mut hosts: Vec<Host> = Vec::new();
    let mut point_host = vec![0usize; parts[0].1.sweep.points.len()];
    let mut order: Vec<usize> = (0..point_host.len()).collect();
    for (_, part) in &parts {
        let h = Host::of(&part.host);
        let at = hosts.iter().position(|x| *x == h).unwrap_or_else(|| {
            hosts.push(h);
            hosts.len() - 1
        });
        for &i in &part.points {
            point_host[i] = at;
        }
    }
    if hosts.len() > 1 && !args.across_machines {
        let ran: Vec<String> = parts
            .iter()
            .map(|(p, part)| format!("{} on {} ({})", shown(p), part.host.hostname, part.host.cpu))
            .collect();
        bail!(
            "the parts were measured on {} machines:\n  {}\nrates of different machines are \
             not one machine's figures: run every shard on one machine, or give \
             --across-machines to merge them with every point labelled and grouped by host",
            hosts.len(),
            ran.join("\n  ")
        );
    }
    let by_host = args.across_machines;
    if by_host {
        // Hosts in the order of their first point, each host's points in sweep order.
        hosts = {
            let mut first_point: Vec<(usize, usize)> = (0..hosts.len())
                .map(|h| {
                    (
                        point_host
                            .iter()
                            .position(|&x| x == h)
                            .unwrap_or(usize::MAX),
                        h,
                    )
                })
                .collect();
            first_point.sort();
            let renumber: Vec<usize> = {
                let mut r = vec![0; hosts.len()];
                for (new, &(_, old)) in first_point.iter().enumerate() {
                    r[old] = new;
                }
                r
            };
            for h in &mut point_host {
                *h = renumber[*h];
            }
            first_point
                .iter()
                .map(|&(_, old)| hosts[old].clone())
                .collect()
        };
        order.sort_by_key(|&i| (point_host[i], i));
    }

    let mut slots: Vec<Option<BenchRecord>> = vec![None; point_host.len()];
    for (_, part) in &mut parts {
        for (&i, r) in part.points.iter().zip(std::mem::take(&mut part.records)) {
            slots[i] = Some(r);
        }
    }
    let sweep = &parts[0].1.sweep;
    let mut records = Vec::new();
    let mut labels = Vec::new();
    let mut host_of = Vec::new();
    for &i in &order {
        let Some(r) = slots[i].take() else {
            bail!("no shard ran point {i} of the sweep: the parts are inconsistent");
        };
        records.push(r);
        labels.push(sweep.points[i].label.clone());
        host_of.push(point_host[i]);
    }

    let time = |s: &str| humantime::parse_rfc3339(s).ok();
    let wall_seconds = parts.iter().map(|(_, p)| p.seconds).sum();
    let start = parts.iter().filter_map(|(_, p)| time(&p.started)).min();
    let end = parts.iter().filter_map(|(_, p)| time(&p.finished)).max();
    let elapsed_seconds = match (start, end) {
        (Some(s), Some(e)) => e.duration_since(s).map_or(0.0, |d| d.as_secs_f64()),
        _ => 0.0,
    };

    // Every output is checked against the parts and each other before anything is written.
    let mut to_save = Vec::new();
    if let Some(name) = &args.save {
        for label in &labels {
            let point = super::sweep::Point {
                size: None,
                shadow_samples: None,
                threads: None,
                label: label.clone(),
            };
            to_save.push(record::record_path(&args.dir, &record_name(name, &point))?);
        }
    }
    let mut plan = OutputPlan::new();
    for (p, _) in &parts {
        plan = plan.input("PARTS", p);
    }
    for p in &to_save {
        plan = plan.output_in_new_dir("--save", p);
    }
    for (flag, p) in args.exports.flags() {
        plan = plan.output(flag, p);
    }
    plan.check()?;
    for (path, r) in to_save.iter().zip(&records) {
        record::save(path, r)?;
    }
    args.exports.write(&records, &labels, by_host)?;
    let saved = to_save;
    Ok(Merged {
        records,
        labels,
        host_of,
        hosts,
        parts,
        wall_seconds,
        elapsed_seconds,
        saved,
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
                    let _ = writeln!(
                        out,
                        "\nhost    {} · {}",
                        self.hosts[h].hostname, self.hosts[h].cpu
                    );
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
            self.parts.len(),
            self.records.len(),
            self.hosts.len()
        );
        for (path, part) in &self.parts {
            let points = if part.labels.is_empty() {
                "no points".to_string()
            } else if part.labels.iter().all(|l| l.is_empty()) {
                format!("{} point(s)", part.labels.len())
            } else {
                part.labels.join(", ")
            };
            let _ = writeln!(
                out,
                "  {} {}: {} on {}, {:.2} s",
                part.shard,
                path.display(),
                points,
                part.host.hostname,
                part.seconds
            );
        }
        for h in &self.hosts {
            let _ = writeln!(out, "  host {}: {}", h.hostname, h.cpu);
        }
        let _ = writeln!(
            out,
            "time    {:.2} s of benching summed over the shards, {:.2} s elapsed from the \
             first start to the last end",
            self.wall_seconds, self.elapsed_seconds
        );
        out
    }
}
