//! A real Slurm cluster (`common::slurm`: munged, slurmctld and slurmd in a temp dir) runs a
//! variance study as a job array: `sbatch --array=0-3 --wait`, task I running shard I/4 on the
//! references `variance prepare` rendered ahead, then `variance merge` gives the single
//! process's figures. `sbatch --wait` returns non-zero when a task failed or was killed, and
//! the merge of what the others left names the shard that died.
//!
//! Needs Debian's `slurm-wlm` and `munge` (`.ci/run` installs them). When the cluster cannot
//! start, the test says why, with the daemons' logs: it prints SKIPPED and passes, unless CI is
//! set: then it fails.

use crate::common;

use crate::variance_shards::{merge_matches_single, single_and_prepared, study_dir};
use common::bin::{files_in, raywave, stderr};
use common::skip::skip_or_fail;
use common::slurm::SlurmCluster;
use std::path::{Path, PathBuf};

/// A cluster in `tmp`, or None (the test returns) when it cannot start outside CI.
fn cluster(tmp: &Path) -> Option<SlurmCluster> {
    match SlurmCluster::start(tmp) {
        Ok(c) => Some(c),
        Err(why) => {
            skip_or_fail(&format!("the test's Slurm cluster did not start: {why}"));
            None
        }
    }
}

/// `body` as an executable shell script `tmp/name`, and an empty working directory
/// `tmp/work-name` for it.
fn script(tmp: &Path, name: &str, body: &str) -> (PathBuf, PathBuf) {
    use std::os::unix::fs::PermissionsExt;
    let path = tmp.join(name);
    std::fs::write(&path, format!("#!/bin/sh\n{body}")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    let work = tmp.join(format!("work-{name}"));
    std::fs::create_dir(&work).unwrap();
    (path, work)
}

/// The array script of a study's shards: task I runs shard I/4 of `study.toml` in its working
/// directory, on the cache the shards share; with `die_at`, that task exits 7 first.
fn shards_script(tmp: &Path, name: &str, die_at: Option<u32>) -> (PathBuf, PathBuf) {
    let exe = crate::common::bin::exe();
    let die = die_at.map_or(String::new(), |i| {
        format!("[ \"$SLURM_ARRAY_TASK_ID\" = {i} ] && exit 7\n")
    });
    script(
        tmp,
        name,
        &format!(
            "set -e\n{die}exec {exe} variance --study study.toml --shard \"$SLURM_ARRAY_TASK_ID/4\" \\
             --cache cache --out parts --threads 1 -q\n"
        ),
    )
}

/// Copies the study of `variance_shards` (the file and its scenes) into `work`.
fn study_into(work: &Path) {
    let study = study_dir();
    for e in std::fs::read_dir(study.path()).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), work.join(e.file_name())).unwrap();
    }
}

#[test]
fn a_study_submitted_as_an_array_job_merges_into_the_single_process_report() {
    let tmp = tempfile::tempdir().unwrap();
    let Some(cluster) = cluster(tmp.path()) else {
        return;
    };
    let (path, work) = shards_script(tmp.path(), "shards.sh", None);
    study_into(&work);
    single_and_prepared(&work);
    let out = cluster.sbatch_array_wait(&path, 0..4, &work).unwrap();
    let logs = || format!("{}{}", cluster.task_logs(), cluster.log_tails());
    assert!(
        out.status.success(),
        "sbatch --wait: {}\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr),
        logs()
    );
    merge_matches_single(
        &work,
        &[
            "merged  4 shards, 18 jobs",
            "references 0 rendered by a shard",
        ],
    );
}

#[test]
fn a_task_that_fails_or_is_killed_fails_sbatch_wait() {
    let tmp = tempfile::tempdir().unwrap();
    let Some(cluster) = cluster(tmp.path()) else {
        return;
    };
    // Shard 2 dies; the others run to their end and write their parts, and the merge names
    // the shard that is missing.
    let (path, work) = shards_script(tmp.path(), "fails.sh", Some(2));
    study_into(&work);
    let out = cluster.sbatch_array_wait(&path, 0..4, &work).unwrap();
    assert_eq!(
        out.status.code(),
        Some(7),
        "sbatch --wait returns the failed task's exit code\n{}",
        cluster.task_logs()
    );
    assert_eq!(
        files_in(&work.join("parts")),
        [
            "variance-shard-0-of-4.part",
            "variance-shard-1-of-4.part",
            "variance-shard-3-of-4.part"
        ]
    );
    let merged = raywave(&work, &["variance", "merge", "parts", "--out", "merged"]);
    assert_eq!(merged.status.code(), Some(1));
    assert!(
        stderr(&merged).contains("shard 2/4 is missing"),
        "{}",
        stderr(&merged)
    );
    assert!(!work.join("merged").exists());
    // Task 1 dies of a signal, as a shard killed by the kernel or an operator would.
    let (path, work) = script(
        tmp.path(),
        "killed.sh",
        "[ \"$SLURM_ARRAY_TASK_ID\" = 1 ] && kill -9 $$\ntouch \"task-$SLURM_ARRAY_TASK_ID\"\n",
    );
    let out = cluster.sbatch_array_wait(&path, 0..4, &work).unwrap();
    assert!(
        !out.status.success(),
        "sbatch --wait succeeded although task 1 was killed\n{}",
        cluster.task_logs()
    );
    assert_eq!(files_in(&work), ["task-0", "task-2", "task-3"]);
}
