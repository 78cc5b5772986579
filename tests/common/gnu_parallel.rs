//! GNU parallel for the tests: one command template run once per shard, all shards at once,
//! stopping the others as soon as one fails. Needs Debian's `parallel` (`.ci/run` installs it).

use std::path::Path;
use std::process::{Command, Output};

/// `parallel --halt now,fail=1 --jobs SHARDS TEMPLATE ::: 0 1 .. SHARDS-1` in `dir`: the
/// shell runs `template` once per shard with `{}` replaced by the shard's index. Its status is
/// 0 when every shard succeeded, else the failed shard's exit code (the shards still running
/// are killed, and the rest never start). Err when GNU parallel is missing or cannot run.
pub fn run_shards(template: &str, shards: u32, dir: &Path) -> Result<Output, String> {
    // moreutils has a `parallel` of its own, with other flags.
    let version = Command::new("parallel").arg("--version").output();
    if !version.is_ok_and(|v| String::from_utf8_lossy(&v.stdout).starts_with("GNU parallel")) {
        return Err("GNU parallel is not installed (Debian package parallel)".into());
    }
    Command::new("parallel")
        // No citation notice on stderr, nor a prompt for one.
        .arg("--will-cite")
        .args(["--halt", "now,fail=1"])
        .arg(format!("--jobs={shards}"))
        .arg(template)
        .arg(":::")
        .args((0..shards).map(|i| i.to_string()))
        .current_dir(dir)
        .stdin(std::process::Stdio::null())
        .output()
        .map_err(|e| format!("cannot run GNU parallel (Debian package parallel): {e}"))
}
