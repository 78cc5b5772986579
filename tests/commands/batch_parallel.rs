//! GNU parallel as a one-machine batch system for raywave's shards (`common::gnu_parallel`):
//! a command template runs once per shard index, and a shard that fails makes the whole run
//! fail with its exit code, the shards still running stopped.
//!
//! Needs Debian's `parallel` (`.ci/run` installs it). Without it the test prints SKIPPED and
//! passes, unless CI is set: then it fails.

use crate::common;

use common::bin::files_in;
use common::gnu_parallel::run_shards;
use common::skip::skip_or_fail;

#[test]
fn every_shard_runs_with_its_index_and_a_failed_one_fails_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = match run_shards("echo {} > shard-{}", 4, dir.path()) {
        Ok(out) => out,
        Err(why) => return skip_or_fail(&why),
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}: {stderr}", out.status);
    assert_eq!(
        files_in(dir.path()),
        ["shard-0", "shard-1", "shard-2", "shard-3"]
    );
    for i in 0..4 {
        let text = std::fs::read_to_string(dir.path().join(format!("shard-{i}"))).unwrap();
        assert_eq!(text.trim(), i.to_string(), "shard-{i}");
    }

    // Shard 2 fails at once; the others would write their file a few seconds later, but
    // `--halt now,fail=1` stops them first.
    let dir = tempfile::tempdir().unwrap();
    let out = run_shards(
        "if [ {} = 2 ]; then exit 7; fi; sleep 5; echo {} > shard-{}",
        4,
        dir.path(),
    )
    .unwrap();
    assert_eq!(
        out.status.code(),
        Some(7),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(files_in(dir.path()), Vec::<String>::new());
}
