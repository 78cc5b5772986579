//! What makes two shards parts of one run: the same build (version, commit, profile, target,
//! target features, RUSTFLAGS, SIMD path, and the executable's hash when the tree was dirty)
//! and the same work, which the command describes through [`Work`].

use crate::output::build_info::BuildInfo;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// A command's sharded work: its items, their costs and results. Bench's sweep and variance's
/// study implement it; everything else about shards is written once, in this module.
pub trait Work: Clone + PartialEq + Serialize + DeserializeOwned {
    /// The part kind, in the file header and the file names: `bench`, `variance`.
    const KIND: &'static str;
    /// What one run of the work is called in messages: `sweep`, `study`.
    const NOUN: &'static str;
    /// The command that writes this kind's parts, for messages: `raywave bench --shard I/N`.
    const COMMAND: &'static str;
    /// How to make two shards of one run, said when two are not.
    const SAME_RUN: &'static str;
    /// What one item produced; a part holds one per item it ran.
    type Result: Clone + std::fmt::Debug + Serialize + DeserializeOwned;
    /// What a part holds besides its results (`()` when nothing).
    type Extra: Clone + std::fmt::Debug + Serialize + DeserializeOwned;

    /// Each item's estimated cost, in item order: the split is made by them.
    fn costs(&self) -> Vec<f64>;

    /// How `other` differs from this work, one line per difference (empty: the same work),
    /// values named by the sides `a` and `b` (`runs: 6 in A, 7 in B`).
    fn differences(&self, other: &Self, a: &str, b: &str) -> Vec<String>;

    /// Why `results` cannot be those of `items` of this work, run by `identity`'s build, if
    /// they cannot; `results` and `items` have the same length.
    fn check_results(
        identity: &Identity<Self>,
        items: &[usize],
        results: &[Self::Result],
    ) -> Option<String>;
}

/// The identity of a sharded run: the build that ran it and its work. Every shard of one run
/// carries an equal identity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Identity<W> {
    /// raywave's version.
    pub raywave: String,
    /// The build: commit, dirty flag, profile, target, target features, RUSTFLAGS.
    pub build: BuildInfo,
    /// The SIMD path the work's renders ran (`raywave::simd_path_for`).
    pub simd: String,
    /// FNV-1a of the running executable, when its commit does not identify it (a dirty tree).
    pub executable: Option<String>,
    /// The work.
    pub work: W,
}

impl<W: Work> Identity<W> {
    /// The identity of `work` run by this binary on the SIMD path `simd`.
    pub fn current(simd: &str, work: W) -> Identity<W> {
        let build = crate::output::build_info::current();
        // Read and hashed once per process: a command may ask more than once.
        static EXECUTABLE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        let executable = (build.dirty != Some(false)).then(|| {
            EXECUTABLE
                .get_or_init(|| {
                    std::env::current_exe().and_then(std::fs::read).map_or_else(
                        |_| "unreadable".to_string(),
                        |b| crate::render::digest::hex(&b),
                    )
                })
                .clone()
        });
        Identity {
            raywave: env!("CARGO_PKG_VERSION").to_string(),
            build,
            simd: simd.to_string(),
            executable,
            work,
        }
    }

    /// How the build of `other` differs from this one's, one line per field (`commit: X in A,
    /// Y in B`); the SIMD path is among them.
    fn build_differences(&self, other: &Identity<W>, a: &str, b: &str) -> Vec<String> {
        let describe = |s: &Identity<W>| {
            [
                ("raywave", s.raywave.clone()),
                ("commit", s.build.short_commit()),
                ("profile", s.build.profile.clone()),
                ("target", s.build.target.clone()),
                ("target features", s.build.target_features.clone()),
                ("RUSTFLAGS", s.build.rustflags.clone()),
                ("simd", s.simd.clone()),
                ("executable", s.executable.clone().unwrap_or_default()),
            ]
        };
        describe(self)
            .into_iter()
            .zip(describe(other))
            .filter(|((_, x), (_, y))| x != y)
            .map(|((name, x), (_, y))| format!("{name}: {x} {a}, {y} {b}"))
            .collect()
    }

    /// Why `other` cannot be a shard of the same run as this identity, naming the two files
    /// `a` and `b`; None when it can.
    pub fn refusal(&self, other: &Identity<W>, a: &str, b: &str) -> Option<String> {
        let (in_a, in_b) = (format!("in {a}"), format!("in {b}"));
        let build = self.build_differences(other, &in_a, &in_b);
        // The SIMD path first: binaries built for two CPUs (`target-cpu=native` on two kinds of
        // node) can share a commit and differ only there, and their kernels are not the same.
        if self.simd != other.simd {
            return Some(format!(
                "{a} and {b} were run by binaries with different SIMD paths, {} and {}, so their \
                 figures do not come from the same kernels:\n  {}\nrun every shard with one \
                 build (for nodes of several CPUs, one built for the oldest: docs/SCALING.md)",
                self.simd,
                other.simd,
                build.join("\n  ")
            ));
        }
        if !build.is_empty() {
            return Some(format!(
                "{a} and {b} come from different raywave builds, so their figures do not \
                 describe the same code:\n  {}\nrun every shard with one build",
                build.join("\n  ")
            ));
        }
        let work = self.work.differences(&other.work, &in_a, &in_b);
        if !work.is_empty() || self.work != other.work {
            let noun = W::NOUN;
            return Some(format!(
                "{a} and {b} are not shards of the same {noun}:\n  {}\n{}",
                if work.is_empty() {
                    format!("the {noun}s differ")
                } else {
                    work.join("\n  ")
                },
                W::SAME_RUN
            ));
        }
        None
    }
}
