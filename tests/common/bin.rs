//! Running the `raywave` binary in a scratch directory, and reading what it left there.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The bundled scenes' folder.
pub fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// Runs the binary with `args` in `dir` and waits for it.
pub fn raywave(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raywave"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run raywave")
}

/// The run's standard error, lossily decoded.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The run's standard output, lossily decoded.
pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A command line split at white space (no quoting).
pub fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

/// A temp dir holding copies of the given bundled scenes.
pub fn dir_with(names: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in names {
        std::fs::copy(scenes().join(name), dir.path().join(name)).unwrap();
    }
    dir
}

/// The names in `dir`, sorted: a test lists exactly the files it expects, so a stray
/// `render.png` or a leftover temporary file fails it.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}
