//! A real single-node Slurm cluster in a temporary directory, for tests that submit batch jobs:
//! munged with its own key and socket there, then slurmctld and slurmd in the foreground
//! (`-D`) as child processes reading a slurm.conf written there, one node with the machine's
//! CPUs, one partition. Nothing outside the directory is read or written but two TCP ports,
//! chosen free, so two test runs on one machine do not clash. Dropping the cluster cancels its
//! jobs and kills the daemons, also when the test panics; the daemons also die with the thread
//! that started them (PR_SET_PDEATHSIG), so a killed test run leaves none behind.
//!
//! Needs Debian's `slurm-wlm` and `munge` (`.ci/run` installs them) and, as CI has it, root.
//!
//! ```ignore
//! let tmp = tempfile::tempdir().unwrap();
//! let cluster = SlurmCluster::start(tmp.path())?;
//! let out = cluster.sbatch_array_wait(&script, 0..4, &workdir)?; // sbatch --array=0-3 --wait
//! assert!(out.status.success(), "{}", cluster.task_logs());
//! ```

use std::fs;
use std::io::{Read, Seek, SeekFrom};
use std::net::TcpListener;
use std::ops::Range;
use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// How long the daemons may take to show the node idle.
const START: Duration = Duration::from_secs(60);
/// How long one array job may take, waiting in the queue included, before
/// [`SlurmCluster::sbatch_array_wait`] cancels it and says so.
pub const JOB_TIMEOUT: Duration = Duration::from_secs(600);
/// How long a client command (sinfo, squeue, scancel) may take.
const CLIENT: Duration = Duration::from_secs(20);
/// Lines of each daemon's log quoted in an error.
const TAIL: usize = 25;

/// The programs the cluster runs, and where Debian puts them (the daemons in /usr/sbin, which
/// a non-root PATH may lack).
const PROGRAMS: [(&str, &str); 8] = [
    ("munged", "munge"),
    ("slurmctld", "slurm-wlm"),
    ("slurmd", "slurm-wlm"),
    ("sbatch", "slurm-wlm"),
    ("sinfo", "slurm-wlm"),
    ("squeue", "slurm-wlm"),
    ("scancel", "slurm-wlm"),
    ("scontrol", "slurm-wlm"),
];

/// One daemon: its process (the leader of its own process group) and its log.
struct Daemon {
    name: &'static str,
    child: Child,
    log: PathBuf,
}

/// A running single-node cluster; see the module's doc.
pub struct SlurmCluster {
    /// The cluster's directory (`TMP/slurm`).
    dir: PathBuf,
    /// Its slurm.conf.
    conf: PathBuf,
    /// Each program of [`PROGRAMS`], found.
    programs: Vec<(&'static str, PathBuf)>,
    /// munged, slurmctld, slurmd: started in that order, stopped in the reverse.
    daemons: Vec<Daemon>,
    /// The node's CPUs: how many one-CPU tasks run at once.
    cpus: u32,
}

/// `name` on the PATH or in the sbin directories.
fn find(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(["/usr/local/sbin", "/usr/sbin", "/sbin"].map(PathBuf::from))
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}

/// The last `n` lines of the file at `path`, or why there are none.
fn tail(path: &Path, n: usize) -> String {
    match fs::read(path) {
        Ok(bytes) => {
            let text = String::from_utf8_lossy(&bytes);
            let lines: Vec<&str> = text.lines().collect();
            lines[lines.len().saturating_sub(n)..].join("\n")
        }
        Err(e) => format!("(cannot read {}: {e})", path.display()),
    }
}

/// Runs `cmd` to completion, killing it after `limit`; Err says which of the two failed. Its
/// output goes through files, so a chatty command cannot fill a pipe and stall while we poll
/// it.
fn run_for(cmd: &mut Command, limit: Duration, scratch: &Path) -> Result<Output, String> {
    let name = cmd.get_program().to_string_lossy().into_owned();
    let file = || tempfile::tempfile_in(scratch).map_err(|e| format!("{}: {e}", scratch.display()));
    let (mut out, mut err) = (file()?, file()?);
    let clone = |f: &fs::File| {
        f.try_clone()
            .map_err(|e| format!("{}: {e}", scratch.display()))
    };
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(clone(&out)?)
        .stderr(clone(&err)?)
        .spawn()
        .map_err(|e| format!("cannot run {name}: {e}"))?;
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().map_err(|e| format!("{name}: {e}"))? {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "{name} did not end within {limit:?}, and was killed"
            ));
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let read = |f: &mut fs::File| {
        let mut v = Vec::new();
        f.seek(SeekFrom::Start(0))
            .and_then(|_| f.read_to_end(&mut v))
            .map(|_| v)
            .map_err(|e| format!("{name}'s output: {e}"))
    };
    Ok(Output {
        status,
        stdout: read(&mut out)?,
        stderr: read(&mut err)?,
    })
}

/// Two TCP ports free now on every interface (slurmctld and slurmd listen on all).
fn free_ports() -> Result<(u16, u16), String> {
    let bind = || {
        TcpListener::bind(("0.0.0.0", 0))
            .and_then(|l| Ok((l.local_addr()?.port(), l)))
            .map_err(|e| format!("no free TCP port: {e}"))
    };
    // Both held open at once, so that they differ.
    let ((a, _la), (b, _lb)) = (bind()?, bind()?);
    Ok((a, b))
}

/// The user running the tests, who is also the cluster's SlurmUser.
fn user_name() -> Result<String, String> {
    let out = Command::new("id")
        .arg("-un")
        .output()
        .map_err(|e| format!("cannot run `id -un`: {e}"))?;
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The CPUs slurmd will find (`slurmd -C` prints the node line it would register), so the
/// node is not drained for having fewer than slurm.conf says; the machine's count otherwise.
fn cpus(slurmd: &Path) -> u32 {
    let detected = Command::new(slurmd).arg("-C").output().ok().and_then(|o| {
        String::from_utf8_lossy(&o.stdout)
            .split_whitespace()
            .find_map(|w| w.strip_prefix("CPUs=")?.parse().ok())
    });
    detected.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get() as u32))
}

impl SlurmCluster {
    /// Starts munged, slurmctld and slurmd in `tmp/slurm` and waits until `sinfo` shows the
    /// node idle. `tmp` is made searchable by all (mode 755): munged refuses a socket under a
    /// directory that others cannot search. The error says which step failed and quotes the
    /// daemons' logs.
    pub fn start(tmp: &Path) -> Result<SlurmCluster, String> {
        let mut programs = Vec::new();
        for (name, package) in PROGRAMS {
            let path = find(name)
                .ok_or_else(|| format!("`{name}` is not installed (Debian package {package})"))?;
            programs.push((name, path));
        }
        let dir = tmp.join("slurm");
        let io = |what: &str, e: std::io::Error| format!("{what} in {}: {e}", dir.display());
        for sub in ["", "munge", "state", "spool", "jobs", "scratch"] {
            fs::create_dir_all(dir.join(sub)).map_err(|e| io("cannot create a directory", e))?;
        }
        for d in [tmp, &dir, &dir.join("munge")] {
            fs::set_permissions(d, fs::Permissions::from_mode(0o755))
                .map_err(|e| io("cannot chmod 755", e))?;
        }
        let slurmd = &programs.iter().find(|(n, _)| *n == "slurmd").unwrap().1;
        let mut cluster = SlurmCluster {
            conf: dir.join("slurm.conf"),
            dir,
            cpus: cpus(slurmd),
            programs,
            daemons: Vec::new(),
        };
        cluster.start_munged()?;
        cluster.write_conf()?;
        cluster.spawn("slurmctld", &["-D", "-f"])?;
        cluster.spawn("slurmd", &["-D", "-N", "localhost", "-f"])?;
        cluster.wait_idle()?;
        Ok(cluster)
    }

    /// The node's CPUs, as slurmd finds them: how many one-CPU tasks run at once.
    pub fn cpus(&self) -> u32 {
        self.cpus
    }

    /// The variables a client command needs to reach this cluster.
    pub fn env(&self) -> Vec<(&'static str, PathBuf)> {
        vec![("SLURM_CONF", self.conf.clone())]
    }

    /// A client command (`sbatch`, `squeue`, ...) for this cluster: [`Self::env`] set and the
    /// caller's own SLURM_*, SBATCH_*, SALLOC_* and SRUN_* variables removed, so a test run
    /// from inside another Slurm job does not carry that job's options or cluster along.
    pub fn command(&self, program: &str) -> Command {
        let path = self.program(program);
        let mut cmd = Command::new(path);
        for (key, _) in std::env::vars_os() {
            let k = key.to_string_lossy();
            if ["SLURM_", "SBATCH_", "SALLOC_", "SRUN_"]
                .iter()
                .any(|p| k.starts_with(p))
            {
                cmd.env_remove(&key);
            }
        }
        cmd.envs(self.env());
        cmd
    }

    /// `sbatch --wait --array=A-B SCRIPT` in `workdir`: returns when every task has ended,
    /// with sbatch's output; its status is the highest exit code of the tasks (non-zero when
    /// one failed or was killed). Each task's output goes to the cluster's `jobs/JOB_TASK.out`
    /// ([`Self::task_logs`]). Err when sbatch cannot run, or the job has not ended after
    /// [`JOB_TIMEOUT`] (it is then cancelled).
    pub fn sbatch_array_wait(
        &self,
        script: &Path,
        indices: Range<u32>,
        workdir: &Path,
    ) -> Result<Output, String> {
        if indices.is_empty() {
            return Err(format!("no array task in {indices:?}"));
        }
        let mut cmd = self.command("sbatch");
        cmd.arg("--wait")
            .arg(format!("--array={}-{}", indices.start, indices.end - 1))
            .arg(format!("--chdir={}", workdir.display()))
            .arg(format!(
                "--output={}/%A_%a.out",
                self.dir.join("jobs").display()
            ))
            .arg(script);
        run_for(&mut cmd, JOB_TIMEOUT, &self.dir.join("scratch")).map_err(|why| {
            let queue = self.squeue();
            self.cancel_all();
            format!(
                "{why} (array job {}; every job is now cancelled); the queue was:\n{queue}\n{}{}",
                script.display(),
                self.task_logs(),
                self.log_tails()
            )
        })
    }

    /// Every task output file of the cluster's jobs, each under its name: for a failure
    /// message.
    pub fn task_logs(&self) -> String {
        let jobs = self.dir.join("jobs");
        let mut names: Vec<PathBuf> = fs::read_dir(&jobs)
            .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        names.sort();
        let mut text = String::new();
        for path in names {
            text += &format!(
                "--- task output {} ---\n{}\n",
                path.display(),
                tail(&path, 50)
            );
        }
        text
    }

    /// The last lines of each daemon's log, and which daemons have exited: for a failure
    /// message.
    pub fn log_tails(&self) -> String {
        let mut text = String::new();
        for d in &self.daemons {
            text += &format!(
                "--- {} ({}) ---\n{}\n",
                d.name,
                d.log.display(),
                tail(&d.log, TAIL)
            );
        }
        text
    }

    fn program(&self, name: &str) -> &Path {
        let found = self.programs.iter().find(|(n, _)| *n == name);
        &found
            .unwrap_or_else(|| panic!("{name} is not one of the cluster's programs"))
            .1
    }

    /// Starts `name` with `args` (then the slurm.conf path, for the Slurm daemons' `-f`) as
    /// the leader of its own process group, its output to `name.log`.
    fn spawn(&mut self, name: &'static str, args: &[&str]) -> Result<(), String> {
        let log = self.dir.join(format!("{name}.log"));
        let file = fs::File::create(&log).map_err(|e| format!("{}: {e}", log.display()))?;
        let mut cmd = Command::new(self.program(name));
        cmd.args(args);
        if name != "munged" {
            cmd.arg(&self.conf);
        }
        cmd.env("SLURM_CONF", &self.conf)
            .stdin(Stdio::null())
            .stdout(file.try_clone().map_err(|e| e.to_string())?)
            .stderr(file)
            .process_group(0);
        // SAFETY: prctl(2) is async-signal-safe, so it may run between fork and exec. The
        // daemon gets SIGKILL when the thread that started it ends: a test killed before
        // its drop guard runs leaves no daemon behind.
        unsafe {
            cmd.pre_exec(|| {
                if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) == -1 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = cmd
            .spawn()
            .map_err(|e| format!("cannot start {name}: {e}"))?;
        self.daemons.push(Daemon { name, child, log });
        Ok(())
    }

    /// Err naming the first daemon that has exited, with its status and the logs.
    fn check_alive(&mut self, during: &str) -> Result<(), String> {
        for i in 0..self.daemons.len() {
            if let Ok(Some(status)) = self.daemons[i].child.try_wait() {
                let name = self.daemons[i].name;
                return Err(format!(
                    "{name} exited ({status}) {during}\n{}",
                    self.log_tails()
                ));
            }
        }
        Ok(())
    }

    /// munged with a fresh key, its socket, pid and seed files in `munge/`; waits for the
    /// socket. Its `--log-file` is not used in the foreground (`-F`): it logs to stderr.
    fn start_munged(&mut self) -> Result<(), String> {
        let munge = self.dir.join("munge");
        let key = munge.join("munge.key");
        // munged wants a key of at least 32 bytes, readable by its owner alone; 128 random
        // bytes is what `mungekey -c` writes.
        let mut bytes = vec![0u8; 128];
        fs::File::open("/dev/urandom")
            .and_then(|mut f| f.read_exact(&mut bytes))
            .map_err(|e| format!("cannot read /dev/urandom for the munge key: {e}"))?;
        fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(&key)
            .and_then(|mut f| std::io::Write::write_all(&mut f, &bytes))
            .map_err(|e| format!("cannot write the munge key {}: {e}", key.display()))?;
        let socket = munge.join("munge.socket");
        let flag = |name: &str, file: &str| format!("--{name}={}", munge.join(file).display());
        let args = [
            "-F".to_string(),
            format!("--socket={}", socket.display()),
            flag("key-file", "munge.key"),
            flag("pid-file", "munged.pid"),
            flag("seed-file", "munged.seed"),
            flag("log-file", "munged.log"),
        ];
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        self.spawn("munged", &args)?;
        let start = Instant::now();
        while !socket.exists() {
            self.check_alive("before creating its socket")?;
            if start.elapsed() > Duration::from_secs(10) {
                return Err(format!(
                    "munged made no socket at {} in 10 s\n{}",
                    socket.display(),
                    self.log_tails()
                ));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        Ok(())
    }

    /// slurm.conf: the smallest set of settings a one-node cluster in a temp dir needs, every
    /// path in the cluster's directory.
    fn write_conf(&self) -> Result<(), String> {
        let (ctld_port, d_port) = free_ports()?;
        let user = user_name()?;
        let cpus = self.cpus;
        let d = self.dir.display();
        let conf = format!(
            "# One test's cluster, written by tests/common/slurm.rs.
ClusterName=raywavetest
SlurmctldHost=localhost
# Free ports, chosen when the test started: two runs on one machine do not clash.
SlurmctldPort={ctld_port}
SlurmdPort={d_port}
SlurmUser={user}
SlurmdUser={user}
# Slurm's clients and daemons talk to this munged, not to a system-wide one.
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={d}/munge/munge.socket
MpiDefault=none
# No cgroups (a container has no writable cgroup tree): processes tracked by their parent
# pids, tasks not bound to CPUs.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
# Each CPU is a resource of its own, so one node runs as many one-CPU tasks at once as it
# has CPUs (the default select/linear gives each job a whole node).
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
# A node that was down comes back by itself when its slurmd registers.
ReturnToService=2
# `sbatch --wait` polls every 2 s, then 8, then 32, unless a finished job could be purged
# before the next poll (MinJobAge / 2): keeping finished jobs 4 s keeps it polling every 2 s,
# where the default (300 s) made each array of shards wait 10 s for a 2 s job.
MinJobAge=4
MailProg=/bin/true
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
# The node is called localhost whatever the machine's name (slurmd runs with -N localhost),
# and reached on the loopback address.
NodeName=localhost NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
"
        );
        fs::write(&self.conf, conf).map_err(|e| format!("{}: {e}", self.conf.display()))
    }

    /// The node's state as `sinfo` prints it (`idle`, `down*`, ...), or what went wrong.
    fn node_state(&self) -> String {
        let mut cmd = self.command("sinfo");
        cmd.args(["--noheader", "--Node", "--format=%T"]);
        match run_for(&mut cmd, CLIENT, &self.dir.join("scratch")) {
            Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).trim().into(),
            Ok(o) => format!(
                "sinfo failed: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ),
            Err(why) => why,
        }
    }

    /// Waits until the node is idle, failing as soon as a daemon exits.
    fn wait_idle(&mut self) -> Result<(), String> {
        let start = Instant::now();
        loop {
            self.check_alive("before the node was idle")?;
            let state = self.node_state();
            if state == "idle" {
                return Ok(());
            }
            if start.elapsed() > START {
                let mut cmd = self.command("scontrol");
                cmd.args(["show", "node", "localhost"]);
                let node = run_for(&mut cmd, CLIENT, &self.dir.join("scratch")).map_or_else(
                    |why| why,
                    |o| String::from_utf8_lossy(&o.stdout).into_owned(),
                );
                return Err(format!(
                    "the node is not idle after {START:?}: sinfo says {state:?}\n{node}\n{}",
                    self.log_tails()
                ));
            }
            std::thread::sleep(Duration::from_millis(250));
        }
    }

    /// `squeue`'s listing of every job, for a message.
    fn squeue(&self) -> String {
        let mut cmd = self.command("squeue");
        run_for(&mut cmd, CLIENT, &self.dir.join("scratch")).map_or_else(
            |why| why,
            |o| String::from_utf8_lossy(&o.stdout).into_owned(),
        )
    }

    /// Cancels every job of the cluster and waits (up to 15 s) until the queue is empty:
    /// slurmstepd, which runs a job's script, is not a child of slurmd (it starts its own
    /// session), so only Slurm itself can end a job that is still running.
    fn cancel_all(&self) {
        let scratch = self.dir.join("scratch");
        let ids = || {
            let mut cmd = self.command("squeue");
            cmd.args(["--noheader", "--format=%A"]);
            run_for(&mut cmd, CLIENT, &scratch).ok().map(|o| {
                String::from_utf8_lossy(&o.stdout)
                    .split_whitespace()
                    .map(str::to_string)
                    .collect::<Vec<_>>()
            })
        };
        let Some(jobs) = ids() else { return };
        if jobs.is_empty() {
            return;
        }
        let mut cmd = self.command("scancel");
        cmd.args(&jobs);
        let _ = run_for(&mut cmd, CLIENT, &scratch);
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(15) && ids().is_some_and(|j| !j.is_empty()) {
            std::thread::sleep(Duration::from_millis(250));
        }
    }
}

impl Drop for SlurmCluster {
    fn drop(&mut self) {
        let ctld_alive = self
            .daemons
            .iter_mut()
            .any(|d| d.name == "slurmctld" && matches!(d.child.try_wait(), Ok(None)));
        if ctld_alive {
            self.cancel_all();
        }
        // SIGTERM first, for slurmctld to end its slurmscriptd; SIGKILL after 5 s.
        for d in self.daemons.iter_mut().rev() {
            // SAFETY: kill(2) on the process group our own child leads (slurmctld's
            // slurmscriptd is in it too).
            unsafe { libc::kill(-(d.child.id() as i32), libc::SIGTERM) };
            let start = Instant::now();
            while matches!(d.child.try_wait(), Ok(None)) && start.elapsed() < Duration::from_secs(5)
            {
                std::thread::sleep(Duration::from_millis(20));
            }
            // SAFETY: as above; the group may still hold a process that ignored SIGTERM.
            unsafe { libc::kill(-(d.child.id() as i32), libc::SIGKILL) };
            let _ = d.child.wait();
        }
    }
}
