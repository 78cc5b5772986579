//! A study over several cases (scene × image size), its identity and its job list: what every
//! shard of a study computes alike, and what a merge checks its parts against.
//!
//! ```text
//! cases    = scenes × sizes, named by the scene's file stem (and the size, given several)
//! identity = format, raywave build (version, commit, SIMD path; the executable's hash when the
//!            tree was dirty), engine, per case: name, scene bytes' hash, lights, settings
//! jobs     = per case in order: budgets × samplers (jobs::case_jobs), numbered across cases
//! shard i  = output::shard::partition(costs of the jobs, count)[i]
//! ```

use super::StudyConfig;
use super::jobs::{self, Job};
use crate::render::scene::Scene;
use serde::{Deserialize, Serialize};

/// Bumped when the parts' layout or the meaning of a study's identity changes.
pub const PART_FORMAT: u32 = 1;

/// One case of a study: a scene at one size.
pub struct Case {
    /// Its name in the report (`cornell_box`, `cornell_box-256x256`).
    pub name: String,
    /// The scene.
    pub scene: Scene,
    /// The bytes the scene was parsed from.
    pub bytes: Vec<u8>,
    /// What to measure in it.
    pub config: StudyConfig,
}

/// What makes two runs parts of the same study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyIdentity {
    /// [`PART_FORMAT`].
    pub format: u32,
    /// raywave's version, commit and SIMD path.
    pub build: String,
    /// FNV-1a of the running executable, when its commit does not identify it (a dirty tree).
    pub executable: Option<String>,
    /// The engine rendering the images.
    pub engine: String,
    /// The cases, in order.
    pub cases: Vec<CaseIdentity>,
}

/// What identifies a case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseIdentity {
    /// Its name in the report.
    pub name: String,
    /// FNV-1a of the scene's bytes, in hex.
    pub scene_hash: String,
    /// Its area lights (the jobs' costs depend on them).
    pub lights: usize,
    /// What is measured.
    pub config: StudyConfig,
}

/// The build as an identity names it.
fn build() -> (String, Option<String>) {
    let info = crate::output::build_info::current();
    let build = format!(
        "raywave {} commit {} simd {}",
        env!("CARGO_PKG_VERSION"),
        info.commit,
        crate::simd_path()
    );
    // Read and hashed once per process: the command line and the study both ask.
    static EXECUTABLE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    let executable = (info.dirty != Some(false)).then(|| {
        EXECUTABLE
            .get_or_init(|| {
                std::env::current_exe().and_then(std::fs::read).map_or_else(
                    |_| "unreadable".to_string(),
                    |b| crate::render::digest::hex(&b),
                )
            })
            .clone()
    });
    (build, executable)
}

/// The identity of a study of `cases` rendered by `engine`.
pub fn identity(cases: &[Case], engine: &str) -> StudyIdentity {
    let (build, executable) = build();
    StudyIdentity {
        format: PART_FORMAT,
        build,
        executable,
        engine: engine.to_string(),
        cases: cases
            .iter()
            .map(|c| CaseIdentity {
                name: c.name.clone(),
                scene_hash: crate::render::digest::hex(&c.bytes),
                lights: c.scene.lights.len(),
                config: c.config.clone(),
            })
            .collect(),
    }
}

impl StudyIdentity {
    /// Every job of the study, cases in order.
    pub fn jobs(&self) -> Vec<Job> {
        self.cases
            .iter()
            .enumerate()
            .flat_map(|(i, c)| jobs::case_jobs(i, &c.config))
            .collect()
    }

    /// The estimated cost of each of [`StudyIdentity::jobs`].
    pub fn costs(&self) -> Vec<f64> {
        self.jobs()
            .iter()
            .map(|j| {
                let c = &self.cases[j.case];
                jobs::cost(&c.config, c.lights, j)
            })
            .collect()
    }

    /// The job numbers of each of `count` shards.
    pub fn assignment(&self, count: usize) -> Vec<Vec<usize>> {
        crate::output::shard::partition(&self.costs(), count)
    }

    /// How `other` differs from this identity, in words; None when they are the same study.
    pub fn difference(&self, other: &StudyIdentity) -> Option<String> {
        if self == other {
            return None;
        }
        if self.format != other.format {
            return Some(format!(
                "part format {} against {}",
                self.format, other.format
            ));
        }
        // The SIMD path first: binaries built for two CPUs (`target-cpu=native` on two kinds of
        // node) can share a commit and differ only there.
        let simd = |build: &str| build.split_once(" simd ").map(|(_, path)| path.to_string());
        if simd(&self.build) != simd(&other.build) {
            return Some(format!(
                "different SIMD paths: {} against {} (run by {} against {}); run every shard \
                 with one build (for nodes of several CPUs, one built for the oldest: \
                 docs/SCALING.md)",
                simd(&self.build).unwrap_or_default(),
                simd(&other.build).unwrap_or_default(),
                self.build,
                other.build
            ));
        }
        if self.build != other.build || self.executable != other.executable {
            return Some(format!(
                "different raywave builds: {}{} against {}{}",
                self.build,
                self.executable
                    .as_ref()
                    .map_or(String::new(), |e| format!(" (executable {e})")),
                other.build,
                other
                    .executable
                    .as_ref()
                    .map_or(String::new(), |e| format!(" (executable {e})")),
            ));
        }
        if self.engine != other.engine {
            return Some(format!("engine {} against {}", self.engine, other.engine));
        }
        let names = |i: &StudyIdentity| {
            i.cases
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        if self.cases.len() != other.cases.len() {
            return Some(format!(
                "different studies: cases [{}] against [{}]",
                names(self),
                names(other)
            ));
        }
        for (a, b) in self.cases.iter().zip(&other.cases) {
            if a.name != b.name || a.scene_hash != b.scene_hash || a.lights != b.lights {
                return Some(format!(
                    "different studies: case {} (scene {}) against {} (scene {})",
                    a.name, a.scene_hash, b.name, b.scene_hash
                ));
            }
            if a.config != b.config {
                let json = |c: &StudyConfig| serde_json::to_value(c).unwrap_or_default();
                let (x, y) = (json(&a.config), json(&b.config));
                let differing: Vec<String> = x
                    .as_object()
                    .into_iter()
                    .flatten()
                    .filter(|(k, v)| y.get(k.as_str()) != Some(v))
                    .map(|(k, v)| {
                        format!("{k} {v} against {}", y.get(k.as_str()).unwrap_or_default())
                    })
                    .collect();
                return Some(format!(
                    "different studies: case {} has {}",
                    a.name,
                    differing.join("; ")
                ));
            }
        }
        Some("different studies".into())
    }
}

/// Names for cases: the scene's file stem (`builtin` for the built-in scene), with `-WxH`
/// when the study has several sizes, and `-2`, `-3`, ... for a name already taken.
pub fn case_names(stems: &[String], sizes: &[[u32; 2]]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for stem in stems {
        for [w, h] in sizes {
            let base = if sizes.len() > 1 {
                format!("{stem}-{w}x{h}")
            } else {
                stem.clone()
            };
            let mut name = base.clone();
            let mut k = 2;
            while names.contains(&name) {
                name = format!("{base}-{k}");
                k += 1;
            }
            names.push(name);
        }
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn case_names_are_unique_and_name_the_size_only_when_it_varies() {
        let stems = ["box".to_string(), "box".to_string(), "builtin".to_string()];
        assert_eq!(case_names(&stems, &[[8, 8]]), ["box", "box-2", "builtin"]);
        assert_eq!(
            case_names(&stems[..1], &[[8, 8], [16, 8]]),
            ["box-8x8", "box-16x8"]
        );
    }

    #[test]
    fn a_difference_names_what_differs() {
        let config = StudyConfig::standard(crate::render::settings::RenderSettings::default());
        let a = StudyIdentity {
            format: PART_FORMAT,
            build: "raywave 0.1.0 commit abc simd avx2".into(),
            executable: None,
            engine: "wavefront".into(),
            cases: vec![CaseIdentity {
                name: "box".into(),
                scene_hash: "01".into(),
                lights: 1,
                config: config.clone(),
            }],
        };
        assert_eq!(a.difference(&a.clone()), None);
        let mut b = a.clone();
        b.build = "raywave 0.1.0 commit def simd avx2".into();
        assert!(
            a.difference(&b)
                .unwrap()
                .contains("different raywave builds")
        );
        // Built for another CPU: the same commit, another SIMD path.
        let mut v3 = a.clone();
        v3.build = "raywave 0.1.0 commit abc simd avx2+fma (f32x8 in one 256-bit register)".into();
        let d = a.difference(&v3).unwrap();
        assert!(
            d.contains(
                "different SIMD paths: avx2 against avx2+fma (f32x8 in one 256-bit register)"
            ),
            "{d}"
        );
        let mut c = a.clone();
        c.cases[0].config.seeds = 9;
        let d = a.difference(&c).unwrap();
        assert!(d.contains("seeds 8 against 9"), "{d}");
        let mut e = a.clone();
        e.cases[0].scene_hash = "02".into();
        assert!(a.difference(&e).unwrap().contains("scene 01"));
    }
}
