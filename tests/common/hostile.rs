//! The harness of the hostile-input catalogue: one [`Case`] per thing a hostile or careless
//! user can do, run in a scratch directory of its own, checked for everything raywave promises
//! on bad input (docs/RELIABILITY.md):
//!
//! - the exit code the case names (2 usage, 1 failure, 3 regression, 0 success);
//! - every fragment the case names appears in standard error;
//! - no panic (exit 101 or "panicked at" in stderr) and no hang (killed after the timeout);
//! - nothing in the scratch directory changed or appeared except the outputs the case names
//!   (a checksum of every file before and after; symlinks and FIFOs by kind and target), so a
//!   destroyed input, a half-written output or a leftover temporary file fails the case.
//!
//! Cases are plain data so that one test can hold a table of them and report every failure at
//! once, not only the first.

use std::collections::BTreeMap;
use std::io::Write;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How long a case may run before it counts as a hang.
pub const TIMEOUT: Duration = Duration::from_secs(20);

/// One hostile run.
pub struct Case {
    /// What the case does, as the failure report names it.
    pub name: &'static str,
    /// Puts the case's files in the scratch directory (scenes, FIFOs, symlinks, records, ...).
    pub setup: fn(&Path),
    /// The arguments, relative to the scratch directory (`{dir}` is replaced by its path).
    pub args: &'static [&'static str],
    /// Bytes fed to standard input (closed when `None`).
    pub stdin: Option<&'static [u8]>,
    /// The exit code expected.
    pub exit: i32,
    /// Fragments that standard error must contain.
    pub stderr: &'static [&'static str],
    /// Files (relative to the scratch directory) the run may create or change.
    pub outputs: &'static [&'static str],
}

/// A file's identity for the before/after comparison.
#[derive(Debug, PartialEq, Eq)]
enum Entry {
    File { len: u64, sum: u64, inode: u64 },
    Symlink(PathBuf),
    Fifo,
    Dir,
    Other,
}

/// FNV-1a over the bytes: enough to tell a changed file from an unchanged one.
fn checksum(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Every entry under `dir` (recursively, not following symlinks), by relative path.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Entry> {
    let mut out = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let path = e.unwrap().path();
            let meta = std::fs::symlink_metadata(&path).unwrap();
            let kind = meta.file_type();
            let entry = if kind.is_symlink() {
                Entry::Symlink(std::fs::read_link(&path).unwrap())
            } else if kind.is_fifo() {
                Entry::Fifo
            } else if kind.is_dir() {
                todo.push(path.clone());
                Entry::Dir
            } else if kind.is_file() {
                Entry::File {
                    len: meta.len(),
                    sum: checksum(&std::fs::read(&path).unwrap()),
                    inode: meta.ino(),
                }
            } else {
                Entry::Other
            };
            out.insert(path.strip_prefix(dir).unwrap().to_path_buf(), entry);
        }
    }
    out
}

/// The result of one run: exit code (`None` when killed by a signal), stderr, and whether it
/// had to be killed.
pub struct Run {
    /// The exit code, `None` when a signal ended it.
    pub code: Option<i32>,
    /// Standard output, lossily decoded.
    pub stdout: String,
    /// Standard error, lossily decoded.
    pub stderr: String,
    /// True when the timeout killed it.
    pub hung: bool,
}

/// Runs the binary in `dir` with `args` (`{dir}` replaced), `stdin`, killed after `timeout`.
pub fn run(dir: &Path, args: &[&str], stdin: Option<&[u8]>, timeout: Duration) -> Run {
    let dir_text = dir.to_string_lossy();
    let args: Vec<String> = args.iter().map(|a| a.replace("{dir}", &dir_text)).collect();
    // Beside `dir`, named after it: the temp dir's name (`.tmpXXXXXX`) is its only unique
    // part, so it is not an extension to replace (`with_extension` gave every run one stderr
    // file, which parallel tests deleted under each other).
    let name = dir.file_name().unwrap().to_string_lossy();
    let out_path = dir.join("..").join(format!("stdout-{name}"));
    let err_path = dir.join("..").join(format!("stderr-{name}"));
    let mut child = Command::new(crate::common::bin::exe())
        .args(&args)
        .current_dir(dir)
        .stdin(if stdin.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .expect("run raywave");
    if let Some(bytes) = stdin {
        // A child that stops reading early closes the pipe: not the harness's failure.
        let _ = child.stdin.take().unwrap().write_all(bytes);
    }
    let start = Instant::now();
    let mut hung = false;
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > timeout {
            hung = true;
            let _ = child.kill();
            break child.wait().unwrap();
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let read = |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap()).into_owned();
    let run = Run {
        code: status.code(),
        stdout: read(&out_path),
        stderr: read(&err_path),
        hung,
    };
    let _ = std::fs::remove_file(out_path);
    let _ = std::fs::remove_file(err_path);
    run
}

/// Runs one case; `Err` says everything that was wrong with it.
pub fn check(case: &Case) -> Result<(), String> {
    // The scratch directory sits inside a parent of its own, which holds the captured
    // stdout/stderr, so that they are not part of the snapshot.
    let parent = tempfile::tempdir().unwrap();
    let dir = parent.path().join("work");
    std::fs::create_dir(&dir).unwrap();
    (case.setup)(&dir);
    let before = snapshot(&dir);
    let run = run(&dir, case.args, case.stdin, TIMEOUT);
    let after = snapshot(&dir);
    let mut wrong = Vec::new();
    if run.hung {
        wrong.push(format!("hung: killed after {TIMEOUT:?}"));
    }
    if run.code == Some(101) || run.stderr.contains("panicked at") {
        wrong.push("panicked".to_string());
    }
    if !run.hung && run.code != Some(case.exit) {
        wrong.push(format!("exit {:?}, expected {}", run.code, case.exit));
    }
    for fragment in case.stderr {
        if !run.stderr.contains(fragment) {
            wrong.push(format!("stderr lacks {fragment:?}"));
        }
    }
    let allowed = |p: &Path| case.outputs.iter().any(|o| Path::new(o) == p);
    for (path, entry) in &before {
        match after.get(path) {
            None if !allowed(path) => wrong.push(format!("{} was deleted", path.display())),
            Some(now) if now != entry && !allowed(path) => {
                wrong.push(format!("{} changed: {entry:?} -> {now:?}", path.display()))
            }
            _ => {}
        }
    }
    for path in after.keys() {
        if !before.contains_key(path) && !allowed(path) {
            wrong.push(format!("{} appeared", path.display()));
        }
    }
    if wrong.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{}: {}\n    args: {:?}\n    stderr: {}",
            case.name,
            wrong.join("; "),
            case.args,
            run.stderr.trim_end()
        ))
    }
}

/// A case with nothing on standard input, the commonest kind.
pub fn case(
    name: &'static str,
    setup: fn(&Path),
    args: &'static [&'static str],
    exit: i32,
    stderr: &'static [&'static str],
    outputs: &'static [&'static str],
) -> Case {
    Case {
        name,
        setup,
        args,
        stdin: None,
        exit,
        stderr,
        outputs,
    }
}

/// Runs every case and fails listing all that went wrong.
pub fn check_all(cases: &[Case]) {
    let failures: Vec<String> = cases.iter().filter_map(|c| check(c).err()).collect();
    assert!(
        failures.is_empty(),
        "{} of {} hostile cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// Setup helpers for [`Case::setup`].
pub mod setup {
    use std::path::Path;

    /// Nothing.
    pub fn nothing(_: &Path) {}

    /// A copy of the bundled scene `name` in `dir`.
    pub fn scene(dir: &Path, name: &str) {
        std::fs::copy(super::super::bin::scenes().join(name), dir.join(name)).unwrap();
    }

    /// The lab's box (`cornell_box.obj`) in `dir`.
    pub fn cornell_box(dir: &Path) {
        scene(dir, "cornell_box.obj");
    }

    /// A file `name` holding `text`.
    pub fn file(dir: &Path, name: &str, text: &[u8]) {
        std::fs::write(dir.join(name), text).unwrap();
    }

    /// A FIFO at `dir/name`.
    pub fn fifo(dir: &Path, name: &str) {
        let path = std::ffi::CString::new(dir.join(name).to_string_lossy().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path; mkfifo reads it and keeps nothing.
        let rc = unsafe { libc::mkfifo(path.as_ptr(), 0o644) };
        assert_eq!(rc, 0, "mkfifo {name}");
    }

    /// A symlink `dir/name` pointing at `target`.
    pub fn symlink(dir: &Path, name: &str, target: &str) {
        std::os::unix::fs::symlink(target, dir.join(name)).unwrap();
    }
}

/// More setup helpers: streams and big files.
pub mod setup_streams {
    use std::io::Write;
    use std::path::Path;

    /// A FIFO `dir/name` and a thread that writes `bytes` into it once a reader opens it (the
    /// thread waits forever, harmlessly, if none does).
    pub fn fifo_feeding(dir: &Path, name: &str, bytes: &'static [u8]) {
        super::setup::fifo(dir, name);
        let path = dir.join(name);
        std::thread::spawn(move || {
            if let Ok(mut f) = std::fs::OpenOptions::new().write(true).open(path) {
                let _ = f.write_all(bytes);
            }
        });
    }

    /// A sparse file `dir/name` of `len` bytes (zeros, no disk blocks).
    pub fn sparse(dir: &Path, name: &str, len: u64) {
        std::fs::File::create(dir.join(name))
            .unwrap()
            .set_len(len)
            .unwrap();
    }

    /// `dir/name`: the bundled scene `scene` with every vertex and sphere scaled by `s`.
    pub fn scaled(dir: &Path, name: &str, scene: &str, s: f64) {
        let text = std::fs::read_to_string(super::super::bin::scenes().join(scene)).unwrap();
        let mut out = String::new();
        for line in text.lines() {
            let t: Vec<&str> = line.split_whitespace().collect();
            let scale = |xs: &[&str]| {
                xs.iter()
                    .map(|x| format!("{:e}", x.parse::<f64>().unwrap() * s))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            match t.first() {
                Some(&"v") => out.push_str(&format!("v {}\n", scale(&t[1..4]))),
                Some(&"s") if t.len() == 5 => out.push_str(&format!("s {}\n", scale(&t[1..5]))),
                _ => {
                    out.push_str(line);
                    out.push('\n');
                }
            }
        }
        std::fs::write(dir.join(name), out).unwrap();
    }
}

/// More setup helpers for the output cases (tests/reliability/hostile_outputs.rs).
pub mod setup_outputs {
    use std::path::Path;

    /// A directory `dir/name`.
    pub fn dir(dir: &Path, name: &str) {
        std::fs::create_dir_all(dir.join(name)).unwrap();
    }

    /// A hard link `dir/name` to `dir/target`.
    pub fn hard_link(dir: &Path, name: &str, target: &str) {
        std::fs::hard_link(dir.join(target), dir.join(name)).unwrap();
    }

    /// A FIFO at `dir/name` with a thread that reads it to the end, as a consumer would.
    pub fn fifo_with_reader(dir: &Path, name: &str) {
        super::setup::fifo(dir, name);
        let path = dir.join(name);
        std::thread::spawn(move || {
            // Opening blocks until raywave opens the other end.
            if let Ok(mut f) = std::fs::File::open(&path) {
                let _ = std::io::copy(&mut f, &mut std::io::sink());
            }
        });
    }
}
