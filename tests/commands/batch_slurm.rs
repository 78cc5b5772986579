//! A real Slurm cluster (`common::slurm`: munged, slurmctld and slurmd in a temp dir) runs a
//! job array: every task runs, in its working directory, with its own SLURM_ARRAY_TASK_ID,
//! two at a time on a two-CPU node; and `sbatch --wait` returns non-zero when a task failed or
//! was killed, which is how a batch run of raywave's shards notices a shard that died.
//!
//! Needs Debian's `slurm-wlm` and `munge` (`.ci/run` installs them). When the cluster cannot
//! start, the test says why, with the daemons' logs: it prints SKIPPED and passes, unless CI is
//! set: then it fails.

use crate::common;

use common::bin::files_in;
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

#[test]
fn an_array_job_runs_every_task_in_its_workdir_two_at_a_time() {
    let tmp = tempfile::tempdir().unwrap();
    let Some(cluster) = cluster(tmp.path()) else {
        return;
    };
    // Each task marks itself running, then waits (up to 30 s) until it sees as many marks
    // as the node runs tasks at once, and writes its index and the marks it saw. The first
    // task to start sees a second mark only if a second task runs beside it.
    let at_once = cluster.cpus().min(2);
    let (path, work) = script(
        tmp.path(),
        "array.sh",
        &format!(
            "set -e
touch \"running-$SLURM_ARRAY_TASK_ID\"
i=0
while [ \"$(ls running-* | wc -l)\" -lt {at_once} ] && [ $i -lt 300 ]; do sleep 0.1; i=$((i+1)); done
echo \"$SLURM_ARRAY_TASK_ID $(ls running-* | wc -l)\" > \"task-$SLURM_ARRAY_TASK_ID\"
"
        ),
    );
    let out = cluster.sbatch_array_wait(&path, 0..4, &work).unwrap();
    let logs = || format!("{}{}", cluster.task_logs(), cluster.log_tails());
    assert!(
        out.status.success(),
        "sbatch --wait: {}\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr),
        logs()
    );
    let mut expected: Vec<String> = (0..4).map(|i| format!("running-{i}")).collect();
    expected.extend((0..4).map(|i| format!("task-{i}")));
    assert_eq!(files_in(&work), expected, "{}", logs());
    for i in 0..4 {
        let text = std::fs::read_to_string(work.join(format!("task-{i}"))).unwrap();
        let words: Vec<&str> = text.split_whitespace().collect();
        assert_eq!(words[0], i.to_string(), "task-{i} holds {text:?}");
        let seen: u32 = words[1].parse().unwrap();
        assert!(
            seen >= at_once,
            "task {i} saw {seen} task(s) running, not {at_once}: the node ran the array's \
             tasks one at a time\n{}",
            logs()
        );
    }
}

#[test]
fn a_task_that_fails_or_is_killed_fails_sbatch_wait() {
    let tmp = tempfile::tempdir().unwrap();
    let Some(cluster) = cluster(tmp.path()) else {
        return;
    };
    // Task 2 fails; the others run to their end and write their files.
    let (path, work) = script(
        tmp.path(),
        "fails.sh",
        "[ \"$SLURM_ARRAY_TASK_ID\" = 2 ] && exit 7\ntouch \"task-$SLURM_ARRAY_TASK_ID\"\n",
    );
    let out = cluster.sbatch_array_wait(&path, 0..4, &work).unwrap();
    assert_eq!(
        out.status.code(),
        Some(7),
        "sbatch --wait returns the failed task's exit code\n{}",
        cluster.task_logs()
    );
    assert_eq!(files_in(&work), ["task-0", "task-1", "task-3"]);
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
