//! The noise-free gate: instruction counts of the hot kernels under callgrind, against
//! committed baselines (`benches/baselines/icount.json`) with a tight threshold.
//!
//! ```text
//! runner (this test, in release builds):
//!     child = tests/gates/icount_child.rs, built by cargo for x86-64-v3 against the library
//!             alone (--no-default-features --features icount-child, in
//!             target/icount-x86-64-v3): valgrind runs x86-64-v3 code on every x86-64 machine
//!     valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*icount_region_*'
//!              --dump-after=...icount_region_NAME  <child>
//!     one dump per region → instructions per region; the child prints its key
//!     key = rustc version · target arch · enabled x86 features · valgrind version
//!     baseline for the key?  compare each region: rise > THRESHOLD fails, fall > THRESHOLD notes
//!     nothing compared (no baseline, no valgrind, a debug build)?  fail when CI is set, else
//!                            say why and pass
//! ```
//!
//! The workloads are the child's (its module docs list them). The child is a build of the
//! renderer and its few dependencies only, about a minute on 2 cores from nothing, where a
//! second build of this test with every dev-dependency took five.
//!
//! Re-record deliberately (after a change to a kernel, rustc, a dependency, or on a new
//! machine): `RAYWAVE_RECORD=1 cargo test --release --test gates icount`. It rewrites this
//! key's entry and keeps the others. See docs/BENCHMARKING.md ("The instruction-count gate").

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A region whose count rises by more than this fraction fails. Counts repeat exactly from run
/// to run on one machine (docs/TRIED.md); the threshold absorbs what the key does not
/// capture, chiefly glibc's `memset`/`memcpy`/`malloc`, which are picked per CPU at run time.
const THRESHOLD: f64 = 0.01;
/// The committed baselines.
const RECORD: &str = concat!(env!("RAYWAVE_REPO"), "/benches/baselines/icount.json");
/// The one command that re-records this machine's baselines.
const RECORD_COMMAND: &str = "RAYWAVE_RECORD=1 cargo test --release --test gates icount";
/// The regions, in the order the child runs them (the dumps come in this order).
const REGIONS: [&str; 9] = [
    "generate",
    "intersect",
    "shadow",
    "film",
    "reflect",
    "intersect_scalar",
    "reference",
    "intersect_mesh",
    "shadow_mesh",
];
/// `benches/baselines/icount.json`: instructions per region, per key.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
struct Baselines {
    how_to_update: String,
    threshold_percent: f64,
    baselines: BTreeMap<String, BTreeMap<String, u64>>,
}

/// The child's key and its instructions per region, in `REGIONS` order.
type Measured = (String, Vec<(&'static str, u64)>);

/// Runs `exe` (the child, built for `FIXED_TARGET`) under callgrind and returns
/// the child's key and (region, instructions) in `REGIONS` order, or the reason it could not.
fn measure(exe: &Path) -> Result<Measured, String> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let out_file = dir.path().join("callgrind.out");
    let output = Command::new("valgrind")
        .args([
            "--tool=callgrind",
            "--collect-atstart=no",
            "--toggle-collect=*icount_region_*",
        ])
        .args(
            // One exact name each: callgrind's --dump-after takes no wildcard.
            REGIONS.map(|r| format!("--dump-after={CHILD_CRATE}::icount_region_{r}")),
        )
        .arg(format!("--callgrind-out-file={}", out_file.display()))
        .arg(exe)
        .output()
        .expect("run valgrind");
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        if stderr.contains("unhandled instruction") || stderr.contains("unrecognised instruction") {
            return Err(format!(
                "valgrind cannot run {} (an instruction it does not emulate)\n{stderr}",
                exe.display()
            ));
        }
        panic!(
            "icount: the workloads failed under valgrind ({}):\n{}\n{stderr}",
            output.status,
            String::from_utf8_lossy(&output.stdout)
        );
    }
    // One part per dump (`callgrind.out.1`, `.2`, ...), then the final one at exit.
    let mut counts = Vec::new();
    for (i, region) in REGIONS.iter().enumerate() {
        let part = dir.path().join(format!("callgrind.out.{}", i + 1));
        let text = std::fs::read_to_string(&part).unwrap_or_else(|e| {
            panic!(
                "icount: no dump {} ({e}): was region {region} inlined or renamed?\n{stderr}",
                part.display()
            )
        });
        assert!(
            text.lines().any(|l| l.starts_with("desc: Trigger:")
                && l.trim_end().ends_with(&format!("::icount_region_{region}"))),
            "icount: dump {} is not region {region}:\n{}",
            i + 1,
            text.lines()
                .filter(|l| l.starts_with("desc:"))
                .collect::<Vec<_>>()
                .join("\n")
        );
        let total = text
            .lines()
            .find_map(|l| l.strip_prefix("summary:").or(l.strip_prefix("totals:")))
            .and_then(|v| v.split_whitespace().next()?.parse::<u64>().ok())
            .unwrap_or_else(|| panic!("icount: no total in {}", part.display()));
        assert!(total > 0, "icount: region {region} counted no instructions");
        counts.push((*region, total));
    }
    let stdout = String::from_utf8_lossy(&output.stdout);
    let key = stdout
        .lines()
        // The test harness's "test ... " may precede it on the same line.
        .find_map(|l| l.find(KEY_LINE).map(|i| &l[i + KEY_LINE.len()..]))
        .ok_or_else(|| format!("the child printed no `{KEY_LINE}` line:\n{stdout}"))?;
    Ok((key.to_string(), counts))
}

/// The CPU the gate measures for, whatever the machine: valgrind runs x86-64-v3 code on every
/// x86-64 machine it runs on (this machine's native AVX-512 build it cannot), so one baseline
/// serves them all.
const FIXED_TARGET: &str = "x86-64-v3";
/// Where the child is built: its own target directory, so that building it does not wait on
/// the lock of the `cargo test` that runs this, and its flags do not rebuild the test build.
const FIXED_TARGET_DIR: &str = concat!(env!("RAYWAVE_REPO"), "/target/icount-x86-64-v3");
/// The child's binary target (Cargo.toml) and the crate name its symbols carry.
const CHILD_BIN: &str = "raywave-icount-child";
const CHILD_CRATE: &str = "raywave_icount_child";
/// The line by which the child tells the runner its key.
const KEY_LINE: &str = "icount-key: ";

/// The child built for `FIXED_TARGET` by cargo: a release build of the library alone and
/// `tests/gates/icount_child.rs`, in `FIXED_TARGET_DIR` (about a minute the first time, then
/// nothing to do until the renderer changes).
fn fixed_target_child() -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = Command::new(cargo)
        .args([
            "build",
            "--release",
            "--package",
            "raywave",
            "--no-default-features",
            "--features",
            "icount-child",
            "--bin",
            CHILD_BIN,
            "--message-format=json",
        ])
        .current_dir(env!("RAYWAVE_REPO"))
        .env("RUSTFLAGS", format!("-C target-cpu={FIXED_TARGET}"))
        .env("CARGO_TARGET_DIR", FIXED_TARGET_DIR)
        .output()
        .map_err(|e| format!("cannot run cargo to build the {FIXED_TARGET} child: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "building the {FIXED_TARGET} child failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == CHILD_BIN)
        .find_map(|m| m["executable"].as_str().map(PathBuf::from))
        .ok_or_else(|| format!("cargo built no {CHILD_BIN} executable for {FIXED_TARGET}"))
}

/// A gate that did not compare is a pass on a developer's machine (with the reason printed) and
/// a failure in CI (`CI` set), where a silent pass would be a false green.
fn not_gated(why: &str) {
    let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false" && v != "0");
    assert!(!ci, "icount: the gate did not run, and CI is set: {why}");
    eprintln!("icount: SKIPPED: {why}");
}

/// A region's count against its baseline.
#[derive(Debug, PartialEq)]
enum Verdict {
    Within,
    Rose,
    Fell,
}

/// The relative change of `now` against `before`, and what the gate makes of it.
fn judge(before: u64, now: u64) -> (f64, Verdict) {
    let change = (now as f64 - before as f64) / before.max(1) as f64;
    let verdict = if change > THRESHOLD {
        Verdict::Rose
    } else if change < -THRESHOLD {
        Verdict::Fell
    } else {
        Verdict::Within
    };
    (change, verdict)
}

#[test]
fn the_threshold_is_one_percent_either_way() {
    assert_eq!(judge(1_000_000, 1_000_000).1, Verdict::Within);
    assert_eq!(judge(1_000_000, 1_010_000).1, Verdict::Within);
    assert_eq!(judge(1_000_000, 1_010_001).1, Verdict::Rose);
    assert_eq!(judge(1_000_000, 989_999).1, Verdict::Fell);
    assert_eq!(judge(1_000_000, 990_000).1, Verdict::Within);
}

#[test]
fn kernel_instruction_counts() {
    if cfg!(debug_assertions) {
        return not_gated("a debug build: the baselines are release counts (cargo test --release)");
    }
    let valgrind = Command::new("valgrind").arg("--version").output();
    if !valgrind.is_ok_and(|o| o.status.success()) {
        return not_gated(
            "valgrind is not installed (Debian: apt-get install valgrind; .ci/run installs it)",
        );
    }
    let child = match fixed_target_child() {
        Ok(child) => child,
        Err(why) => return not_gated(&why),
    };
    let (key, counts) = match measure(&child) {
        Ok(measured) => measured,
        Err(why) => return not_gated(&why),
    };
    let mut record: Baselines = std::fs::read_to_string(RECORD)
        .ok()
        .map(|text| serde_json::from_str(&text).unwrap_or_else(|e| panic!("icount: {RECORD}: {e}")))
        .unwrap_or_default();
    let baseline = record.baselines.get(&key);
    println!("icount: key {key}");
    println!(
        "{:<18} {:>14} {:>14} {:>9}",
        "region", "instructions", "baseline", "change"
    );
    let mut rose = Vec::new();
    let mut fell = Vec::new();
    for &(region, now) in &counts {
        let before = baseline.and_then(|b| b.get(region)).copied();
        let (cell, change) = match before {
            Some(b) => {
                let (change, verdict) = judge(b, now);
                match verdict {
                    Verdict::Rose => {
                        rose.push(format!("{region} {:+.2}% ({b} -> {now})", change * 100.0))
                    }
                    Verdict::Fell => fell.push(format!("{region} {:+.2}%", change * 100.0)),
                    Verdict::Within => {}
                }
                (b.to_string(), format!("{:+.2}%", change * 100.0))
            }
            None => ("-".into(), "-".into()),
        };
        println!("{region:<18} {now:>14} {cell:>14} {change:>9}");
    }

    if std::env::var_os("RAYWAVE_RECORD").is_some_and(|v| !v.is_empty() && v != "0") {
        record.how_to_update = format!(
            "Instruction counts of tests/gates/icount_child.rs per key, re-recorded deliberately with `{RECORD_COMMAND}`; see docs/BENCHMARKING.md"
        );
        record.threshold_percent = THRESHOLD * 100.0;
        record.baselines.insert(
            key.clone(),
            counts.iter().map(|&(r, n)| (r.to_string(), n)).collect(),
        );
        let text = serde_json::to_string_pretty(&record).expect("serialise") + "\n";
        let tmp = Path::new(RECORD).with_extension("json.tmp");
        std::fs::write(&tmp, text).expect("write the baselines");
        std::fs::rename(&tmp, RECORD).expect("replace the baselines");
        println!("icount: RAYWAVE_RECORD is set: wrote this key's counts to {RECORD}");
        return;
    }
    let Some(baseline) = baseline else {
        return not_gated(&format!(
            "NO BASELINE for this key in {RECORD}: nothing compared (every region ran under \
             callgrind). Keys recorded: {:?}. To record this one: {RECORD_COMMAND}",
            record.baselines.keys().collect::<Vec<_>>()
        ));
    };
    let missing: Vec<_> = REGIONS
        .iter()
        .filter(|r| !baseline.contains_key(**r))
        .collect();
    assert!(
        missing.is_empty(),
        "icount: regions {missing:?} have no baseline for this key: record them with {RECORD_COMMAND}"
    );
    if !fell.is_empty() {
        println!(
            "icount: fewer instructions than the baseline: {}; if meant, re-record to keep the gate tight: {RECORD_COMMAND}",
            fell.join(", ")
        );
    }
    assert!(
        rose.is_empty(),
        "icount: instruction counts ROSE by more than {:.1}%: {}. Counts are exact, so this is \
         a real change of the code or toolchain; if it is meant, re-record: {RECORD_COMMAND}",
        THRESHOLD * 100.0,
        rose.join(", ")
    );
    println!(
        "icount: every region within {:.1}% of its baseline",
        THRESHOLD * 100.0
    );
}
