//! The merge: part files put back into one run, with every check written once.
//!
//! ```text
//! inputs     files as given; in a directory, its KIND-shard-*.part files in name order
//! each part  read_part: whole, intact, of this kind, consistent with itself
//! together   the same file twice; shard counts that disagree; another SIMD path, build or
//!            work; a shard twice or missing; more than one machine, unless allowed
//! result     the parts by shard index, every item's result in item order, the machines
//! ```

use super::identity::{Identity, Work};
use super::part::{Part, read_part};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// Whether a merge accepts parts measured on more than one machine.
#[derive(Clone, Copy, Debug)]
pub enum Machines {
    /// Any number: the command keeps each result's machine (variance's timings do).
    Any,
    /// One, unless the command's flag (named here, for the message) says otherwise.
    One {
        /// The flag that accepts several (`--across-machines`).
        unless: &'static str,
    },
}

/// A machine that ran shards, and what it ran.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HostSummary {
    /// Host name.
    pub hostname: String,
    /// CPU model.
    pub cpu: String,
    /// How many shards it ran.
    pub shards: usize,
    /// How many items.
    pub items: usize,
    /// Its shards' wall-clock seconds, summed.
    pub seconds: f64,
}

/// The parts of one run, checked and put together.
#[derive(Debug)]
pub struct Merged<W: Work> {
    /// The parts, by shard index, each with its file; their results are in `results`.
    pub parts: Vec<(PathBuf, Part<W>)>,
    /// Every item's result, in item order.
    pub results: Vec<W::Result>,
    /// The machines, in the order of the first item each ran.
    pub hosts: Vec<HostSummary>,
    /// Each item's machine, an index into `hosts`.
    pub item_host: Vec<usize>,
}

impl<W: Work> Merged<W> {
    /// The run's identity (every part's).
    pub fn identity(&self) -> &Identity<W> {
        &self.parts[0].1.identity
    }

    /// Seconds of work, summed over the shards.
    pub fn summed_seconds(&self) -> f64 {
        self.parts.iter().map(|(_, p)| p.host.seconds()).sum()
    }

    /// Seconds from the first shard's start to the last one's end (clocks of different
    /// machines may disagree).
    pub fn elapsed_seconds(&self) -> f64 {
        let start = self.parts.iter().map(|(_, p)| p.host.started);
        let end = self.parts.iter().map(|(_, p)| p.host.finished);
        (end.fold(f64::NEG_INFINITY, f64::max) - start.fold(f64::INFINITY, f64::min)).max(0.0)
    }
}

/// Whether `a` and `b` name the same file (both resolved; false when either does not exist).
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    matches!((a.canonicalize(), b.canonicalize()), (Ok(a), Ok(b)) if a == b)
}

/// The part files named by `inputs`: each file as given, and in each directory its
/// `KIND-shard-*.part` files, in name order.
fn expand<W: Work>(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let prefix = format!("{}-shard-", W::KIND);
    let mut out = Vec::new();
    for input in inputs {
        if !input.is_dir() {
            out.push(input.clone());
            continue;
        }
        let mut found: Vec<PathBuf> = std::fs::read_dir(input)
            .with_context(|| format!("cannot list {}", input.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.is_file()
                    && p.file_name().is_some_and(|n| {
                        let n = n.to_string_lossy();
                        n.starts_with(&prefix) && n.ends_with(".part")
                    })
            })
            .collect();
        if found.is_empty() {
            bail!(
                "{}: expected {} shard parts ({prefix}I-of-N.part) in this directory, found none",
                input.display(),
                W::KIND
            );
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

/// Reads the parts named by `inputs` (files, or directories of parts) and checks that they are
/// every shard of one run exactly once; errors name the files.
pub fn merge<W: Work>(inputs: &[PathBuf], machines: Machines) -> Result<Merged<W>> {
    let command = W::COMMAND;
    let paths = expand::<W>(inputs)?;
    let mut parts: Vec<(PathBuf, Part<W>)> = Vec::new();
    for path in &paths {
        if let Some((earlier, _)) = parts.iter().find(|(p, _)| same_file(p, path)) {
            bail!(
                "{} is given twice (also as {}): expected each part once",
                path.display(),
                earlier.display()
            );
        }
        parts.push((path.clone(), read_part::<W>(path)?));
    }
    let Some((first_path, first)) = parts.first() else {
        bail!("nothing to merge: expected the part files of `{command}`, or their directory");
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
        if let Some(refusal) = first
            .identity
            .refusal(&part.identity, &shown(first_path), &shown(p))
        {
            bail!("{refusal}");
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
        let (s, are) = if missing.len() == 1 {
            ("", "is")
        } else {
            ("s", "are")
        };
        bail!(
            "shard{s} {} {are} missing: expected all {count} shards, got {}; run `{}` with the \
             same flags and --shard {} to make it",
            missing.join(", "),
            given.join(", "),
            command.trim_end_matches(" --shard I/N"),
            missing[0]
        );
    }
    // Every shard is here exactly once now, so its index is its place.
    let items = first.identity.work.costs().len();
    parts.sort_by_key(|(_, p)| p.shard.index);

    let mut hosts: Vec<HostSummary> = Vec::new();
    let mut item_host = vec![usize::MAX; items];
    // Machines in the order of the first item each ran.
    let mut by_first: Vec<&(PathBuf, Part<W>)> = parts.iter().collect();
    by_first.sort_by_key(|(_, p)| p.items.first().copied().unwrap_or(usize::MAX));
    for (_, part) in by_first {
        let same = |h: &HostSummary| (&h.hostname, &h.cpu) == (&part.host.hostname, &part.host.cpu);
        let at = hosts.iter().position(same).unwrap_or_else(|| {
            hosts.push(HostSummary {
                hostname: part.host.hostname.clone(),
                cpu: part.host.cpu.clone(),
                ..HostSummary::default()
            });
            hosts.len() - 1
        });
        let h = &mut hosts[at];
        h.shards += 1;
        h.items += part.items.len();
        h.seconds += part.host.seconds();
        for &i in &part.items {
            item_host[i] = at;
        }
    }
    if let (Machines::One { unless }, true) = (machines, hosts.len() > 1) {
        let ran: Vec<String> = parts
            .iter()
            .map(|(p, part)| format!("{} on {} ({})", shown(p), part.host.hostname, part.host.cpu))
            .collect();
        bail!(
            "the parts were measured on {} machines:\n  {}\nrates of different machines are \
             not one machine's figures: run every shard on one machine, or give {unless} to \
             merge them with every point labelled and grouped by host",
            hosts.len(),
            ran.join("\n  ")
        );
    }

    let mut slots: Vec<Option<W::Result>> = (0..items).map(|_| None).collect();
    for (_, part) in &mut parts {
        for (&i, r) in part.items.iter().zip(std::mem::take(&mut part.results)) {
            slots[i] = Some(r);
        }
    }
    let results = (slots.into_iter().enumerate())
        .map(|(i, r)| {
            r.with_context(|| format!("no shard ran item {i}: the parts are inconsistent"))
        })
        .collect::<Result<_>>()?;
    Ok(Merged {
        parts,
        results,
        hosts,
        item_host,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shard::part::write_part;
    use crate::shard::toy::{Toy, part};

    const COSTS: [f64; 5] = [5.0, 4.0, 3.0, 2.0, 1.0];

    /// Every shard of a toy run in three, written into a fresh directory.
    fn three() -> (tempfile::TempDir, Vec<PathBuf>) {
        let dir = tempfile::tempdir().unwrap();
        let paths = (0..3)
            .map(|i| write_part(dir.path(), &part(&COSTS, i, 3)).unwrap())
            .collect();
        (dir, paths)
    }

    fn refused(inputs: &[PathBuf], needles: &[&str]) {
        let e = format!("{:#}", merge::<Toy>(inputs, Machines::Any).unwrap_err());
        for n in needles {
            assert!(e.contains(n), "expected `{n}` in: {e}");
        }
    }

    #[test]
    fn the_parts_of_a_run_merge_into_item_order_from_files_or_their_directory() {
        let (dir, paths) = three();
        let reversed: Vec<PathBuf> = paths.iter().rev().cloned().collect();
        for inputs in [reversed, vec![dir.path().to_path_buf()]] {
            let merged = merge::<Toy>(&inputs, Machines::Any).unwrap();
            assert_eq!(merged.results, [0, 1, 4, 9, 16]);
            let shards: Vec<usize> = merged.parts.iter().map(|(_, p)| p.shard.index).collect();
            assert_eq!(shards, [0, 1, 2]);
            assert_eq!(merged.hosts.len(), 1);
            assert_eq!((merged.hosts[0].shards, merged.hosts[0].items), (3, 5));
            assert_eq!(merged.item_host, [0; 5]);
        }
    }

    #[test]
    fn missing_repeated_and_foreign_parts_are_refused_naming_them() {
        let (dir, p) = three();
        let shown = |i: usize| p[i].display().to_string();
        refused(
            &[p[0].clone(), p[2].clone()],
            &["shard 1/3 is missing", &shown(0), "--shard 1/3"],
        );
        refused(&[p[0].clone()], &["shards 1/3, 2/3 are missing"]);
        refused(
            &[p[0].clone(), p[1].clone(), p[0].clone()],
            &["given twice (also as"],
        );
        let copy = dir.path().join("copy.part");
        std::fs::copy(&p[1], &copy).unwrap();
        refused(
            &[p[0].clone(), p[1].clone(), copy.clone(), p[2].clone()],
            &["shard 1/3 is given twice", &shown(1), "copy.part"],
        );
        let other = tempfile::tempdir().unwrap();
        let two = write_part(other.path(), &part(&COSTS, 1, 2)).unwrap();
        refused(
            &[p[0].clone(), two],
            &["disagree on the number of shards", "0/3", "1/2"],
        );
        let mut costs = COSTS;
        costs[4] = 1.5;
        let foreign = write_part(other.path(), &part(&costs, 1, 3)).unwrap();
        refused(
            &[p[0].clone(), foreign, p[2].clone()],
            &[
                "are not shards of the same toy run",
                "costs: ",
                "run every shard with the same toys",
            ],
        );
        let mut simd = part(&COSTS, 1, 3);
        simd.identity.simd = "avx512".into();
        let simd = write_part(other.path(), &simd).unwrap();
        refused(
            &[p[0].clone(), simd, p[2].clone()],
            &["different SIMD paths, scalar and avx512", "simd: scalar in"],
        );
        let mut build = part(&COSTS, 1, 3);
        build.identity.build.rustflags = "-C target-cpu=x86-64-v2".into();
        let build = write_part(other.path(), &build).unwrap();
        refused(
            &[p[0].clone(), build, p[2].clone()],
            &["come from different raywave builds", "RUSTFLAGS: "],
        );
        refused(&[], &["nothing to merge"]);
        refused(
            &[other.path().join("none")],
            &["cannot read a part file of"],
        );
        let empty = tempfile::tempdir().unwrap();
        refused(
            &[empty.path().to_path_buf()],
            &["expected toy shard parts (toy-shard-I-of-N.part)"],
        );
    }

    #[test]
    fn parts_of_two_machines_merge_only_where_the_command_allows() {
        let dir = tempfile::tempdir().unwrap();
        let mut elsewhere = part(&COSTS, 0, 2);
        elsewhere.host.hostname = "elsewhere".into();
        let paths = [
            write_part(dir.path(), &elsewhere).unwrap(),
            write_part(dir.path(), &part(&COSTS, 1, 2)).unwrap(),
        ];
        let e = merge::<Toy>(&paths, Machines::One { unless: "--across" }).unwrap_err();
        let e = format!("{e:#}");
        assert!(
            e.contains("measured on 2 machines") && e.contains("give --across"),
            "{e}"
        );
        let merged = merge::<Toy>(&paths, Machines::Any).unwrap();
        // Shard 0 of 5, 4, 3, 2, 1 in two is items 0, 3, 4: elsewhere ran the first item.
        assert_eq!(merged.hosts[0].hostname, "elsewhere");
        assert_eq!(merged.item_host, [0, 1, 1, 0, 0]);
    }
}
