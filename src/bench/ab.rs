//! `raywave bench --against OTHER`: two builds timed alternately on one machine, round after
//! round, and a verdict from the paired rounds.
//!
//! A saved record cannot beat a shared machine's drift (the same binary's frame time moves by
//! 20–35% between invocations minutes apart); two builds run in alternation see the same drift,
//! and the ratio of a round's two times cancels most of it.
//!
//! ```text
//! check OTHER is an executable file; resolve this build's path
//! warm-up: W untimed rounds (and a check that both builds accept the flags)
//! for round in 1..=R: this then OTHER on odd rounds, OTHER then this on even ones
//!     each run: `BUILD render SCENE FLAGS --engine E --threads T -q -o tmp --stats-json tmp`,
//!               its render seconds from the JSON (parsing and file writing excluded)
//!     ratio_r = this_r / other_r
//! per engine: median ratio, 95% interval of the median from order statistics (no resampling),
//!             verdict against the threshold t:
//!     slower  when the whole interval lies above 1 + t   → exit 3
//!     faster  when it lies below 1 / (1 + t)
//!     within  when it lies inside [1 / (1 + t), 1 + t]
//!     undecided otherwise (the interval straddles a boundary: more rounds narrow it)
//! ```
//!
//! The interval is distribution-free (`statistics::median_interval_rank`): for n paired ratios
//! sorted, the median lies between the k-th and the (n − k + 1)-th with probability ≥ 95%, k the
//! largest with P(Binomial(n, ½) < k) ≤ 2.5%. It needs n ≥ 6.

use crate::output::statistics::{MIN_FOR_INTERVAL, median, median_with_interval};
use crate::render::engine::Engine;
use crate::render::error::UsageError;
use anyhow::{Context, Result, bail};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The fewest rounds that give a 95% interval of the median.
pub const MIN_ROUNDS: u32 = MIN_FOR_INTERVAL as u32;

/// What an A/B run is asked to do.
#[derive(Clone, Debug)]
pub struct AbOptions {
    /// The other build's binary (the baseline: ratios are this build over it).
    pub other: PathBuf,
    /// Scene file (`None`: each build's built-in default scene).
    pub scene: Option<PathBuf>,
    /// The image flags exactly as both builds are to get them (`--size 1024 1024`, ...).
    pub render_flags: Vec<String>,
    /// The engines to time, each in its own rounds.
    pub engines: Vec<Engine>,
    /// Worker threads (`None`: each build's default, all cores).
    pub threads: Option<u32>,
    /// Timed rounds per engine (at least [`MIN_ROUNDS`]).
    pub rounds: u32,
    /// Untimed rounds first.
    pub warmup: u32,
    /// Regression threshold in percent.
    pub threshold_pct: f64,
    /// Print only the verdict table.
    pub quiet: bool,
}

/// What the rounds of one engine gave.
#[derive(Clone, Debug, PartialEq)]
pub struct EngineAb {
    /// The engine.
    pub engine: Engine,
    /// This build's render seconds, in round order.
    pub this: Vec<f64>,
    /// The other build's render seconds, in round order.
    pub other: Vec<f64>,
    /// The ray counts (camera, shadow, reflection, total) of this build and the other in the
    /// first round where they differed: the builds then did different work.
    pub different_work: Option<(String, String)>,
}

/// How a ratio's interval sits against the threshold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The whole interval lies above 1 + t: a regression.
    Slower,
    /// The whole interval lies below 1 / (1 + t).
    Faster,
    /// The whole interval lies within [1 / (1 + t), 1 + t]: no change as large as t.
    Within,
    /// The interval straddles a boundary: more rounds are needed to decide.
    Undecided,
}

/// A ratio's summary: median, 95% interval, verdict.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RatioSummary {
    /// Median of the per-round ratios this / other.
    pub median: f64,
    /// The 95% interval of that median.
    pub low: f64,
    /// The 95% interval of that median.
    pub high: f64,
    /// Against the threshold.
    pub verdict: Verdict,
}

impl EngineAb {
    /// Per-round ratios this / other.
    pub fn ratios(&self) -> Vec<f64> {
        self.this
            .iter()
            .zip(&self.other)
            .map(|(a, b)| a / b)
            .collect()
    }

    /// The ratios' median, interval and verdict at `threshold_pct`.
    pub fn summary(&self, threshold_pct: f64) -> RatioSummary {
        summarize(&self.ratios(), threshold_pct)
    }
}

/// Median, 95% interval and verdict of per-round ratios.
pub fn summarize(ratios: &[f64], threshold_pct: f64) -> RatioSummary {
    let (median, low, high) = median_with_interval(ratios);
    let slow = 1.0 + threshold_pct / 100.0;
    let verdict = if low > slow {
        Verdict::Slower
    } else if high < 1.0 / slow {
        Verdict::Faster
    } else if low >= 1.0 / slow && high <= slow {
        Verdict::Within
    } else {
        Verdict::Undecided
    };
    RatioSummary {
        median,
        low,
        high,
        verdict,
    }
}

/// Refuses a path that is not an executable regular file, before any work.
fn check_executable(path: &Path) -> Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let meta = std::fs::metadata(path).map_err(|e| {
        UsageError(format!(
            "--against {}: expected an executable raywave binary: {e}",
            path.display()
        ))
    })?;
    if !meta.is_file() || meta.permissions().mode() & 0o111 == 0 {
        return Err(UsageError(format!(
            "--against {}: expected an executable raywave binary, found {}",
            path.display(),
            if meta.is_file() {
                "a file that is not executable"
            } else {
                "something that is not a regular file"
            }
        ))
        .into());
    }
    Ok(())
}

/// One timed render by `binary`: its render seconds and ray counts (as JSON text).
fn time_one(
    binary: &Path,
    options: &AbOptions,
    engine: Engine,
    scratch: &Path,
) -> Result<(f64, String)> {
    let json = scratch.join("stats.json");
    let mut cmd = Command::new(binary);
    cmd.arg("render");
    if let Some(scene) = &options.scene {
        cmd.arg(scene);
    }
    cmd.args(&options.render_flags)
        .args(["--engine", engine.name(), "-q"])
        .arg("-o")
        // PPM: every build writes it, and cheaply (the write is not timed either way).
        .arg(scratch.join("image.ppm"))
        .arg("--stats-json")
        .arg(&json);
    if let Some(t) = options.threads {
        cmd.args(["--threads", &t.to_string()]);
    }
    let out = cmd
        .output()
        .with_context(|| format!("cannot run {}", binary.display()))?;
    if !out.status.success() {
        let args: Vec<OsString> = cmd.get_args().map(OsString::from).collect();
        bail!(
            "{} failed ({}) on `render {}`:\n{}",
            binary.display(),
            out.status,
            args[1..]
                .iter()
                .map(|a| a.to_string_lossy())
                .collect::<Vec<_>>()
                .join(" "),
            String::from_utf8_lossy(&out.stderr).trim_end()
        );
    }
    let text = std::fs::read_to_string(&json)
        .with_context(|| format!("{} wrote no --stats-json", binary.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}'s --stats-json is not JSON: is it a raywave binary?",
            binary.display()
        )
    })?;
    let seconds = value["seconds"]
        .as_f64()
        .filter(|s| *s > 0.0)
        .with_context(|| {
            format!(
                "{}'s --stats-json has no positive `seconds`: is it a raywave binary?",
                binary.display()
            )
        })?;
    // The ray counts by kind, without the rates (which differ from run to run).
    let counts = ["camera", "shadow", "reflection", "total"]
        .map(|kind| {
            value["rays"][kind]["rays"]
                .as_u64()
                .unwrap_or(u64::MAX)
                .to_string()
        })
        .join(" ");
    Ok((seconds, counts))
}

/// Runs the rounds; `progress` is called after each run with (runs done, runs in all).
pub fn run(options: &AbOptions, progress: &dyn Fn(u64, u64)) -> Result<Vec<EngineAb>> {
    if options.rounds < MIN_ROUNDS {
        return Err(UsageError(format!(
            "--rounds {}: a 95% interval of the median needs at least {MIN_ROUNDS} rounds",
            options.rounds
        ))
        .into());
    }
    check_executable(&options.other)?;
    let this = std::env::current_exe().context("cannot find this build's own binary")?;
    let scratch = tempfile::tempdir().context("cannot make a scratch directory")?;
    let total = options.engines.len() as u64 * u64::from(options.warmup + options.rounds) * 2;
    let mut done = 0;
    let mut results = Vec::new();
    for &engine in &options.engines {
        let mut result = EngineAb {
            engine,
            this: Vec::new(),
            other: Vec::new(),
            different_work: None,
        };
        for round in 0..options.warmup + options.rounds {
            // Alternate which build goes first, so that neither always runs on a warmer or
            // cooler machine.
            let order = if round % 2 == 0 {
                [&this, &options.other]
            } else {
                [&options.other, &this]
            };
            let mut times = [(0.0, String::new()), (0.0, String::new())];
            for (slot, binary) in order.into_iter().enumerate() {
                times[slot] = time_one(binary, options, engine, scratch.path())?;
                done += 1;
                progress(done, total);
            }
            let (mine, theirs) = if round % 2 == 0 {
                (&times[0], &times[1])
            } else {
                (&times[1], &times[0])
            };
            if mine.1 != theirs.1 && result.different_work.is_none() {
                result.different_work = Some((mine.1.clone(), theirs.1.clone()));
            }
            if round >= options.warmup {
                result.this.push(mine.0);
                result.other.push(theirs.0);
            }
        }
        results.push(result);
    }
    Ok(results)
}

/// The verdict table.
pub fn report(options: &AbOptions, results: &[EngineAb]) -> String {
    let t = options.threshold_pct;
    let mut out = format!(
        "this build / {} · {} rounds after {} warm-up, alternating · threshold {t}%\n\
         {:<10} {:>25} {:>25} {:>8} {:>18}  verdict\n",
        options.other.display(),
        options.rounds,
        options.warmup,
        "engine",
        "this: median (min–max)",
        "other: median (min–max)",
        "ratio",
        "95% interval",
    );
    for r in results {
        let s = r.summary(t);
        let spread = |xs: &[f64]| {
            let (lo, hi) = xs
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                });
            format!("{:.4} s ({:.3}–{:.3})", median(xs), lo, hi)
        };
        let verdict = match s.verdict {
            Verdict::Slower => format!("slower by more than {t}%: a regression"),
            Verdict::Faster => format!("faster by more than {t}%"),
            Verdict::Within => format!("no change beyond {t}%"),
            Verdict::Undecided => {
                "undecided: the interval crosses the threshold; run more rounds".to_string()
            }
        };
        out += &format!(
            "{:<10} {:>25} {:>25} {:>8.4} {:>18}  {verdict}\n",
            r.engine.name(),
            spread(&r.this),
            spread(&r.other),
            s.median,
            format!("[{:.4}, {:.4}]", s.low, s.high),
        );
        if let Some((mine, theirs)) = &r.different_work {
            out += &format!(
                "  warning: the builds traced different rays with {} (camera, shadow, \
                 reflection, total: this {mine}, other {theirs}): the ratio compares \
                 different work\n",
                r.engine.name()
            );
        }
    }
    out
}

/// True when some engine's verdict is a regression.
pub fn regressed(options: &AbOptions, results: &[EngineAb]) -> bool {
    results
        .iter()
        .any(|r| r.summary(options.threshold_pct).verdict == Verdict::Slower)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_follow_the_whole_interval() {
        let around = |centre: f64, spread: f64| -> Vec<f64> {
            (0..20)
                .map(|i| centre + spread * (i as f64 / 19.0 - 0.5))
                .collect()
        };
        assert_eq!(summarize(&around(1.10, 0.02), 5.0).verdict, Verdict::Slower);
        assert_eq!(summarize(&around(0.90, 0.02), 5.0).verdict, Verdict::Faster);
        assert_eq!(summarize(&around(1.00, 0.02), 5.0).verdict, Verdict::Within);
        // A 5% slowdown inside a wide spread is not called a regression.
        assert_eq!(
            summarize(&around(1.05, 0.30), 5.0).verdict,
            Verdict::Undecided
        );
        // Too few rounds give an unbounded interval: never a verdict.
        assert_eq!(summarize(&[2.0; 5], 5.0).verdict, Verdict::Undecided);
        let s = summarize(&around(1.10, 0.02), 5.0);
        assert!(s.low <= s.median && s.median <= s.high);
    }

    /// The interval's ends are the sign test's order statistics, known by hand: for the 20
    /// ratios 1 + i/64 (i = 0..20, given in reverse), rank 6, so the 6th and the 15th smallest,
    /// 1 + 5/64 and 1 + 14/64, around the median 1 + 9.5/64 (all exact in binary). A threshold
    /// whose bound equals the low end does not call a slowdown; one just below it does.
    #[test]
    fn the_interval_ends_are_the_sign_tests_order_statistics() {
        let ratios: Vec<f64> = (0..20).rev().map(|i| 1.0 + i as f64 / 64.0).collect();
        let s = summarize(&ratios, 5.0);
        assert_eq!(
            (s.low, s.median, s.high),
            (1.0 + 5.0 / 64.0, 1.0 + 9.5 / 64.0, 1.0 + 14.0 / 64.0)
        );
        assert_eq!(s.verdict, Verdict::Slower);
        let at_low_end = 100.0 * 5.0 / 64.0;
        assert_ne!(summarize(&ratios, at_low_end).verdict, Verdict::Slower);
        assert_eq!(
            summarize(&ratios, at_low_end * 0.999).verdict,
            Verdict::Slower
        );
    }
}
