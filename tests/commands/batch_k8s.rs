//! The Kubernetes Jobs of docs/scaling/variance-job.yaml (not run here): each validates
//! against the API's JSON Schema of a batch/v1 Job (`k8s/job-batch-v1.json`, strict: a
//! misspelt field fails; see `k8s/README.md` for its origin), and together they follow the
//! rules the schema cannot state: those the API server enforces (a Job's pods restart Never or
//! OnFailure, an enum's values, mounts name volumes of the pod, `$(VAR)` expands only a
//! declared variable) and those the study needs (the shard count in `--shard` equal to the
//! Job's completions, one cache for prepare and the shards, merge reading the shards'
//! folder). Doctored copies of the manifest fail, one for each rule.
//!
//! Needs a python3 with the `yaml` and `jsonschema` modules (Debian: python3-yaml,
//! python3-jsonschema; `.ci/run` installs them). Without one the test prints SKIPPED and
//! passes, unless CI is set: then it fails.

use crate::common;

use common::skip::skip_or_fail;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn manifest() -> PathBuf {
    Path::new(env!("RAYWAVE_REPO")).join("docs/scaling/variance-job.yaml")
}

fn schema() -> PathBuf {
    Path::new(env!("RAYWAVE_REPO")).join("tests/commands/k8s/job-batch-v1.json")
}

/// Reads YAML documents from stdin and prints `{"docs": [...], "violations": [...]}`: each
/// document as JSON, and each way one breaks the schema. The schema's `$schema` names no
/// draft; its keywords are OpenAPI v2's, a subset of draft 4, so draft 4 it is.
const VALIDATE: &str = r#"
import json, sys, yaml
from jsonschema import Draft4Validator
with open(sys.argv[1]) as f:
    schema = json.load(f)
Draft4Validator.check_schema(schema)
out = {"docs": [], "violations": []}
try:
    docs = [d for d in yaml.safe_load_all(sys.stdin) if d is not None]
except yaml.YAMLError as e:
    out["violations"].append("not YAML: %s" % e)
    docs = []
for i, doc in enumerate(docs):
    out["docs"].append(doc)
    for e in Draft4Validator(schema).iter_errors(doc):
        path = "/".join(map(str, e.absolute_path))
        out["violations"].append("document %d: %s at /%s" % (i + 1, e.message, path))
print(json.dumps(out, default=str))
"#;

/// The first python3 (on the PATH, then Debian's) with both modules; None, having said why,
/// when none has them outside CI.
fn python() -> Option<&'static str> {
    let found = ["python3", "/usr/bin/python3"].into_iter().find(|p| {
        std::process::Command::new(p)
            .args(["-c", "import yaml, jsonschema"])
            .output()
            .is_ok_and(|o| o.status.success())
    });
    if found.is_none() {
        skip_or_fail(
            "no python3 has the yaml and jsonschema modules (Debian: python3-yaml, \
             python3-jsonschema)",
        );
    }
    found
}

/// The documents of `yaml`, and every way they break the schema.
fn parse_and_validate(python: &str, yaml: &str) -> (Vec<Value>, Vec<String>) {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let mut child = Command::new(python)
        .args(["-c", VALIDATE])
        .arg(schema())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {python}: {e}"));
    child
        .stdin
        .take()
        .unwrap()
        .write_all(yaml.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "the validator failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let docs = report["docs"].as_array().unwrap().clone();
    let violations = report["violations"].as_array().unwrap();
    (
        docs,
        violations
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect(),
    )
}

/// The value after `flag` in `args`.
fn flag<'a>(args: &'a [&str], flag: &str) -> Option<&'a str> {
    args.iter()
        .position(|a| *a == flag)
        .and_then(|i| args.get(i + 1).copied())
}

/// The pod's volume (its JSON) that `path` lies on, through the container's mounts.
fn volume_of<'a>(pod: &'a Value, mounts: &[Value], path: &str) -> Option<&'a Value> {
    let mount = mounts.iter().find(|m| {
        let dir = m["mountPath"].as_str().unwrap_or("");
        Path::new(path).starts_with(dir) && !dir.is_empty()
    })?;
    pod["volumes"]
        .as_array()?
        .iter()
        .find(|v| v["name"] == mount["name"])
}

/// One Job's container, seen through the rules every Job here follows.
struct Step<'a> {
    pod: &'a Value,
    mounts: Vec<Value>,
    args: Vec<&'a str>,
}

impl Step<'_> {
    /// The PVC claim `path` lies on, if it lies on one.
    fn claim(&self, path: &str) -> Option<String> {
        let v = volume_of(self.pod, &self.mounts, path)?;
        Some(
            v["persistentVolumeClaim"]["claimName"]
                .as_str()?
                .to_string(),
        )
    }

    /// The ConfigMap `path` lies on, if it lies on one.
    fn config_map(&self, path: &str) -> Option<String> {
        let v = volume_of(self.pod, &self.mounts, path)?;
        Some(v["configMap"]["name"].as_str()?.to_string())
    }
}

/// Everything the three Jobs break of the rules in the module's doc (empty: none).
fn rule_violations(docs: &[Value]) -> Vec<String> {
    let mut bad = Vec::new();
    let labels: Vec<&str> = docs
        .iter()
        .map(|d| {
            d["metadata"]["labels"]["raywave-step"]
                .as_str()
                .unwrap_or("?")
        })
        .collect();
    if labels != ["prepare", "shards", "merge"] {
        return vec![format!(
            "the Jobs' raywave-step labels are {labels:?}, not prepare, shards, merge"
        )];
    }
    let mut steps = Vec::new();
    for (doc, label) in docs.iter().zip(&labels) {
        let pod = &doc["spec"]["template"]["spec"];
        if !matches!(pod["restartPolicy"].as_str(), Some("Never" | "OnFailure")) {
            bad.push(format!(
                "{label}: a Job's restartPolicy must be Never or OnFailure"
            ));
        }
        let containers = pod["containers"]
            .as_array()
            .map_or(&[][..], |c| c.as_slice());
        let [container] = containers else {
            bad.push(format!("{label}: {} containers, not one", containers.len()));
            continue;
        };
        let mounts = container["volumeMounts"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        for m in &mounts {
            let named = pod["volumes"]
                .as_array()
                .is_some_and(|v| v.iter().any(|v| v["name"] == m["name"]));
            if !named {
                bad.push(format!(
                    "{label}: the mount {} names no volume of the pod",
                    m["name"]
                ));
            }
        }
        let args: Vec<&str> = container["args"]
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_str).collect())
            .unwrap_or_default();
        if args.first() != Some(&"variance") {
            bad.push(format!(
                "{label}: the arguments {args:?} are not `variance ...`"
            ));
        }
        // $(VAR) in args expands only a variable declared in the container's env.
        let declared: Vec<&str> = container["env"]
            .as_array()
            .map(|e| e.iter().filter_map(|v| v["name"].as_str()).collect())
            .unwrap_or_default();
        for arg in &args {
            for var in arg.split("$(").skip(1).filter_map(|s| s.split(')').next()) {
                if !declared.contains(&var) {
                    bad.push(format!(
                        "{label}: {arg:?} refers to $({var}), which env does not declare"
                    ));
                }
            }
        }
        let spec = &doc["spec"];
        let indexed = spec["completionMode"].as_str().unwrap_or("NonIndexed");
        if !matches!(indexed, "NonIndexed" | "Indexed") {
            bad.push(format!(
                "{label}: completionMode {indexed:?} is neither NonIndexed nor Indexed"
            ));
        }
        if (*label == "shards") != (indexed == "Indexed") {
            bad.push(format!(
                "{label}: completionMode {indexed}; only the shards are Indexed"
            ));
        }
        steps.push(Step { pod, mounts, args });
    }
    if !bad.is_empty() || steps.len() != 3 {
        return bad;
    }
    let [prepare, shards, merge] = &steps[..] else {
        unreachable!()
    };

    // The shards: one pod per shard, all at once, each told its own index of the same count.
    let spec = &docs[1]["spec"];
    let completions = spec["completions"].as_u64().unwrap_or(0);
    if spec["parallelism"].as_u64() != Some(completions) {
        bad.push(format!(
            "shards: parallelism is not completions ({completions}): every shard at once"
        ));
    }
    let expected = format!("$(JOB_COMPLETION_INDEX)/{completions}");
    if flag(&shards.args, "--shard") != Some(expected.as_str()) {
        bad.push(format!(
            "shards: --shard is {:?}, not {expected:?}",
            flag(&shards.args, "--shard")
        ));
    }
    let env = docs[1]["spec"]["template"]["spec"]["containers"][0]["env"].as_array();
    let index = env.and_then(|e| e.iter().find(|v| v["name"] == "JOB_COMPLETION_INDEX"));
    let source = index.map(|v| &v["valueFrom"]["fieldRef"]["fieldPath"]);
    if source.and_then(Value::as_str)
        != Some("metadata.annotations['batch.kubernetes.io/job-completion-index']")
    {
        bad.push(
            "shards: JOB_COMPLETION_INDEX is not the pod's completion-index annotation".into(),
        );
    }

    // One study file, one cache, and the parts' folder, all on the same shared claim.
    let study = flag(&prepare.args, "--study");
    let cache = flag(&prepare.args, "--cache");
    let (Some(study), Some(cache)) = (study, cache) else {
        bad.push("prepare: no --study or no --cache".into());
        return bad;
    };
    if flag(&shards.args, "--study") != Some(study) || flag(&shards.args, "--cache") != Some(cache)
    {
        bad.push(format!(
            "shards: not the --study {study} and --cache {cache} of prepare"
        ));
    }
    for (label, step) in [("prepare", prepare), ("shards", shards)] {
        if step.config_map(study).is_none() {
            bad.push(format!(
                "{label}: --study {study} is not on a ConfigMap volume"
            ));
        }
    }
    let claim = prepare.claim(cache);
    let parts = flag(&shards.args, "--out").unwrap_or("?");
    let report = flag(&merge.args, "--out").unwrap_or("?");
    let inputs: Vec<&str> = merge.args[2..]
        .iter()
        .take_while(|a| !a.starts_with("--"))
        .copied()
        .collect();
    if merge.args.get(1) != Some(&"merge") || inputs != [parts] {
        bad.push(format!(
            "merge: {:?} does not merge the shards' --out {parts}",
            merge.args
        ));
    }
    let on_claim = [
        ("prepare's --cache", prepare.claim(cache)),
        ("the shards' --cache", shards.claim(cache)),
        ("the shards' --out", shards.claim(parts)),
        ("merge's parts", merge.claim(parts)),
        ("merge's --out", merge.claim(report)),
    ];
    for (what, c) in on_claim {
        if c.is_none() || c != claim {
            bad.push(format!(
                "{what} is on {c:?}, not on prepare's cache claim {claim:?}"
            ));
        }
    }
    bad
}

/// Everything wrong with the manifest text `yaml`: schema violations, then broken rules.
fn problems(python: &str, yaml: &str) -> Vec<String> {
    let (docs, mut v) = parse_and_validate(python, yaml);
    if v.is_empty() {
        v.extend(rule_violations(&docs));
    }
    v
}

#[test]
fn the_variance_jobs_validate_and_agree() {
    let Some(python) = python() else { return };
    let text = std::fs::read_to_string(manifest()).unwrap();
    let v = problems(python, &text);
    assert!(v.is_empty(), "{}:\n{}", manifest().display(), v.join("\n"));
}

#[test]
fn doctored_manifests_do_not_validate() {
    let Some(python) = python() else { return };
    let text = std::fs::read_to_string(manifest()).unwrap();
    // (what, the text replaced, its replacement): the first occurrence only.
    let doctored = [
        (
            "a misspelt completion mode",
            "completionMode: Indexed",
            "completionMode: Indexd",
        ),
        (
            "a misspelt field",
            "completionMode: Indexed",
            "completionModes: Indexed",
        ),
        (
            "a count that is text",
            "completions: 4",
            "completions: \"4\"",
        ),
        ("more pods than shards", "completions: 4", "completions: 5"),
        ("shards one at a time", "parallelism: 4", "parallelism: 1"),
        (
            "pods that restart forever",
            "restartPolicy: Never",
            "restartPolicy: Always",
        ),
        (
            "an index no one expands",
            "\"$(JOB_COMPLETION_INDEX)/4\"",
            "\"$JOB_COMPLETION_INDEX/4\"",
        ),
        (
            "an undeclared index",
            "- name: JOB_COMPLETION_INDEX",
            "- name: JOB_INDEX",
        ),
        (
            "shards with a cache of their own",
            "\"--shard\", \"$(JOB_COMPLETION_INDEX)/4\",\n                 \"--cache\", \"/shared/cache\"",
            "\"--shard\", \"$(JOB_COMPLETION_INDEX)/4\",\n                 \"--cache\", \"/tmp/cache\"",
        ),
        (
            "merge reading another folder",
            "\"merge\", \"/shared/parts\"",
            "\"merge\", \"/shared/part\"",
        ),
        (
            "a mount with no volume",
            "{name: shared, mountPath: /shared}",
            "{name: shard, mountPath: /shared}",
        ),
        (
            "a study not on the ConfigMap",
            "{name: study, mountPath: /study, readOnly: true}",
            "{name: shared, mountPath: /study, readOnly: true}",
        ),
        ("broken YAML", "  completions: 4", " completions: 4"),
    ];
    for (what, from, to) in doctored {
        let changed = text.replacen(from, to, 1);
        assert_ne!(changed, text, "{what}: the manifest has no {from:?}");
        assert!(!problems(python, &changed).is_empty(), "{what} validated");
    }
}
