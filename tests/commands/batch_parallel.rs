//! GNU parallel as a one-machine batch system for raywave's shards (`common::gnu_parallel`):
//! a study of two scenes, its references prepared first, run as four shards at once and merged,
//! gives the single process's figures; and a shard that fails makes the whole run fail with
//! its exit code, the shards still running stopped.
//!
//! Needs Debian's `parallel` (`.ci/run` installs it). Without it the test prints SKIPPED and
//! passes, unless CI is set: then it fails.

use crate::common;
use crate::variance_shards::{merge_matches_single, ok, single_and_prepared, study_dir};

use common::bin::files_in;
use common::gnu_parallel::run_shards;
use common::skip::skip_or_fail;

#[test]
fn a_study_sharded_four_ways_by_gnu_parallel_merges_into_the_single_process_report() {
    let dir = study_dir();
    let d = dir.path();
    let exe = crate::common::bin::exe();
    single_and_prepared(d);
    let template = format!(
        "{exe} variance --study study.toml --shard {{}}/4 --cache cache --out parts --threads 1 -q"
    );
    let out = match run_shards(&template, 4, d) {
        Ok(out) => out,
        Err(why) => return skip_or_fail(&why),
    };
    ok(&out);
    merge_matches_single(
        d,
        &[
            "merged  4 shards, 18 jobs",
            "references 0 rendered by a shard",
        ],
    );
}

#[test]
fn a_failed_shard_fails_the_run() {
    // Shard 2 fails at once; the others would write their file a few seconds later, but
    // `--halt now,fail=1` stops them first.
    let dir = tempfile::tempdir().unwrap();
    let out = match run_shards(
        "if [ {} = 2 ]; then exit 7; fi; sleep 5; echo {} > shard-{}",
        4,
        dir.path(),
    ) {
        Ok(out) => out,
        Err(why) => return skip_or_fail(&why),
    };
    assert_eq!(
        out.status.code(),
        Some(7),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(files_in(dir.path()), Vec::<String>::new());
}
