//! Running the `raywave` binary in a scratch directory, and reading what it left there.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use std::time::SystemTime;

/// The `raywave` binary cargo built beside this test: `target/PROFILE/raywave`, this test being
/// `target/PROFILE/deps/NAME-HASH`. The binary's tests are a package of their own
/// (tests/Cargo.toml), and cargo builds the top package's binary only when that package is
/// tested too (a whole `cargo test --release`, not `--test commands` alone), so a binary
/// missing, or older than any file under src/, is refused here rather than tested stale.
pub fn exe() -> &'static str {
    static EXE: OnceLock<String> = OnceLock::new();
    EXE.get_or_init(|| {
        let test = std::env::current_exe().expect("the test binary's path");
        let profile = test
            .parent()
            .and_then(Path::parent)
            .expect("target/PROFILE/deps/TEST");
        let exe = profile.join("raywave");
        let build = "build it with `cargo build --release` (a whole `cargo test --release` \
                     builds it too; `--test commands` alone does not)";
        let built = std::fs::metadata(&exe)
            .and_then(|m| m.modified())
            .unwrap_or_else(|e| panic!("{}: {e}: {build}", exe.display()));
        let src = Path::new(env!("RAYWAVE_REPO")).join("src");
        if let Some((newer, _)) = newest(&src).filter(|(_, t)| *t > built) {
            panic!(
                "{} is older than {}: {build}",
                exe.display(),
                newer.display()
            );
        }
        exe.into_os_string().into_string().expect("a UTF-8 path")
    })
}

/// The most recently modified file below `dir`, and when.
fn newest(dir: &Path) -> Option<(PathBuf, SystemTime)> {
    std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let meta = e.metadata().ok()?;
            if meta.is_dir() {
                newest(&e.path())
            } else {
                Some((e.path(), meta.modified().ok()?))
            }
        })
        .max_by_key(|(_, t)| *t)
}

/// The bundled scenes' folder.
pub fn scenes() -> PathBuf {
    Path::new(env!("RAYWAVE_REPO")).join("scenes")
}

/// Runs the binary with `args` in `dir` and waits for it.
pub fn raywave(dir: &Path, args: &[&str]) -> Output {
    Command::new(exe())
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
