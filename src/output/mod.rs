//! Where a command's outputs go, checked all at once before any work: no output may be an
//! input or another output, and every output's directory must be usable.
//!
//! ```text
//! OutputPlan::new().input("SCENE", scene).output("-o", out).output("--hdr", hdr).check()?
//!   identity of each path: stdout (`-`), or (dev, inode) + canonical path if it exists,
//!                          else canonical parent + name (symlinks followed first)
//!   same identity twice  -> UsageError naming both flags and paths (exit 2)
//!   unusable directory   -> error naming the file and the directory (exit 1)
//! ```
//!
//! `image_file.rs` turns a film into PNG, PPM, PFM or EXR bytes; `write.rs` writes the files
//! (atomically for regular files, directly for devices, FIFOs and stdout; all of a run's at
//! once, at its commit) and removes temporary files on SIGINT/SIGTERM; `memory.rs` estimates a render's peak.

pub mod bench_record;
pub mod build_info;
pub mod cost_map;
pub mod cpu;
pub mod false_colour;
pub mod image_file;
pub mod machine;
pub mod memory;
pub mod render_record;
pub mod terminal;
pub(crate) mod write;

pub use write::{
    Target, commit_outputs, discard_outputs, hold_outputs, install_signal_cleanup, target,
    write_output, write_output_now,
};

use crate::render::error::UsageError;
use anyhow::{Context, Result, bail};
use std::io::Read;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// The path that means standard output (and standard input for a scene).
const STDIO: &str = "-";

/// True when `path` is `-`.
pub fn is_stdio(path: &Path) -> bool {
    path.as_os_str() == STDIO
}

/// Reads back a file the tools wrote (a bench record, a shard's part, a study file), which must
/// be a regular file of at most `max_bytes`: a FIFO would hang the command (refused before it
/// is opened) and a link to /dev/zero would read until memory runs out (the read stops one byte
/// past the limit, whatever the file became since its metadata was read). `what` names the
/// file in the errors ("a bench record"); a missing file's error keeps its `io::Error`.
pub fn read_bounded(path: &Path, what: &str, max_bytes: u64) -> Result<Vec<u8>> {
    let shown = path.display();
    let cannot = || format!("cannot read {what} {shown}");
    let meta = std::fs::metadata(path).with_context(cannot)?;
    if !meta.is_file() {
        bail!("{shown}: expected {what}, found a directory or device");
    }
    let mut bytes = Vec::new();
    if meta.len() <= max_bytes {
        std::fs::File::open(path)
            .with_context(cannot)?
            .take(max_bytes + 1)
            .read_to_end(&mut bytes)
            .with_context(cannot)?;
    }
    let len = meta.len().max(bytes.len() as u64);
    if len > max_bytes {
        bail!(
            "{shown}: {len} bytes, expected {what} of at most {} MiB",
            max_bytes >> 20
        );
    }
    Ok(bytes)
}

/// What a path names, for telling whether two paths are the same file.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Identity {
    /// Device and inode of an existing file (hard links share them).
    dev_ino: Option<(u64, u64)>,
    /// The canonical path, or the canonical parent joined with the name for a new file.
    canonical: PathBuf,
}

impl Identity {
    fn of(path: &Path) -> Identity {
        if is_stdout(path) {
            // Whatever standard output is (a file, a pipe, a terminal).
            return Identity {
                dev_ino: dev_ino("/proc/self/fd/1"),
                canonical: PathBuf::from("<stdout>"),
            };
        }
        let dev_ino = dev_ino(path);
        let canonical = match dev_ino {
            Some(_) => std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
            // A new file, or one a dangling symlink would create.
            None => canonical_new(&write::resolve_symlinks(path)),
        };
        Identity { dev_ino, canonical }
    }

    /// True for `/dev/null` under any name (also standard output sent there).
    fn is_null(&self) -> bool {
        self.canonical == Path::new("/dev/null")
            || (self.dev_ino.is_some() && self.dev_ino == dev_ino("/dev/null"))
    }

    fn same(&self, other: &Identity) -> bool {
        self.canonical == other.canonical
            || matches!((self.dev_ino, other.dev_ino), (Some(a), Some(b)) if a == b)
    }
}

/// Device and inode of the file at `path` (symlinks followed), if it exists.
fn dev_ino(path: impl AsRef<Path>) -> Option<(u64, u64)> {
    let meta = std::fs::metadata(path).ok()?;
    Some((meta.dev(), meta.ino()))
}

/// The canonical form of a path that does not exist yet: its parent canonicalised (when it
/// exists), joined with the name; else the path made absolute.
fn canonical_new(path: &Path) -> PathBuf {
    let parent = write::parent_dir(path);
    let name = path.file_name().map(PathBuf::from).unwrap_or_default();
    match std::fs::canonicalize(parent) {
        Ok(p) => p.join(name),
        Err(_) => std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
    }
}

/// One path as the user gave it, with the flag that gave it.
#[derive(Clone, Debug)]
struct Named {
    flag: String,
    path: PathBuf,
    /// The command creates the directory itself (bench's `--dir`, variance's `--out`).
    creates_dir: bool,
}

impl Named {
    fn new(flag: &str, path: &Path, creates_dir: bool) -> Named {
        Named {
            flag: flag.to_string(),
            path: path.to_path_buf(),
            creates_dir,
        }
    }

    fn describe(&self) -> String {
        if is_stdio(&self.path) {
            format!("{} - (standard output)", self.flag)
        } else {
            format!("{} {}", self.flag, self.path.display())
        }
    }
}

/// A command's inputs and outputs, checked together by [`OutputPlan::check`].
#[derive(Clone, Debug, Default)]
pub struct OutputPlan {
    inputs: Vec<Named>,
    outputs: Vec<Named>,
}

impl OutputPlan {
    /// No inputs, no outputs.
    pub fn new() -> OutputPlan {
        OutputPlan::default()
    }

    /// An input file, named as the user gave it (`flag` is e.g. `SCENE` or `--compare`).
    /// Standard input (`-`) is not a file and is skipped.
    pub fn input(mut self, flag: &str, path: &Path) -> OutputPlan {
        if !is_stdio(path) {
            self.inputs.push(Named::new(flag, path, false));
        }
        self
    }

    /// [`OutputPlan::input`] when the flag was given.
    pub fn input_if(self, flag: &str, path: Option<&Path>) -> OutputPlan {
        path.into_iter().fold(self, |plan, p| plan.input(flag, p))
    }

    /// An output file whose directory must already exist.
    pub fn output(mut self, flag: &str, path: &Path) -> OutputPlan {
        self.outputs.push(Named::new(flag, path, false));
        self
    }

    /// [`OutputPlan::output`] when the flag was given.
    pub fn output_if(self, flag: &str, path: Option<&Path>) -> OutputPlan {
        path.into_iter().fold(self, |plan, p| plan.output(flag, p))
    }

    /// An output file in a directory the command creates if it is missing.
    pub fn output_in_new_dir(mut self, flag: &str, path: &Path) -> OutputPlan {
        self.outputs.push(Named::new(flag, path, true));
        self
    }

    /// True when some output is standard output (text meant for the terminal must then go to
    /// standard error).
    pub fn uses_stdout(&self) -> bool {
        self.outputs.iter().any(|o| is_stdout(&o.path))
    }

    /// Refuses binary output (`flag -`) to standard output when that is a terminal: the
    /// bytes would only garble it.
    pub fn refuse_binary_on_terminal(&self, flags: &[&str]) -> Result<()> {
        use std::io::IsTerminal;
        if let Some(o) = self
            .outputs
            .iter()
            .find(|o| is_stdout(&o.path) && flags.contains(&o.flag.as_str()))
            && std::io::stdout().is_terminal()
        {
            bail!(UsageError(format!(
                "{} would write an image to the terminal: expected standard output redirected to a file or a pipe",
                o.describe()
            )));
        }
        Ok(())
    }

    /// Refuses an output that is one of the files `scene` read besides itself: its textures,
    /// which are known only once it is parsed (the plan's other checks come before the parse).
    /// `label` names the scene as the user gave it (`SCENE`, `--scene`).
    pub fn check_scene_files(
        &self,
        label: &str,
        scene: &crate::render::scene::Scene,
    ) -> Result<()> {
        let plan = scene.textures.iter().fold(
            OutputPlan {
                inputs: Vec::new(),
                outputs: self.outputs.clone(),
            },
            |plan, t| plan.input(&format!("{label}'s texture_file"), &t.path),
        );
        plan.check_against_inputs()
    }

    /// Refuses an output that is an input or another output (a [`UsageError`]), then an
    /// output whose directory is missing, not a directory or not writable, or an output that
    /// is a directory (a plain error: the flags are valid, the file system is not ready).
    pub fn check(&self) -> Result<()> {
        self.check_against_inputs()?;
        for out in &self.outputs {
            check_writable(out)?;
        }
        Ok(())
    }

    /// The first half of [`OutputPlan::check`]: no output is an input or another output.
    fn check_against_inputs(&self) -> Result<()> {
        fn identities(named: &[Named]) -> Vec<(&Named, Identity)> {
            named.iter().map(|n| (n, Identity::of(&n.path))).collect()
        }
        let (inputs, outputs) = (identities(&self.inputs), identities(&self.outputs));
        for (i, (out, id)) in outputs.iter().enumerate() {
            for (input, input_id) in &inputs {
                if id.same(input_id) {
                    bail!(UsageError(format!(
                        "{} is the same file as the input {}: expected an output that is not an input (it would be overwritten)",
                        out.describe(),
                        input.describe()
                    )));
                }
            }
            for (other, other_id) in &outputs[..i] {
                // Any number of outputs may be thrown away.
                if id.same(other_id) && !id.is_null() {
                    bail!(UsageError(format!(
                        "{} and {} are the same file: expected a different file for each output",
                        other.describe(),
                        out.describe()
                    )));
                }
            }
        }
        Ok(())
    }
}

/// `-`, or standard output under another name: `/dev/stdout`, `/dev/fd/1`, `/proc/self/fd/1`.
pub(crate) fn is_stdout(path: &Path) -> bool {
    is_stdio(path)
        || ["/dev/stdout", "/dev/fd/1", "/proc/self/fd/1"]
            .iter()
            .any(|p| path == Path::new(p))
}

/// Checks that the output can be written: not a directory, in a directory that exists (or
/// that the command creates) and that this process may write in.
fn check_writable(out: &Named) -> Result<()> {
    let path = &out.path;
    let Target::Regular(real) = target(path) else {
        return Ok(());
    };
    let problem = if let Err(e) = std::fs::metadata(path)
        && e.raw_os_error() == Some(libc::ELOOP)
    {
        "its symlinks form a loop, expected a file or a symlink to one".to_string()
    } else if real.is_dir() {
        "it is a directory, expected a file".to_string()
    } else {
        let mut dir = write::parent_dir(&real).to_path_buf();
        if out.creates_dir {
            // The nearest existing ancestor is where the new directories will be made.
            while !dir.exists() {
                dir = write::parent_dir(&dir).to_path_buf();
            }
        }
        if !dir.exists() {
            format!("directory {} does not exist", dir.display())
        } else if !dir.is_dir() {
            format!("{} is not a directory", dir.display())
        } else if !write::may_write_in(&dir) {
            format!("no permission to create files in {}", dir.display())
        } else {
            return Ok(());
        }
    };
    bail!("cannot write {}: {problem}", path.display())
}
