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
//! per engine: median ratio, its 95% interval (order statistics, no resampling; n ≥ 6:
//!             `stats::median_interval_rank_at`) and the verdict against the threshold t
//!             (`Rule::judge`; the words in verdict.rs). Slower → exit 3 in both forms
//! ```
//!
//! The default form asks a pull request's one question, "is this build slower than the other by
//! more than t?", so a build about t faster is decided as soon as its interval's high end is at
//! or below 1 + t; the three-way form must also place it on one side of 1 / (1 + t), which it
//! straddles for as long as the rounds go on.
//!
//! With `--until-decided` the rounds go on until the verdict is decided, judged at planned
//! looks with narrower levels (`sequential`), within `--max-rounds` and `--max-time`.

use super::running::sequential::{self, Budget};
use super::verdict::{RatioSummary, Rule, Verdict, summarize_at};
use super::{EXIT_REGRESSION, EXIT_UNDECIDED};
use crate::render::engine::Engine;
use crate::render::error::UsageError;
use crate::render::progress::Progress;
use crate::stats::looks::{self, LookPlan};
use crate::stats::{MIN_FOR_INTERVAL, median};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

pub use super::ab_report::report;

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
    /// Timed rounds per engine (at least [`MIN_ROUNDS`]); unused with `until_decided`.
    pub rounds: u32,
    /// Rounds until each engine's verdict is decided, within this budget, instead of `rounds`.
    pub until_decided: Option<Budget>,
    /// Untimed rounds first.
    pub warmup: u32,
    /// The threshold and which verdicts it may reach.
    pub rule: Rule,
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
    /// With `--until-decided`: the looks taken, the rounds used and why they stopped.
    pub sequential: Option<sequential::Outcome>,
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

    /// The ratios' median, 95% interval and verdict by `rule`; with `--until-decided`, the
    /// last look's instead (at its level, judged by the same rule), or an unbounded undecided
    /// interval when no look was taken.
    pub fn summary(&self, rule: Rule) -> RatioSummary {
        match &self.sequential {
            None => summarize_at(&self.ratios(), rule, looks::ALPHA),
            Some(outcome) => outcome.looks.last().map_or(
                RatioSummary {
                    median: median(&self.ratios()),
                    low: f64::NEG_INFINITY,
                    high: f64::INFINITY,
                    verdict: Verdict::Undecided,
                },
                |look| look.summary,
            ),
        }
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
        bail!(UsageError(format!(
            "--against {}: expected an executable raywave binary, found {}",
            path.display(),
            if meta.is_file() {
                "a file that is not executable"
            } else {
                "something that is not a regular file"
            }
        )));
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
    let shown = binary.display();
    let out = cmd
        .output()
        .with_context(|| format!("cannot run {shown}"))?;
    if !out.status.success() {
        let args: Vec<_> = cmd
            .get_args()
            .skip(1)
            .map(|a| a.to_string_lossy())
            .collect();
        bail!(
            "{shown} failed ({}) on `render {}`:\n{}",
            out.status,
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim_end()
        );
    }
    let text =
        std::fs::read_to_string(&json).with_context(|| format!("{shown} wrote no --stats-json"))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{shown}'s --stats-json is not JSON: is it a raywave binary?"))?;
    let seconds = (value["seconds"].as_f64().filter(|s| *s > 0.0)).with_context(|| {
        format!("{shown}'s --stats-json has no positive `seconds`: is it a raywave binary?")
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

/// Runs the rounds, reporting each run to `progress` (of the runs in all; with `until_decided`,
/// all that `max_rounds` allows).
pub fn run(options: &AbOptions, progress: &Progress) -> Result<Vec<EngineAb>> {
    let timed = match options.until_decided {
        None => ("--rounds", options.rounds),
        Some(budget) => ("--max-rounds", budget.max_rounds),
    };
    if timed.1 < MIN_ROUNDS {
        bail!(UsageError(format!(
            "{} {}: a 95% interval of the median needs at least {MIN_ROUNDS} rounds",
            timed.0, timed.1
        )));
    }
    check_executable(&options.other)?;
    let this = std::env::current_exe().context("cannot find this build's own binary")?;
    let scratch = tempfile::tempdir().context("cannot make a scratch directory")?;
    let engines = options.engines.len();
    let total = engines as u64 * u64::from(options.warmup + timed.1) * 2;
    let runs = progress.steps(total, "runs");
    // Round `round` (counted from 0, warm-up included) of `engine`: this build's seconds and
    // the other's, each run a step of `runs`. Ray counts that differ are noted in `result`.
    let play = |engine: Engine, round: u32, result: &mut EngineAb| -> Result<(f64, f64)> {
        let run = |binary: &Path| -> Result<(f64, String)> {
            let time = time_one(binary, options, engine, scratch.path())?;
            runs.step();
            Ok(time)
        };
        // Alternate which build goes first, so that neither always runs on a warmer or cooler
        // machine.
        let (mine, theirs) = if round.is_multiple_of(2) {
            let mine = run(&this)?;
            (mine, run(&options.other)?)
        } else {
            let theirs = run(&options.other)?;
            (run(&this)?, theirs)
        };
        if mine.1 != theirs.1 && result.different_work.is_none() {
            result.different_work = Some((mine.1.clone(), theirs.1));
        }
        Ok((mine.0, theirs.0))
    };
    let start = Instant::now();
    let mut results = Vec::new();
    for (i, &engine) in options.engines.iter().enumerate() {
        let mut result = EngineAb {
            engine,
            this: Vec::new(),
            other: Vec::new(),
            different_work: None,
            sequential: None,
        };
        let engine_start = Instant::now();
        for round in 0..options.warmup {
            play(engine, round, &mut result)?;
        }
        let Some(budget) = options.until_decided else {
            for round in options.warmup..options.warmup + options.rounds {
                let (mine, theirs) = play(engine, round, &mut result)?;
                result.this.push(mine);
                result.other.push(theirs);
            }
            results.push(result);
            continue;
        };
        // The time left is shared equally by this engine and those after it; one that decides
        // early leaves its share to the rest.
        let deadline = budget.max_time.map(|t| {
            let left = (start + t).saturating_duration_since(engine_start);
            engine_start + left / (engines - i) as u32
        });
        let mut round = options.warmup;
        let outcome =
            sequential::decide(&LookPlan::new(budget.max_rounds), options.rule, &mut |at| {
                if let Some(end) = deadline
                    && !reachable(engine_start, round, at.next_look - at.rounds, end)
                {
                    return Ok(None);
                }
                let (mine, theirs) = play(engine, round, &mut result)?;
                round += 1;
                result.this.push(mine);
                result.other.push(theirs);
                Ok(Some(mine / theirs))
            })?;
        result.sequential = Some(outcome);
        results.push(result);
    }
    Ok(results)
}

/// Whether `rounds` more rounds can end by `end`, at the pace of the `done` rounds run since
/// `since` (any number while none has run, unless `end` has passed). A look that cannot be
/// reached is not started: its rounds would be spent without a verdict.
fn reachable(since: Instant, done: u32, rounds: u32, end: Instant) -> bool {
    let now = Instant::now();
    if now >= end {
        return false;
    }
    if done == 0 {
        return true;
    }
    let pace = now.duration_since(since) / done;
    pace.checked_mul(rounds)
        .and_then(|ahead| now.checked_add(ahead))
        .is_some_and(|finish| finish <= end)
}

/// The process exit code: [`EXIT_REGRESSION`] when some engine's verdict is a regression, else
/// [`EXIT_UNDECIDED`] when `--until-decided` left some engine undecided at its budget, else 0
/// (a fixed-rounds run that ends undecided exits 0: a regression needs evidence).
pub fn exit_code(options: &AbOptions, results: &[EngineAb]) -> u8 {
    let verdicts: Vec<Verdict> = results
        .iter()
        .map(|r| r.summary(options.rule).verdict)
        .collect();
    if verdicts.contains(&Verdict::Slower) {
        EXIT_REGRESSION
    } else if options.until_decided.is_some() && verdicts.contains(&Verdict::Undecided) {
        EXIT_UNDECIDED
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::verdict::summarize;

    #[test]
    fn verdicts_follow_the_whole_interval() {
        let around = |centre: f64, spread: f64| -> Vec<f64> {
            (0..20)
                .map(|i| centre + spread * (i as f64 / 19.0 - 0.5))
                .collect()
        };
        let verdicts = |ratios: &[f64]| {
            (
                summarize(ratios, Rule::regression(5.0)).verdict,
                summarize(ratios, Rule::three_way(5.0)).verdict,
            )
        };
        use Verdict::*;
        assert_eq!(verdicts(&around(1.10, 0.02)), (Slower, Slower));
        assert_eq!(verdicts(&around(0.90, 0.02)), (NotSlower, Faster));
        assert_eq!(verdicts(&around(1.00, 0.02)), (NotSlower, Within));
        // About 5% faster, its interval across 1/1.05: undecided for the three-way form only.
        assert_eq!(verdicts(&around(0.95, 0.04)), (NotSlower, Undecided));
        // A 5% slowdown inside a wide spread is not called a regression, nor cleared.
        assert_eq!(verdicts(&around(1.05, 0.30)), (Undecided, Undecided));
        // Too few rounds give an unbounded interval: never a verdict.
        assert_eq!(verdicts(&[2.0; 5]), (Undecided, Undecided));
        assert_eq!(verdicts(&[0.5; 5]), (Undecided, Undecided));
        let s = summarize(&around(1.10, 0.02), Rule::regression(5.0));
        assert!(s.low <= s.median && s.median <= s.high);
    }

    /// The interval's ends are the sign test's order statistics, known by hand: for the 20
    /// ratios 1 + i/64 (i = 0..20, given in reverse), rank 6, so the 6th and the 15th smallest,
    /// 1 + 5/64 and 1 + 14/64, around the median 1 + 9.5/64 (all exact in binary, and so are
    /// the thresholds below: 1 + 7.8125/100 and 1 + 21.875/100 are those ends to the bit). A
    /// threshold whose bound equals the low end does not call a slowdown; one just below it
    /// does. A threshold whose bound equals the high end clears the build ("not more than
    /// t"); one just below it leaves it undecided.
    #[test]
    fn the_interval_ends_are_the_sign_tests_order_statistics() {
        let ratios: Vec<f64> = (0..20).rev().map(|i| 1.0 + i as f64 / 64.0).collect();
        let s = summarize(&ratios, Rule::regression(5.0));
        assert_eq!(
            (s.low, s.median, s.high),
            (1.0 + 5.0 / 64.0, 1.0 + 9.5 / 64.0, 1.0 + 14.0 / 64.0)
        );
        assert_eq!(s.verdict, Verdict::Slower);
        let at_low_end = 100.0 * 5.0 / 64.0;
        assert_eq!(1.0 + at_low_end / 100.0, s.low);
        for rule in [Rule::regression(at_low_end), Rule::three_way(at_low_end)] {
            assert_eq!(summarize(&ratios, rule).verdict, Verdict::Undecided);
            let below = Rule {
                threshold_pct: at_low_end * 0.999,
                ..rule
            };
            assert_eq!(summarize(&ratios, below).verdict, Verdict::Slower);
        }
        let at_high_end = 100.0 * 14.0 / 64.0;
        assert_eq!(1.0 + at_high_end / 100.0, s.high);
        assert_eq!(
            summarize(&ratios, Rule::regression(at_high_end)).verdict,
            Verdict::NotSlower
        );
        assert_eq!(
            summarize(&ratios, Rule::regression(at_high_end * 0.999)).verdict,
            Verdict::Undecided
        );
        assert_eq!(
            summarize(&ratios, Rule::three_way(at_high_end)).verdict,
            Verdict::Within
        );
    }
}
