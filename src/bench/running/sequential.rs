//! `raywave bench --against OTHER --until-decided`: rounds until the verdict is decided, with
//! a false-alarm rate that looking at the rounds as they come does not inflate.
//!
//! Stopping at the first look whose 95% interval clears the threshold is not a 95% procedure:
//! each look is one more chance for the interval to miss the true median, and the chances add
//! up. Looking at 95% at each of the default plan's nine looks, an unchanged build (at
//! threshold 0, the worst case) is called slower in 8.1% of runs instead of 2.5%, and slower
//! or faster in 16% instead of 5% (the tests below compute it exactly and simulate it on a
//! noisy machine). So the looks are planned, and the 5% is split between them:
//!
//! ```text
//! plan:  K looks at geometrically growing rounds up to max-rounds, each interval at level
//!        1 − 5%/K (`crate::stats::looks`: the schedule, and why the Bonferroni split holds)
//! for each planned look n:
//!     rounds up to n, unless the caller's budget says the look cannot be reached: stop there
//!     the n ratios' median and its (1 − 5%/K) interval → verdict (`verdict::Rule::judge`)
//!     decided (one-sided: slower, or not slower; three-way: slower, faster or within): stop
//! after the last look: undecided at max-rounds
//! ```
//!
//! In the default, one-sided form (ab.rs) each call errs only when the interval misses the
//! median on one side: a false alarm (a build at most t slower called a regression) has
//! probability at most 2.5%, and a miss (a build more than t slower called not slower) at most
//! 2.5%. Exactly, on the default plan: a build exactly t slower, the worst case, is called a
//! regression in 1.02% of runs, and a build just past t is missed in 1.02% (the sign walk in the
//! tests, exact at every threshold for this rule, whose verdict depends only on how many ratios
//! lie below 1 + t).
//!
//! Why not give the one-sided question the whole 5% (each end of the interval at 5%/K, a
//! (1 − 10%/K) two-sided interval): on the simulated machine below it saves about a tenth of the
//! rounds (a head 5% faster: 41 instead of 47 on average; an unchanged build: 122 instead of
//! 134) and doubles both errors (1.85% exact, instead of 1.02%). The gate's two answers both
//! act (one fails a pull request, the other lets a regression in), so each keeps the 2.5% of one
//! side of a 95% interval; and both forms then judge the same interval at the same level: one
//! plan, one printed interval.
//!
//! The line 1 + t itself belongs to "not slower" (`Rule::judge` says why); a ratio of two
//! measured times equal to 1 + t to the bit is rare enough that the choice matters for the
//! statement, not for a run.

use crate::bench::verdict::{RatioSummary, Rule, Verdict, summarize_at};
use crate::stats::looks::LookPlan;
use anyhow::Result;
use std::time::Duration;

/// Default `--max-rounds`.
pub const DEFAULT_MAX_ROUNDS: u32 = 200;

/// How long `--until-decided` may go on, per run of the command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// The last planned look's rounds, per engine (at least `ab::MIN_ROUNDS`).
    pub max_rounds: u32,
    /// Wall-clock time for the whole command, warm-up included (`None`: no limit).
    pub max_time: Option<Duration>,
}

/// One look: the rounds it saw and what their interval said.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// Rounds seen.
    pub rounds: u32,
    /// Median, (1 − plan.alpha) interval and verdict of those rounds' ratios.
    pub summary: RatioSummary,
}

/// Why the rounds stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// A look's verdict was decided: slower or not slower (one-sided), or slower, faster or
    /// within (three-way).
    Decided,
    /// The last planned look (`--max-rounds`) was undecided.
    MaxRounds,
    /// The caller's budget (`--max-time`) stopped the rounds before the next look.
    Budget,
}

/// What the rounds of one engine came to.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The looks taken, in order; the last one's verdict is the outcome's.
    pub looks: Vec<Look>,
    /// Rounds run (past the last look when the budget stopped them between looks).
    pub rounds: u32,
    /// Why they stopped.
    pub stop: Stop,
}

#[cfg(test)]
impl Outcome {
    /// The last look's verdict; undecided when no look was taken.
    pub fn verdict(&self) -> Verdict {
        self.looks
            .last()
            .map_or(Verdict::Undecided, |l| l.summary.verdict)
    }
}

/// Where the rounds are, as `decide` asks for the next one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Rounds run so far.
    pub rounds: u32,
    /// The rounds of the next planned look.
    pub next_look: u32,
}

/// Runs rounds through `round` and judges them at the plan's looks by `rule`, until a look is
/// decided or the plan ends. `round` runs one round and returns its ratio
/// (this / other), or `None` when the budget allows no more rounds (it sees how far the next
/// look is); its errors end the rounds.
pub fn decide(
    plan: &LookPlan,
    rule: Rule,
    round: &mut dyn FnMut(Progress) -> Result<Option<f64>>,
) -> Result<Outcome> {
    let mut ratios = Vec::new();
    let mut looks = Vec::new();
    let stop = 'looks: {
        for &at in &plan.looks {
            while (ratios.len() as u32) < at {
                let progress = Progress {
                    rounds: ratios.len() as u32,
                    next_look: at,
                };
                let Some(ratio) = round(progress)? else {
                    break 'looks Stop::Budget;
                };
                ratios.push(ratio);
            }
            let summary = summarize_at(&ratios, rule, plan.alpha);
            looks.push(Look {
                rounds: at,
                summary,
            });
            if summary.verdict != Verdict::Undecided {
                break 'looks Stop::Decided;
            }
        }
        Stop::MaxRounds
    };
    // However the rounds stopped, each one run gave a ratio.
    Ok(Outcome {
        looks,
        rounds: ratios.len() as u32,
        stop,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::looks::ALPHA;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    /// A shared machine as two builds timed in alternation see it: a slow drift of its speed
    /// (a load that grows, and comes and goes), each run's log-normal jitter, and one run in
    /// twenty disturbed by something else, slowed by a Pareto factor (heavy-tailed: infinite
    /// variance). The drift moves within a round too, so the build that runs second in a round
    /// sees a slightly different machine; `bench --against` alternates the order to cancel it.
    struct Machine {
        rng: Xoshiro256PlusPlus,
        clock: f64,
        jitter: f64,
    }

    impl Machine {
        fn new(seed: u64, jitter: f64) -> Machine {
            Machine {
                rng: Xoshiro256PlusPlus::seed_from_u64(seed),
                clock: 0.0,
                jitter,
            }
        }

        /// One run of a build whose undisturbed time is `base`.
        fn run(&mut self, base: f64) -> f64 {
            let t = self.clock;
            self.clock += 0.5;
            let drift = 1.0 + 0.3 * t / 200.0 + 0.15 * (t / 11.0).sin();
            // Box–Muller: a standard normal from two uniforms (u1 in (0, 1]).
            let u1 = 1.0 - self.rng.random::<f64>();
            let u2 = self.rng.random::<f64>();
            let normal = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            let disturbed = if self.rng.random::<f64>() < 0.05 {
                (1.0 - self.rng.random::<f64>()).powf(-1.0 / 1.5)
            } else {
                1.0
            };
            base * drift * (self.jitter * normal).exp() * disturbed
        }

        /// One round's ratio this / other, the order alternating as `ab::run`'s does.
        fn round(&mut self, index: u32, this: f64, other: f64) -> f64 {
            if index.is_multiple_of(2) {
                let mine = self.run(this);
                mine / self.run(other)
            } else {
                let theirs = self.run(other);
                self.run(this) / theirs
            }
        }
    }

    /// How many runs of a simulation ended in each verdict, and their mean rounds.
    #[derive(Clone, Copy, Debug, Default)]
    struct Tally {
        slower: u32,
        not_slower: u32,
        faster: u32,
        within: u32,
        undecided: u32,
        mean_rounds: f64,
    }

    impl Tally {
        /// The fraction of `RUNS` runs that `count` is.
        fn rate(count: u32) -> f64 {
            f64::from(count) / RUNS as f64
        }
    }

    /// `runs` sequential runs of `plan` by `rule` on [`Machine`]s (seeds 1..=runs), through
    /// [`decide`], for a head `slowdown` times the base's time.
    fn simulate(plan: &LookPlan, rule: Rule, slowdown: f64, runs: u64) -> Tally {
        let mut tally = Tally::default();
        let mut rounds = 0;
        for seed in 1..=runs {
            let mut machine = Machine::new(seed, JITTER);
            let outcome = decide(plan, rule, &mut |at| {
                Ok(Some(machine.round(at.rounds, slowdown, 1.0)))
            })
            .unwrap();
            *match outcome.verdict() {
                Verdict::Slower => &mut tally.slower,
                Verdict::NotSlower => &mut tally.not_slower,
                Verdict::Faster => &mut tally.faster,
                Verdict::Within => &mut tally.within,
                Verdict::Undecided => &mut tally.undecided,
            } += 1;
            rounds += u64::from(outcome.rounds);
        }
        tally.mean_rounds = rounds as f64 / runs as f64;
        tally
    }

    /// Three binomial standard errors of a rate `p` over `n` runs: the margin allowed above a
    /// nominal rate (the seeds are fixed, so this is about the seeds' luck, not flakiness).
    fn margin(p: f64, n: u64) -> f64 {
        3.0 * (p * (1.0 - p) / n as f64).sqrt()
    }

    const RUNS: u64 = 2000;

    /// Each run's log-normal jitter: with the drift and the disturbed runs, ratios spread
    /// like those of the lab benchmark at 512×512 on a shared 2-core machine, where a 95%
    /// interval of 20 rounds could not separate a 13% slowdown from 5% (its half-width was
    /// above 0.08, so σ of a ratio's logarithm about 0.15).
    const JITTER: f64 = 0.1;

    /// The limit on a one-sided false alarm over [`RUNS`] runs: 2.5% plus the margin.
    fn one_sided_limit() -> f64 {
        ALPHA / 2.0 + margin(ALPHA / 2.0, RUNS)
    }

    /// 2000 A/A runs at threshold 0 (the worst case: the true ratio on the boundary), up to
    /// 200 rounds: with the plan, the gate calls at most 2.5% a regression, and the three-way
    /// form at most 2.5% slower and 5% slower or faster (each plus three binomial standard
    /// errors); with the same looks at 95% each, more than those limits.
    #[test]
    fn peeking_at_95_percent_inflates_false_alarms_and_the_plan_does_not() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let any_limit = ALPHA + margin(ALPHA, RUNS);
        for rule in [Rule::regression(0.0), Rule::three_way(0.0)] {
            let corrected = simulate(&plan, rule, 1.0, RUNS);
            let peeking = simulate(&plan.naive(), rule, 1.0, RUNS);
            println!("A/A at threshold 0, {:?}:", rule.form);
            println!("  corrected {corrected:?}\n  naive {peeking:?}");
            let wrong = |t: &Tally| t.slower + t.faster;
            assert!(
                Tally::rate(corrected.slower) <= one_sided_limit(),
                "{corrected:?}"
            );
            assert!(Tally::rate(wrong(&corrected)) <= any_limit, "{corrected:?}");
            assert!(
                Tally::rate(peeking.slower) > one_sided_limit(),
                "{peeking:?}"
            );
        }
        let peeking = simulate(&plan.naive(), Rule::three_way(0.0), 1.0, RUNS);
        assert!(
            Tally::rate(peeking.slower + peeking.faster) > any_limit,
            "{peeking:?}"
        );
    }

    /// The gate's worst case at its own threshold: a head exactly 5% slower, not *more* than
    /// 5%, is called a regression in at most 2.5% of runs (plus the margin).
    #[test]
    fn a_head_exactly_at_the_threshold_is_rarely_called_a_regression() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let tally = simulate(&plan, Rule::regression(5.0), 1.05, RUNS);
        println!("exactly 5% slower at threshold 5%: {tally:?}");
        assert!(Tally::rate(tally.slower) <= one_sided_limit(), "{tally:?}");
    }

    /// The fixed-rounds design of `bench --against` at its default 20 rounds, through the
    /// same function: one look at 95%.
    fn fixed_20() -> LookPlan {
        LookPlan {
            looks: vec![20],
            alpha: ALPHA,
            split: 1,
        }
    }

    /// Heads 3%, 5% and 7% faster than the base, threshold 5%: the gate clears at least 99.9%
    /// of the runs as "not slower", on average within 70 rounds of the 200-round budget; the
    /// three-way form, which must also place the ratio against 1/1.05, takes more rounds and
    /// leaves more runs undecided at the budget, most of them for a head 3–5% faster.
    #[test]
    fn a_faster_head_is_cleared_well_before_the_budget() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        for speed in [0.97, 0.95, 0.93] {
            let one_sided = simulate(&plan, Rule::regression(5.0), speed, RUNS);
            let three = simulate(&plan, Rule::three_way(5.0), speed, RUNS);
            println!(
                "head {speed} × base at threshold 5%:\n  gate {one_sided:?}\n  three-way {three:?}"
            );
            assert!(Tally::rate(one_sided.not_slower) >= 0.999, "{one_sided:?}");
            assert!(one_sided.mean_rounds <= 70.0, "{one_sided:?}");
            assert!(three.mean_rounds > one_sided.mean_rounds, "{three:?}");
            assert!(three.undecided > one_sided.undecided, "{three:?}");
        }
    }

    /// A head 10% slower, threshold 5%: the gate calls it a regression in at least 70% of the
    /// runs before 200 rounds (on this much noise the rest are undecided at the budget, exit
    /// 4), and "not slower" in at most 2.5% (plus the margin); 15% slower, a regression in
    /// every run, more often than 20 fixed rounds do.
    #[test]
    fn a_slowdown_past_the_threshold_is_still_caught() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let ten = simulate(&plan, Rule::regression(5.0), 1.10, RUNS);
        let fifteen = simulate(&plan, Rule::regression(5.0), 1.15, RUNS);
        let fixed = simulate(&fixed_20(), Rule::regression(5.0), 1.15, RUNS);
        println!("10% slower at threshold 5%: {ten:?}");
        println!("15% slower at threshold 5%: {fifteen:?}\n  20 fixed rounds: {fixed:?}");
        assert!(Tally::rate(ten.slower) >= 0.7, "{ten:?}");
        assert!(Tally::rate(ten.not_slower) <= one_sided_limit(), "{ten:?}");
        assert_eq!(fifteen.slower, RUNS as u32, "{fifteen:?}");
        assert_eq!(fifteen.not_slower, 0, "{fifteen:?}");
        assert!(fifteen.slower > fixed.slower, "{fifteen:?} {fixed:?}");
    }

    /// The same build against itself at the default threshold: the gate calls it a regression
    /// in at most 2.5% of the runs (plus the margin), and clears at least 75% as "not slower",
    /// in fewer rounds than the three-way form needs; that form decides "no change beyond 5%"
    /// more often than 20 fixed rounds, which on this much noise hardly ever decide it, but
    /// leaves about half undecided at 200.
    #[test]
    fn an_unchanged_build_is_cleared_early_by_the_gate() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let one_sided = simulate(&plan, Rule::regression(5.0), 1.0, RUNS);
        let three = simulate(&plan, Rule::three_way(5.0), 1.0, RUNS);
        let fixed = simulate(&fixed_20(), Rule::three_way(5.0), 1.0, RUNS);
        println!(
            "A/A at threshold 5%:\n  gate {one_sided:?}\n  three-way {three:?}\n  three-way, \
             20 fixed rounds: {fixed:?}"
        );
        assert!(
            Tally::rate(one_sided.slower) <= one_sided_limit(),
            "{one_sided:?}"
        );
        assert!(Tally::rate(one_sided.not_slower) >= 0.75, "{one_sided:?}");
        assert!(
            one_sided.mean_rounds < three.mean_rounds,
            "{one_sided:?} {three:?}"
        );
        assert!(Tally::rate(three.slower) <= one_sided_limit(), "{three:?}");
        assert!(three.within > 2 * fixed.within, "{three:?} {fixed:?}");
    }

    /// `decide` runs rounds only up to the looks, stops at the first decided one, and stops
    /// when the budget says so, with the looks taken so far.
    #[test]
    fn decide_stops_at_a_decided_look_or_the_budget() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        // Ratios of 2: slower at the first look, after exactly its rounds, in both forms.
        for rule in [Rule::regression(5.0), Rule::three_way(5.0)] {
            let mut asked = Vec::new();
            let outcome = decide(&plan, rule, &mut |at| {
                asked.push(at);
                Ok(Some(2.0))
            })
            .unwrap();
            assert_eq!(outcome.stop, Stop::Decided);
            assert_eq!(outcome.verdict(), Verdict::Slower);
            assert_eq!(outcome.rounds, plan.looks[0]);
            assert_eq!(outcome.looks.len(), 1);
            assert!(asked.iter().all(|a| a.next_look == plan.looks[0]));
        }
        // Ratios of 0.95, 5% faster: not slower at the first look; the three-way form, whose
        // boundary 1/1.05 = 0.952 they lie just below, faster at the first look too.
        let outcome = decide(&plan, Rule::regression(5.0), &mut |_| Ok(Some(0.95))).unwrap();
        assert_eq!((outcome.verdict(), outcome.rounds), (Verdict::NotSlower, 9));
        let outcome = decide(&plan, Rule::three_way(5.0), &mut |_| Ok(Some(0.95))).unwrap();
        assert_eq!((outcome.verdict(), outcome.rounds), (Verdict::Faster, 9));
        // Ratios alternating far above and below the threshold: never decided.
        for rule in [Rule::regression(5.0), Rule::three_way(5.0)] {
            let outcome = decide(&plan, rule, &mut |at| {
                Ok(Some(if at.rounds % 2 == 0 { 10.0 } else { 0.1 }))
            })
            .unwrap();
            assert_eq!(outcome.stop, Stop::MaxRounds);
            assert_eq!(outcome.rounds, DEFAULT_MAX_ROUNDS);
            assert_eq!(outcome.looks.len(), plan.looks.len());
            assert_eq!(outcome.verdict(), Verdict::Undecided);
        }
        // A budget that ends after 30 rounds: the looks before it, then undecided.
        let outcome = decide(&plan, Rule::regression(5.0), &mut |at| {
            Ok((at.rounds < 30).then_some(if at.rounds % 2 == 0 { 10.0 } else { 0.1 }))
        })
        .unwrap();
        assert_eq!(outcome.stop, Stop::Budget);
        assert_eq!(outcome.rounds, 30);
        let taken: Vec<u32> = outcome.looks.iter().map(|l| l.rounds).collect();
        assert_eq!(taken, [9, 14, 21]);
        // An error in a round ends the rounds with it.
        let err = decide(&plan, Rule::regression(5.0), &mut |_| {
            anyhow::bail!("build failed")
        })
        .unwrap_err();
        assert!(err.to_string().contains("build failed"));
    }
}
