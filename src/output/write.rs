//! Writing outputs, each whole or not at all, and all of a run's together or none.
//!
//! - A regular file (or a new one, or a symlink to either) is written to a temporary file
//!   beside the real target, then renamed over it: the symlink stays a symlink.
//! - Standard output (`-`), devices (`/dev/null`, `/dev/full`) and FIFOs are written directly:
//!   renaming over them would replace a device node or a pipe with a plain file. Write errors
//!   (ENOSPC on `/dev/full`, a closed pipe) are reported with the file's name.
//! - After [`hold_outputs`] (the `raywave` binary calls it first thing), nothing reaches its
//!   target until [`commit_outputs`]: each regular output waits in its temporary file, each
//!   direct one in an unnamed temporary file, so a run that fails before the commit changes no
//!   output ([`discard_outputs`] removes what was held). The commit first copies the direct
//!   outputs (where ENOSPC and closed pipes show), then renames the regular ones, under the
//!   lock the signal handler takes, so a signal during the renames waits for them.
//! - Temporary files are registered while they exist; on SIGINT or SIGTERM the handler from
//!   [`install_signal_cleanup`] removes them and exits 130 or 143, so no temporary file survives
//!   an interruption and the old output stays as it was.
//!
//! ```text
//! write_output(path)  regular -> temp beside it -> held ? queue (temp, real) : rename now
//!                     direct  -> held ? unnamed temp file, queued : write now
//! commit_outputs()    copy each queued direct output; any error -> remove every temp, fail
//!                     rename each temp over its target; an error -> name what was and was
//!                     not replaced, remove the rest, fail
//! ```

use anyhow::{Context, Result, bail};
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// What writes an output: it fills the buffered file it is given, whatever file that is.
pub trait Fill: FnOnce(&mut BufWriter<&mut File>) -> Result<()> {}

impl<F: FnOnce(&mut BufWriter<&mut File>) -> Result<()>> Fill for F {}

/// A regular output written in full to its temporary file, renamed over `real` at the commit.
struct HeldRename {
    tmp: tempfile::NamedTempFile,
    real: PathBuf,
    /// The path as the user gave it, for messages.
    shown: PathBuf,
}

/// A device's, FIFO's or standard output's bytes, copied to it at the commit.
struct HeldDirect {
    bytes: File,
    shown: PathBuf,
}

/// What the process's outputs are doing now.
#[derive(Default)]
struct Outputs {
    /// Temporary files that exist now, removed by the signal handler.
    temporaries: Vec<PathBuf>,
    /// Outputs wait for [`commit_outputs`] (set by [`hold_outputs`]).
    holding: bool,
    /// The regular outputs waiting, in the order they were written.
    renames: Vec<HeldRename>,
    /// The direct outputs waiting, in the order they were written.
    direct: Vec<HeldDirect>,
}

static OUTPUTS: Mutex<Outputs> = Mutex::new(Outputs {
    temporaries: Vec::new(),
    holding: false,
    renames: Vec::new(),
    direct: Vec::new(),
});

fn outputs() -> std::sync::MutexGuard<'static, Outputs> {
    OUTPUTS.lock().unwrap_or_else(|e| e.into_inner())
}

impl Outputs {
    /// Forgets a temporary file that is renamed or dropped.
    fn unregister(&mut self, tmp: &Path) {
        self.temporaries.retain(|p| p != tmp);
    }

    /// Renames a finished temporary file over `real`, and forgets it (on failure it is removed
    /// when the error is dropped).
    fn persist(
        &mut self,
        tmp: tempfile::NamedTempFile,
        real: &Path,
    ) -> Result<(), tempfile::PersistError> {
        let tmp_path = tmp.path().to_path_buf();
        let persisted = tmp.persist(real);
        self.unregister(&tmp_path);
        persisted.map(drop)
    }

    /// Drops the regular outputs in `renames` (their temporary files are removed) and returns
    /// the paths they would have replaced.
    fn drop_renames(&mut self, renames: impl IntoIterator<Item = HeldRename>) -> Vec<String> {
        renames
            .into_iter()
            .map(|held| {
                self.unregister(held.tmp.path());
                held.shown.display().to_string()
            })
            .collect()
    }
}

/// From now on, outputs are written in full but reach their targets only at
/// [`commit_outputs`]: a run that fails first changes none of them.
pub fn hold_outputs() {
    outputs().holding = true;
}

/// Puts every held output in place: the direct ones first, then the renames. Outputs written
/// after this are held again (the process stays in holding mode).
pub fn commit_outputs() -> Result<()> {
    let (direct, renames) = {
        let mut state = outputs();
        (
            std::mem::take(&mut state.direct),
            std::mem::take(&mut state.renames),
        )
    };
    // Without the lock: a FIFO may wait for its reader, and the signal handler must still be
    // able to remove the held temporary files meanwhile.
    let copied = direct.into_iter().try_for_each(|mut held| {
        held.bytes.rewind()?;
        write_output_now(&held.shown, |w| {
            Ok(std::io::copy(&mut held.bytes, w).map(drop)?)
        })
    });
    let mut state = outputs();
    if let Err(e) = copied {
        state.drop_renames(renames);
        return Err(e.context("no file output was changed"));
    }
    let mut replaced = Vec::new();
    let mut renames = renames.into_iter();
    while let Some(HeldRename { tmp, real, shown }) = renames.next() {
        if let Err(e) = state.persist(tmp, &real) {
            let kept = std::iter::once(shown.display().to_string())
                .chain(state.drop_renames(renames))
                .collect::<Vec<_>>()
                .join(", ");
            let replaced = if replaced.is_empty() {
                "none".to_string()
            } else {
                replaced.join(", ")
            };
            bail!(
                "cannot move the finished file to {}: {}; outputs replaced: {replaced}; left as they were: {kept}",
                shown.display(),
                e.error,
            );
        }
        replaced.push(shown.display().to_string());
    }
    Ok(())
}

/// Drops every held output: their temporary files are removed, their targets left as they
/// were.
pub fn discard_outputs() {
    let mut state = outputs();
    state.direct.clear();
    let renames = std::mem::take(&mut state.renames);
    state.drop_renames(renames);
}

/// What writing to a path means.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// `-`: this process's standard output.
    Stdout,
    /// An existing device, FIFO or socket (symlinks followed): written directly.
    Special(PathBuf),
    /// A regular file, existing or not (symlinks followed): the path to rename over.
    Regular(PathBuf),
}

impl Target {
    /// True for targets that cannot seek (stdout, FIFOs): formats that seek back (EXR) must
    /// be encoded in memory first.
    pub fn is_stream(&self) -> bool {
        match self {
            Target::Stdout => true,
            Target::Special(p) => std::fs::metadata(p)
                .map(|m| m.file_type().is_fifo() || m.file_type().is_socket())
                .unwrap_or(true),
            Target::Regular(_) => false,
        }
    }
}

/// Classifies `path`, following symlinks (also dangling ones, to the file they would create).
/// `/dev/stdout` and its aliases are standard output itself, so that its offset is shared and
/// a pipe behind it (`/proc/self/fd/1 -> pipe:[N]`) is written, not looked up as a path.
pub fn target(path: &Path) -> Target {
    if super::is_stdout(path) {
        return Target::Stdout;
    }
    // The kernel follows the links (also /proc's magic ones) to what is really there.
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => Target::Special(path.to_path_buf()),
        _ => Target::Regular(resolve_symlinks(path)),
    }
}

/// Follows a chain of symlinks (at most 40, like the kernel) to the path it ends at, whether
/// or not that exists.
pub(crate) fn resolve_symlinks(path: &Path) -> PathBuf {
    let mut at = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::read_link(&at) {
            Ok(next) => at = parent_dir(&at).join(next),
            Err(_) => break,
        }
    }
    at
}

/// The directory a path's file is in (`.` for a bare name).
pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// True when this process may create files in `dir` (`access(2)` with W_OK and X_OK).
pub(crate) fn may_write_in(dir: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(c) = std::ffi::CString::new(dir.as_os_str().as_bytes()) else {
        return false;
    };
    // SAFETY: a valid NUL-terminated path; access reads it and keeps nothing.
    unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) == 0 }
}

/// Writes through `fill`: atomically to a regular target, directly to anything else; held
/// until [`commit_outputs`] after [`hold_outputs`].
pub fn write_output(path: &Path, fill: impl Fill) -> Result<()> {
    if !outputs().holding {
        return write_output_now(path, fill);
    }
    match target(path) {
        Target::Regular(real) => {
            let tmp = write_temporary(path, &real, fill)?;
            outputs().renames.push(HeldRename {
                tmp,
                real,
                shown: path.to_path_buf(),
            });
        }
        Target::Stdout | Target::Special(_) => {
            let mut bytes =
                tempfile::tempfile().context("cannot create a temporary file to hold an output")?;
            write_direct(&mut bytes, &path.display().to_string(), fill)?;
            outputs().direct.push(HeldDirect {
                bytes,
                shown: path.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Writes through `fill` at once, held or not: for files the run reads back (the variance
/// study's cache), which are not outputs to commit together.
pub fn write_output_now(path: &Path, fill: impl Fill) -> Result<()> {
    match target(path) {
        Target::Stdout => {
            use std::os::fd::AsFd;
            let fd = std::io::stdout()
                .as_fd()
                .try_clone_to_owned()
                .context("cannot write to standard output")?;
            write_direct(&mut File::from(fd), "standard output", fill)
        }
        Target::Special(special) => {
            let mut file = open_special(&special)
                .with_context(|| format!("cannot open {} for writing", path.display()))?;
            write_direct(&mut file, &path.display().to_string(), fill)
        }
        Target::Regular(real) => {
            let tmp = write_temporary(path, &real, fill)?;
            // Renamed under the lock: a signal now waits for the rename, and finds nothing to
            // remove.
            outputs()
                .persist(tmp, &real)
                .with_context(|| format!("cannot move the finished file to {}", path.display()))
        }
    }
}

/// Opens a device or FIFO for writing, without truncation (there are no contents to replace).
/// A FIFO without a reader blocks, as for any writer; a note on stderr says what it waits for.
fn open_special(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    let is_fifo = std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo());
    if is_fifo {
        // O_NONBLOCK fails with ENXIO exactly when no process has the FIFO open for reading.
        let probe = std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(path);
        match probe {
            // Kept, not reopened: closing a writer could hand the reader an early EOF.
            Ok(file) => {
                use std::os::fd::AsRawFd;
                let fd = file.as_raw_fd();
                // SAFETY: fcntl on a file descriptor this function owns.
                let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
                // SAFETY: as above; clears O_NONBLOCK so that writes wait for the reader.
                let set = unsafe { libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) };
                if flags < 0 || set < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                return Ok(file);
            }
            Err(e) if e.raw_os_error() == Some(libc::ENXIO) => {
                eprintln!("note: waiting for a reader on the FIFO {}", path.display())
            }
            Err(_) => {}
        }
    }
    std::fs::OpenOptions::new().write(true).open(path)
}

/// Fills `file` through `fill` and flushes it; errors name the file as `name`.
fn write_direct(file: &mut File, name: &str, fill: impl Fill) -> Result<()> {
    let mut w = BufWriter::new(file);
    fill(&mut w).with_context(|| format!("cannot write {name}"))?;
    w.flush().with_context(|| format!("cannot write {name}"))?;
    Ok(())
}

/// The temporary file beside `real`, filled through `fill`, flushed, with the mode of the
/// file it replaces; registered for the signal handler until it is renamed or dropped.
fn write_temporary(path: &Path, real: &Path, fill: impl Fill) -> Result<tempfile::NamedTempFile> {
    let dir = parent_dir(real);
    // Created and registered under the lock, so that the signal handler sees every
    // temporary file that exists.
    let mut tmp = {
        let mut state = outputs();
        let tmp = tempfile::Builder::new()
            .prefix(".raywave-")
            .tempfile_in(dir)
            .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
        state.temporaries.push(tmp.path().to_path_buf());
        tmp
    };
    let result =
        write_direct(tmp.as_file_mut(), &path.display().to_string(), fill).and_then(|()| {
            // Temporary files are created private (0600); an image is not a secret. Keep the mode
            // of the file being replaced, or use the usual 0644 for a new one.
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(real)
                .map(|m| m.permissions().mode())
                .unwrap_or(0o644);
            tmp.as_file()
                .set_permissions(std::fs::Permissions::from_mode(mode))
                .with_context(|| format!("cannot set the permissions of {}", path.display()))
        });
    if let Err(e) = result {
        let tmp_path = tmp.path().to_path_buf();
        let mut state = outputs();
        drop(tmp);
        state.unregister(&tmp_path);
        return Err(e);
    }
    Ok(tmp)
}

/// Installs the SIGINT/SIGTERM handler: it removes every registered temporary file and exits
/// with 130 (SIGINT) or 143 (SIGTERM), the shell's 128 + signal number.
pub fn install_signal_cleanup() -> Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])
        .context("cannot install the signal handler")?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let state = outputs();
                for p in &state.temporaries {
                    let _ = std::fs::remove_file(p);
                }
                let name = if signal == SIGINT { "SIGINT" } else { "SIGTERM" };
                eprintln!(
                    "\nerror: stopped by {name}; {} unfinished temporary file(s) removed, the file being written left as it was",
                    state.temporaries.len()
                );
                // _exit: no destructors, no flushing of locks another thread may hold.
                // SAFETY: _exit ends the process; nothing runs after it.
                unsafe { libc::_exit(128 + signal) };
            }
        })
        .context("cannot start the signal thread")?;
    Ok(())
}
