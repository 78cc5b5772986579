//! The cache of converged references (`.raywave-cache/` by default): one file per scene and
//! settings, checked on every read, written whole or not at all, bounded in size.
//!
//! ```text
//! entry  reference-KEY.rwref        KEY = FNV-1a(format, scene bytes, settings, executable)
//! magic    8 bytes  "RWREF01\n"
//! format   u32 LE   CACHE_FORMAT
//! width    u32 LE
//! height   u32 LE
//! key      u64 LE   the KEY of the name (a copied or renamed entry is not used for another key)
//! fnv      u64 LE   FNV-1a of the payload
//! payload  2 × width × height × 3 f32 LE: half A then half B, rows from the top
//! ```
//!
//! Shards of one study on several machines share the cache on a shared filesystem. An entry is
//! rendered under an exclusive lock on its own `reference-KEY.lock` (`flock`, which NFS v4 and
//! Lustre honour, and removed by its holder before unlocking), so that the first shard to need
//! it renders it while the others wait and then read it; a reader never sees half an entry,
//! since an entry is written to a temporary file and renamed into place.
//!
//! Anything else found at an entry's path (short, long, another magic or format, other
//! dimensions, a checksum that does not match, a value that is not finite, a directory, a FIFO,
//! an unreadable file) is reported in one warning line naming the file and what was wrong, and
//! the reference is rendered again. The least recently used entries are removed once the
//! entries together exceed the size limit.

use crate::render::digest;
use crate::render::film::Film;
use crate::render::settings::RenderSettings;
use anyhow::{Context, Result, bail};
use glam::Vec3;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// Bumped when the entry layout or the meaning of its key changes.
const CACHE_FORMAT: u32 = 1;

/// The first bytes of every entry.
pub const MAGIC: &[u8; 8] = b"RWREF01\n";

/// Bytes before the payload.
pub const HEADER_LEN: u64 = 36;

/// Default bound on the entries' total size, in MiB (a 128×128 reference takes 0.4 MiB, a
/// 1024×1024 one 24 MiB).
pub const DEFAULT_LIMIT_MIB: u64 = 512;

/// Halves of a converged reference (two independent renders).
const HALVES: u64 = 2;

/// A cache directory and its size bound.
#[derive(Clone, Debug)]
pub struct Cache {
    /// Where the entries live.
    pub dir: PathBuf,
    /// The entries' total size above which the least recently used are removed.
    pub limit_bytes: u64,
}

/// An entry's lock, held until dropped (see [`Cache::lock`]).
pub struct EntryLock {
    file: std::fs::File,
    path: PathBuf,
}

impl Drop for EntryLock {
    fn drop(&mut self) {
        // Removed while still locked: a process waiting on this file finds its path gone (or
        // a new file there) when it wakes, and locks the path again.
        let _ = std::fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

/// Whether `path` still names the open `file` (the same device and inode).
#[cfg(unix)]
fn same_file(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &std::fs::File, path: &Path) -> bool {
    path.exists()
}

/// What a lookup found.
#[derive(Debug)]
pub enum Lookup {
    /// A valid entry: the two halves.
    Hit([Film; 2]),
    /// No entry.
    Miss,
    /// Something that is not a valid entry, and what is wrong with it.
    Invalid(String),
}

/// The key of a reference: the cache format, the scene bytes that were parsed, every setting
/// of the two renders and the running executable's bytes (so new renderer code makes a new
/// entry; where the executable cannot be read, the version stands in for it). Each part is
/// length-prefixed so that no two different inputs run together into the same bytes.
pub fn key(scene_bytes: &[u8], settings: &[RenderSettings]) -> u64 {
    let json = serde_json::to_vec(settings).unwrap_or_default();
    let code = std::env::current_exe()
        .and_then(std::fs::read)
        .unwrap_or_else(|_| env!("CARGO_PKG_VERSION").as_bytes().to_vec());
    let mut h = digest::of(&CACHE_FORMAT.to_le_bytes());
    for part in [scene_bytes, &json, &code] {
        h = digest::continued(h, &(part.len() as u64).to_le_bytes());
        h = digest::continued(h, part);
    }
    h
}

/// Whether a file name is one of the cache's entries (or of its earlier PFM layout).
fn is_entry_name(name: &str) -> bool {
    name.starts_with("reference-") && (name.ends_with(".rwref") || name.ends_with(".pfm"))
}

impl Cache {
    /// A cache in `dir` bounded to `limit_mib` MiB.
    pub fn new(dir: &Path, limit_mib: u64) -> Cache {
        Cache {
            dir: dir.to_path_buf(),
            limit_bytes: limit_mib.saturating_mul(1 << 20),
        }
    }

    /// The file of `key`.
    pub fn entry_path(&self, key: u64) -> PathBuf {
        self.dir.join(format!("reference-{key:016x}.rwref"))
    }

    /// Takes the exclusive lock on `key`'s entry, held until the returned guard is dropped;
    /// calls `waiting` first when another process holds it, then blocks until it is released.
    /// An error means the filesystem cannot lock (the caller goes on without the lock). The lock
    /// file lives only while held, so a process that wakes holding the lock on a removed file
    /// (its path now names a new file, or none) lets it go and locks the path again.
    pub fn lock(&self, key: u64, waiting: impl FnOnce(&Path)) -> Result<EntryLock> {
        let path = self.entry_path(key).with_extension("lock");
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create {}", self.dir.display()))?;
        let mut waiting = Some(waiting);
        loop {
            let file = std::fs::File::options()
                .create(true)
                .truncate(false)
                .write(true)
                .open(&path)
                .with_context(|| format!("cannot open the lock file {}", path.display()))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    if let Some(w) = waiting.take() {
                        w(&path);
                    }
                    file.lock()
                        .with_context(|| format!("cannot lock {}", path.display()))?;
                }
                Err(std::fs::TryLockError::Error(e)) => {
                    return Err(e).with_context(|| format!("cannot lock {}", path.display()));
                }
            }
            if same_file(&file, &path) {
                return Ok(EntryLock { file, path });
            }
        }
    }

    /// Reads and checks the entry of `key`, expected to be `width × height`.
    pub fn read(&self, key: u64, width: u32, height: u32) -> Lookup {
        let path = self.entry_path(key);
        match std::fs::metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Lookup::Miss,
            Err(e) => Lookup::Invalid(format!("cannot read it ({e})")),
            Ok(meta) if !meta.is_file() => {
                Lookup::Invalid("expected a regular file, found a directory or device".into())
            }
            Ok(meta) => match read_entry(&path, meta.len(), key, width, height) {
                Ok(films) => {
                    // The modification time is the last use, for the size bound.
                    if let Ok(f) = std::fs::File::options().append(true).open(&path) {
                        let _ = f.set_modified(std::time::SystemTime::now());
                    }
                    Lookup::Hit(films)
                }
                Err(what) => Lookup::Invalid(what),
            },
        }
    }

    /// Writes the entry of `key` atomically, then removes the least recently used entries
    /// above the size bound. Refuses films with values that are not finite.
    pub fn write(&self, key: u64, films: &[Film; 2]) -> Result<()> {
        let path = self.entry_path(key);
        let (width, height) = (films[0].width, films[0].height);
        if films[1].width != width || films[1].height != height {
            bail!("the two halves differ in size");
        }
        let bad: usize = films.iter().map(Film::non_finite_pixels).sum();
        if bad > 0 {
            bail!("{bad} pixels are not finite: not cached");
        }
        let size = HEADER_LEN + payload_len(width, height);
        if size > self.limit_bytes {
            bail!(
                "the entry would take {:.1} MiB, above the cache limit of {} MiB: not cached",
                size as f64 / (1u64 << 20) as f64,
                self.limit_bytes >> 20
            );
        }
        // Only a regular file of ours is replaced: anything else in an entry's place (a FIFO, a
        // device, a directory, a symlink) is left alone, and written through by nobody.
        if let Ok(meta) = std::fs::symlink_metadata(&path)
            && !meta.is_file()
        {
            bail!(
                "{} is not a regular file: left alone, not cached",
                path.display()
            );
        }
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create {}", self.dir.display()))?;
        let pixels = films.iter().flat_map(|f| &f.pixels);
        let payload: Vec<u8> = pixels
            .flat_map(|c| c.to_array().map(f32::to_le_bytes))
            .flatten()
            .collect();
        // At once, not held for the run's commit: the study reads its references back, and
        // a reference rendered is worth keeping even if the study then fails.
        crate::output::write_output_now(&path, |w| {
            w.write_all(MAGIC)?;
            for v in [CACHE_FORMAT, width, height] {
                w.write_all(&v.to_le_bytes())?;
            }
            w.write_all(&key.to_le_bytes())?;
            w.write_all(&digest::of(&payload).to_le_bytes())?;
            w.write_all(&payload)?;
            Ok(())
        })?;
        self.evict(&path);
        Ok(())
    }

    /// Removes the least recently used entries (never `keep`) until the entries together fit
    /// the bound.
    fn evict(&self, keep: &Path) {
        let mut entries = entries(&self.dir);
        // The entry just written first, then the others from the most recently used.
        entries.sort_by_key(|e| (e.0 != keep, std::cmp::Reverse(e.2)));
        let mut total = 0u64;
        for (path, len, _) in entries {
            total += len;
            if total > self.limit_bytes && path != keep {
                let _ = std::fs::remove_file(&path);
                total -= len;
            }
        }
    }
}

/// The cache's entries in `dir`: path, size, last use.
fn entries(dir: &Path) -> Vec<(PathBuf, u64, std::time::SystemTime)> {
    let Ok(list) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    list.filter_map(|e| e.ok())
        .filter(|e| is_entry_name(&e.file_name().to_string_lossy()))
        .filter_map(|e| {
            let meta = std::fs::symlink_metadata(e.path()).ok()?;
            let used = meta.modified().ok()?;
            meta.is_file().then(|| (e.path(), meta.len(), used))
        })
        .collect()
}

/// Removes every cache entry (and the earlier layout's PFM files) from `dir`, leaving any
/// other file alone; returns how many files and bytes were removed.
pub fn clean(dir: &Path) -> Result<(usize, u64)> {
    if !dir.exists() {
        return Ok((0, 0));
    }
    if !dir.is_dir() {
        bail!(
            "cannot clean the cache {}: expected a directory, found a file",
            dir.display()
        );
    }
    let mut removed = (0, 0);
    for (path, len, _) in entries(dir) {
        std::fs::remove_file(&path).with_context(|| format!("cannot remove {}", path.display()))?;
        removed.0 += 1;
        removed.1 += len;
    }
    Ok(removed)
}

fn payload_len(width: u32, height: u32) -> u64 {
    HALVES * u64::from(width) * u64::from(height) * 12
}

/// Reads the entry at `path` (`len` bytes) and checks it against `key` and the size wanted.
fn read_entry(
    path: &Path,
    len: u64,
    key: u64,
    width: u32,
    height: u32,
) -> std::result::Result<[Film; 2], String> {
    if len < HEADER_LEN {
        return Err(format!(
            "{len} bytes, shorter than the {HEADER_LEN}-byte header"
        ));
    }
    let mut file = std::fs::File::open(path).map_err(|e| format!("cannot read it ({e})"))?;
    let mut header = [0u8; HEADER_LEN as usize];
    file.read_exact(&mut header)
        .map_err(|e| format!("cannot read its header ({e})"))?;
    let u32_at = |i: usize| u32::from_le_bytes(header[i..i + 4].try_into().unwrap_or_default());
    let u64_at = |i: usize| u64::from_le_bytes(header[i..i + 8].try_into().unwrap_or_default());
    let (format, w, h, made_for) = (u32_at(8), u32_at(12), u32_at(16), u64_at(20));
    if &header[..8] != MAGIC {
        return Err("not a raywave reference (wrong magic bytes)".into());
    }
    if format != CACHE_FORMAT {
        return Err(format!("cache format {format}, expected {CACHE_FORMAT}"));
    }
    if (w, h) != (width, height) {
        return Err(format!("{w}×{h} pixels, expected {width}×{height}"));
    }
    if made_for != key {
        return Err(format!("made for key {made_for:016x}, expected {key:016x}"));
    }
    let expected = HEADER_LEN + payload_len(width, height);
    if len != expected {
        return Err(format!(
            "{len} bytes, expected {expected} for a {width}×{height} reference"
        ));
    }
    let mut payload = Vec::new();
    file.take(expected - HEADER_LEN)
        .read_to_end(&mut payload)
        .map_err(|e| format!("cannot read it ({e})"))?;
    if payload.len() as u64 != expected - HEADER_LEN {
        return Err("it shrank while being read".into());
    }
    if digest::of(&payload) != u64_at(28) {
        return Err("checksum mismatch: the pixels are not the ones written".into());
    }
    let values: Vec<f32> = payload
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let bad = values.iter().filter(|x| !x.is_finite()).count();
    if bad > 0 {
        return Err(format!("{bad} values are not finite"));
    }
    let film = |half: &[f32]| Film {
        width,
        height,
        pixels: half.chunks_exact(3).map(Vec3::from_slice).collect(),
    };
    let (a, b) = values.split_at(values.len() / 2);
    Ok([film(a), film(b)])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn films() -> [Film; 2] {
        let mut a = Film::new(3, 2);
        let mut b = Film::new(3, 2);
        for (i, (x, y)) in a.pixels.iter_mut().zip(&mut b.pixels).enumerate() {
            *x = Vec3::splat(i as f32);
            *y = Vec3::new(1.0, i as f32 * 0.5, -2.0);
        }
        [a, b]
    }

    #[test]
    fn the_key_follows_the_scene_bytes_and_every_setting() {
        let s = RenderSettings::preview();
        let k = key(b"v 0 0 0\n", std::slice::from_ref(&s));
        assert_eq!(k, key(b"v 0 0 0\n", std::slice::from_ref(&s)));
        assert_ne!(k, key(b"v 0 0 1\n", std::slice::from_ref(&s)));
        let other = RenderSettings {
            seed: s.seed + 1,
            ..s.clone()
        };
        assert_ne!(k, key(b"v 0 0 0\n", &[other]));
        assert_ne!(k, key(b"v 0 0 0\n", &[s.clone(), s]));
    }

    #[test]
    fn round_trip_and_checks() {
        let dir = tempfile::tempdir().unwrap();
        let cache = Cache::new(dir.path(), 1);
        assert!(matches!(cache.read(7, 3, 2), Lookup::Miss));
        cache.write(7, &films()).unwrap();
        match cache.read(7, 3, 2) {
            Lookup::Hit(f) => assert_eq!(f, films()),
            other => panic!("{other:?}"),
        }
        let what = |l: Lookup| match l {
            Lookup::Invalid(w) => w,
            other => panic!("{other:?}"),
        };
        assert!(what(cache.read(7, 2, 3)).contains("3×2 pixels, expected 2×3"));
        let path = cache.entry_path(7);
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[40] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert!(what(cache.read(7, 3, 2)).contains("checksum mismatch"));
        std::fs::copy(&path, cache.entry_path(8)).unwrap();
        assert!(what(cache.read(8, 3, 2)).contains("made for key"));
    }

    #[test]
    fn non_finite_films_are_not_cached_and_old_entries_are_evicted() {
        let dir = tempfile::tempdir().unwrap();
        // Room for one 3×2 entry (36 + 144 bytes) and not two.
        let cache = Cache {
            dir: dir.path().to_path_buf(),
            limit_bytes: 300,
        };
        let mut nan = films();
        nan[1].pixels[0].y = f32::NAN;
        assert!(cache.write(1, &nan).is_err());
        assert!(!cache.entry_path(1).exists());
        cache.write(2, &films()).unwrap();
        cache.write(3, &films()).unwrap();
        assert!(!cache.entry_path(2).exists());
        assert!(cache.entry_path(3).exists());
        std::fs::write(dir.path().join("notes.txt"), "mine").unwrap();
        assert_eq!(clean(dir.path()).unwrap(), (1, 180));
        assert!(dir.path().join("notes.txt").exists());
    }
}
