//! A study over several cases (scene × image size), its identity and its job list: what every
//! shard of a study computes alike, and what a merge checks its parts against. The study is
//! the variance command's sharded work (`crate::shard::Work`).
//!
//! ```text
//! cases    = scenes × sizes, named by the scene's file stem (and the size, given several)
//! identity = crate::shard::Identity: the raywave build, and the Study: the engine and per
//!            case its name, scene bytes' hash, lights and settings
//! jobs     = per case in order: budgets × samplers (jobs::case_jobs), numbered across cases
//! shard i  = crate::shard::partition(costs of the jobs, count)[i]
//! ```

use crate::render::scene::Scene;
use crate::shard::{Identity, Work};
use crate::variance::StudyConfig;
use crate::variance::study::job_record::JobRecord;
use crate::variance::study::jobs::{self, CaseFacts, Job};
use serde::{Deserialize, Serialize};

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

/// What makes two runs parts of the same study, besides the build.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Study {
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

/// The identity of a study of `cases` rendered by `engine`.
pub fn identity(cases: &[Case], engine: &str) -> Identity<Study> {
    let study = Study {
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
    };
    Identity::current(crate::simd_path(), study)
}

impl Study {
    /// Every job of the study, cases in order.
    pub fn jobs(&self) -> Vec<Job> {
        self.cases
            .iter()
            .enumerate()
            .flat_map(|(i, c)| jobs::case_jobs(i, &c.config))
            .collect()
    }

    /// The job numbers of each of `count` shards.
    pub fn assignment(&self, count: usize) -> Vec<Vec<usize>> {
        crate::shard::partition(&self.costs(), count)
    }
}

impl Work for Study {
    const KIND: &'static str = "variance";
    const NOUN: &'static str = "study";
    const COMMAND: &'static str = "raywave variance --shard I/N";
    const SAME_RUN: &'static str = "run every shard with the same scenes and flags";
    type Result = JobRecord;
    /// Per case the part touched: the case's number, where its scene came from, its facts.
    type Extra = Vec<(usize, String, CaseFacts)>;

    fn costs(&self) -> Vec<f64> {
        self.jobs()
            .iter()
            .map(|j| {
                let c = &self.cases[j.case];
                jobs::cost(&c.config, c.lights, j)
            })
            .collect()
    }

    fn differences(&self, other: &Study, a: &str, b: &str) -> Vec<String> {
        let mut out = Vec::new();
        if self.engine != other.engine {
            out.push(format!("engine: {} {a}, {} {b}", self.engine, other.engine));
        }
        let names = |s: &Study| {
            let v: Vec<&str> = s.cases.iter().map(|c| c.name.as_str()).collect();
            format!("[{}]", v.join(", "))
        };
        if self.cases.len() != other.cases.len() {
            out.push(format!("cases: {} {a}, {} {b}", names(self), names(other)));
            return out;
        }
        for (x, y) in self.cases.iter().zip(&other.cases) {
            if x.name != y.name || x.scene_hash != y.scene_hash || x.lights != y.lights {
                out.push(format!(
                    "case: {} (scene {}) {a}, {} (scene {}) {b}",
                    x.name, x.scene_hash, y.name, y.scene_hash
                ));
                continue;
            }
            let json = |c: &StudyConfig| serde_json::to_value(c).unwrap_or_default();
            let (p, q) = (json(&x.config), json(&y.config));
            for (k, v) in p.as_object().into_iter().flatten() {
                let w = q.get(k.as_str()).cloned().unwrap_or_default();
                if *v != w {
                    out.push(format!("case {}: {k}: {v} {a}, {w} {b}", x.name));
                }
            }
        }
        out
    }

    fn check_results(
        identity: &Identity<Study>,
        items: &[usize],
        results: &[JobRecord],
    ) -> Option<String> {
        let all = identity.work.jobs();
        let differs = items
            .iter()
            .zip(results)
            .any(|(&j, r)| all.get(j) != Some(&r.job));
        differs.then(|| {
            format!(
                "its results are not those of its {} jobs: was it edited, or written by another \
                 raywave?",
                items.len()
            )
        })
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
        let a = Study {
            engine: "wavefront".into(),
            cases: vec![CaseIdentity {
                name: "box".into(),
                scene_hash: "01".into(),
                lights: 1,
                config: config.clone(),
            }],
        };
        assert!(a.differences(&a.clone(), "in A", "in B").is_empty());
        let mut c = a.clone();
        c.cases[0].config.seeds = 9;
        assert_eq!(
            a.differences(&c, "in A", "in B"),
            ["case box: seeds: 8 in A, 9 in B"]
        );
        let mut e = a.clone();
        e.cases[0].scene_hash = "02".into();
        let d = a.differences(&e, "in A", "in B");
        assert_eq!(d, ["case: box (scene 01) in A, box (scene 02) in B"]);
        let mut f = a.clone();
        f.engine = "reference".into();
        f.cases.push(f.cases[0].clone());
        let d = a.differences(&f, "in A", "in B");
        assert_eq!(
            d,
            [
                "engine: wavefront in A, reference in B",
                "cases: [box] in A, [box, box] in B"
            ]
        );
    }
}
