//! The part file: what one shard ran, self-describing, checked whole, written whole or not at
//! all. One format for every kind of work.
//!
//! ```text
//! name     KIND-shard-I-of-N.part                  (bench-shard-0-of-3.part)
//! magic    8 bytes  "RWPART3\n"
//! kind     8 bytes  the work's kind, ASCII, NUL-padded ("bench", "variance")
//! length   u64 LE   bytes of the payload
//! fnv      u64 LE   FNV-1a (64-bit) of the payload
//! payload  CBOR of Part<W>: identity, shard, items, host, extra, one result per item
//! ```
//!
//! CBOR keeps every f64 bit for bit, NaN and infinities included, which is what lets a merge
//! reproduce a single process's figures exactly. A part is read back only whole and intact, and
//! only when it is consistent with itself: its items are its shard's share of its identity's
//! work, and its results are theirs.

use super::identity::{Identity, Work};
use super::split::{MAX_SHARDS, Shard};
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The first bytes of every part: bumped with the bench record's `FORMAT`, which bench parts
/// hold.
const MAGIC: &[u8; 8] = b"RWPART3\n";

/// The magics of earlier raywaves' parts: variance's before the one format, then the one
/// format's with bench records of format 2.
const EARLIER_MAGICS: [&[u8; 8]; 2] = [b"RWPART1\n", b"RWPART2\n"];

/// Bytes before the payload: magic, kind, length, checksum.
const HEADER_LEN: usize = 32;

/// The largest part `read_part` reads: far above any real one (a bench record of 1000 runs is
/// about 1 MiB), low enough that a link to a huge file is refused rather than read.
const MAX_PART_BYTES: u64 = 1 << 30;

/// The machine a shard ran on, and when.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Host {
    /// Host name.
    pub hostname: String,
    /// CPU model.
    pub cpu: String,
    /// Worker threads of the process's pool.
    pub threads: usize,
    /// Start, in seconds since the Unix epoch.
    pub started: f64,
    /// End, in seconds since the Unix epoch.
    pub finished: f64,
}

impl Host {
    /// This machine, starting now on `threads` worker threads.
    pub fn start(threads: usize) -> Host {
        let now = unix_now();
        Host {
            hostname: crate::output::machine::hostname(),
            cpu: crate::output::machine::cpu_model(),
            threads,
            started: now,
            finished: now,
        }
    }

    /// Marks the shard finished now.
    pub fn finish(&mut self) {
        self.finished = unix_now();
    }

    /// Wall-clock seconds from start to end.
    pub fn seconds(&self) -> f64 {
        (self.finished - self.started).max(0.0)
    }
}

/// Seconds since the Unix epoch.
fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// What one shard ran.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(bound(serialize = "W: Work", deserialize = "W: Work"))]
pub struct Part<W: Work> {
    /// The whole run's identity, equal in every shard of it.
    pub identity: Identity<W>,
    /// Which shard this is.
    pub shard: Shard,
    /// The items it ran, ascending: its share of the split of the identity's work.
    pub items: Vec<usize>,
    /// Where and when it ran.
    pub host: Host,
    /// What the work keeps besides its results.
    pub extra: W::Extra,
    /// One result per item, in the order of `items`.
    pub results: Vec<W::Result>,
}

/// The file name of `shard`'s part of work of kind `W`: `KIND-shard-I-of-N.part`.
pub fn part_name<W: Work>(shard: Shard) -> String {
    format!("{}-shard-{}-of-{}.part", W::KIND, shard.index, shard.count)
}

/// Writes `part` to `dir`/[`part_name`] atomically (a temporary file renamed into place),
/// creating `dir`; returns the path.
pub fn write_part<W: Work>(dir: &Path, part: &Part<W>) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let path = dir.join(part_name::<W>(part.shard));
    let mut payload = Vec::new();
    ciborium::into_writer(part, &mut payload).context("cannot encode the part")?;
    crate::output::write_output(&path, |w| {
        w.write_all(MAGIC)?;
        // The kind, NUL-padded to 8 bytes.
        let mut kind = [0u8; 8];
        kind[..W::KIND.len()].copy_from_slice(W::KIND.as_bytes());
        w.write_all(&kind)?;
        w.write_all(&(payload.len() as u64).to_le_bytes())?;
        w.write_all(&crate::render::digest::of(&payload).to_le_bytes())?;
        w.write_all(&payload)?;
        Ok(())
    })?;
    Ok(path)
}

/// Reads and checks the part of kind `W` at `path`; errors name the file and what is wrong.
pub fn read_part<W: Work>(path: &Path) -> Result<Part<W>> {
    let shown = path.display();
    let command = W::COMMAND;
    let what = format!("a part file of `{command}`");
    let bytes = crate::output::read_bounded(path, &what, MAX_PART_BYTES)?;
    // Enough to tell an earlier raywave's parts, the JSON of `{"format": "raywave-bench-shard"`
    // among them, from anything else.
    let head = &bytes[..bytes.len().min(64)];
    let earlier = EARLIER_MAGICS.iter().any(|m| head.starts_with(*m))
        || (head.trim_ascii_start().starts_with(b"{")
            && head.windows(19).any(|w| w == b"raywave-bench-shard"));
    if earlier {
        bail!(
            "{shown}: written by an earlier raywave, in a part format this build does not read; \
             run its shard again with this build"
        );
    }
    if bytes.len() < HEADER_LEN || &bytes[..8] != MAGIC {
        bail!(
            "{shown}: not a raywave part (expected a file written by `{command}`, starting {:?})",
            String::from_utf8_lossy(MAGIC).trim_end()
        );
    }
    let kind = String::from_utf8_lossy(&bytes[8..16])
        .trim_end_matches('\0')
        .to_string();
    if kind != W::KIND {
        bail!(
            "{shown}: a part of `raywave {} --shard`, expected one of `{command}`",
            kind.escape_debug()
        );
    }
    let u64_at = |i: usize| u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap_or_default());
    let (length, sum, payload) = (u64_at(16), u64_at(24), &bytes[HEADER_LEN..]);
    let found = payload.len() as u64;
    if found != length {
        bail!(
            "{shown}: truncated or padded: the header says {length} bytes of results, the file \
             holds {found}; was it cut off mid-write or mid-copy? Run its shard again"
        );
    }
    if crate::render::digest::of(payload) != sum {
        bail!(
            "{shown}: corrupt: its checksum does not match its contents, so it was changed or \
             damaged after it was written; run its shard again"
        );
    }
    let part: Part<W> = ciborium::from_reader(payload)
        .with_context(|| format!("{shown}: its results cannot be decoded"))?;
    if let Some(problem) = inconsistency(&part) {
        bail!("{shown}: inconsistent part: {problem}");
    }
    Ok(part)
}

/// The first way `part` contradicts itself, if any.
fn inconsistency<W: Work>(part: &Part<W>) -> Option<String> {
    let Shard { index, count } = part.shard;
    if count == 0 || index >= count || count > MAX_SHARDS {
        return Some(format!(
            "shard {index}/{count}, expected I < N <= {MAX_SHARDS}"
        ));
    }
    let costs = part.identity.work.costs();
    if costs.is_empty() {
        return Some(format!(
            "a {} of nothing, expected at least one item",
            W::NOUN
        ));
    }
    let expected = part.shard.items(&costs);
    if part.items != expected {
        return Some(format!(
            "it ran items {:?}, but shard {} of this {} is items {expected:?}",
            part.items,
            part.shard,
            W::NOUN
        ));
    }
    if part.results.len() != part.items.len() {
        return Some(format!(
            "{} item(s) and {} result(s), expected one result per item",
            part.items.len(),
            part.results.len()
        ));
    }
    W::check_results(&part.identity, &part.items, &part.results)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shard::toy::{Toy, part};

    fn error(path: &Path) -> String {
        format!("{:#}", read_part::<Toy>(path).unwrap_err())
    }

    #[test]
    fn a_part_reads_back_whole_and_intact_only() {
        let dir = tempfile::tempdir().unwrap();
        let written = part(&[3.0, 2.0, 1.0], 1, 2);
        let path = write_part(dir.path(), &written).unwrap();
        assert_eq!(path, dir.path().join("toy-shard-1-of-2.part"));
        let read = read_part::<Toy>(&path).unwrap();
        assert_eq!((read.items, read.results), (vec![1, 2], vec![1, 4]));
        assert_eq!(
            (read.identity, read.extra),
            (written.identity, written.extra)
        );
        let whole = std::fs::read(&path).unwrap();

        let refused = |bytes: &[u8], needle: &str| {
            std::fs::write(&path, bytes).unwrap();
            let e = error(&path);
            assert!(e.contains(needle), "expected `{needle}` in: {e}");
        };
        refused(&whole[..whole.len() - 1], "truncated or padded");
        refused(&[&whole[..], b"x"].concat(), "truncated or padded");
        let mut flipped = whole.clone();
        let last = flipped.len() - 1;
        flipped[last] ^= 1;
        refused(&flipped, "corrupt: its checksum does not match");
        refused(b"RWPART1\n and the rest", "written by an earlier raywave");
        refused(b"RWPART2\n and the rest", "written by an earlier raywave");
        refused(
            b"{\n  \"format\": \"raywave-bench-shard\",\n  \"version\": 1",
            "written by an earlier raywave",
        );
        refused(b"{\"format\": 2}", "not a raywave part");
        refused(b"RWPART3\n", "not a raywave part");
        let mut other = whole.clone();
        other[8..16].copy_from_slice(b"bench\0\0\0");
        refused(
            &other,
            "a part of `raywave bench --shard`, expected one of `raywave toy",
        );
        assert!(error(dir.path()).contains("found a directory or device"));
    }

    #[test]
    fn a_part_that_contradicts_itself_is_refused_checksum_and_all() {
        let dir = tempfile::tempdir().unwrap();
        // Shard 0 of costs 3, 2, 1 in two is items [0]: a part that claims [0, 2] lies.
        let mut liar = part(&[3.0, 2.0, 1.0], 0, 2);
        liar.items = vec![0, 2];
        liar.results = vec![0, 4];
        let path = write_part(dir.path(), &liar).unwrap();
        let e = error(&path);
        assert!(
            e.contains("inconsistent part") && e.contains("is items [0]"),
            "{e}"
        );
        let mut wrong = part(&[3.0, 2.0, 1.0], 1, 2);
        wrong.results[1] = 5;
        let e = error(&write_part(dir.path(), &wrong).unwrap());
        assert!(e.contains("item 2 has result 5, expected 4"), "{e}");
        let mut short = part(&[3.0, 2.0, 1.0], 1, 2);
        short.results.pop();
        let e = error(&write_part(dir.path(), &short).unwrap());
        assert!(e.contains("2 item(s) and 1 result(s)"), "{e}");
    }
}
