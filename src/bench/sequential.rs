//! `raywave bench --against OTHER --until-decided`: rounds until the verdict is decided, with
//! a false-alarm rate that looking at the rounds as they come does not inflate.
//!
//! Stopping at the first look whose 95% interval clears the threshold is not a 95% procedure:
//! each look is one more chance for the interval to miss the true median, and the chances add
//! up. Looking at 95% at each of the default plan's nine looks, an unchanged build (at
//! threshold 0, the worst case) is called slower or faster in 16% of runs instead of 5%, and
//! slower in 8% instead of 2.5% (the tests below compute it exactly and simulate it on a noisy
//! machine). So the looks are planned, and the 5% is split between them:
//!
//! ```text
//! plan:  looks at n₁, ⌈1.5·n₁⌉, ⌈1.5·n₂⌉, ..., max-rounds (the last one capped): K looks,
//!        each interval at level 1 − 5%/K, n₁ the fewest rounds that have such an interval
//!        (K is the smallest split whose plan has at most K looks)
//! for each planned look n:
//!     rounds up to n, unless the caller's budget says the look cannot be reached: stop there
//!     the n ratios' median and its (1 − 5%/K) interval → verdict (`ab::summarize_at`)
//!     slower, faster or within: stop, decided
//! after the last look: undecided at max-rounds
//! ```
//!
//! Why Bonferroni over planned looks: a verdict is wrong only if the interval of the look that
//! gave it misses the true median ratio; each look's sign-test interval misses it with
//! probability at most 5%/K, whatever the other looks saw, so by the union bound the K looks
//! together miss with probability at most 5%, and a false alarm (one side) at most 2.5%, as
//! for one fixed-rounds 95% interval. The bound needs nothing about how the looks' data overlap
//! (they share rounds) and no normal approximation (the intervals are order statistics, as in
//! `output::statistics`); stopping early, decided or out of time, only removes chances to err
//! (the time budget never moves a look: it stops the rounds before one). It is conservative:
//! on the default plan the exact chance that some look misses is 2.0% (1.0% a false alarm;
//! the sign walk, computed in the tests), not 5%. An alpha-spending plan (Pocock's equal
//! levels, O'Brien–Fleming's late spending) calibrated on that exact walk would spend the
//! whole 5% and give somewhat narrower intervals; Bonferroni keeps the plan one line long and
//! its guarantee one sentence, valid without that calibration. The geometric spacing keeps K
//! small (9 looks up to 200 rounds, 18 up to 10 000): a look's interval at 1 − 5%/9 is about
//! 1.4 times as wide as a 95% one of the same rounds, while a look after every round would
//! split the 5% two hundred ways. Like the fixed-rounds interval, the plan assumes the rounds'
//! ratios are independent with one median; the builds' alternating order keeps a drift of the
//! machine from favouring either (docs/BENCHMARKING.md).

use super::ab::{RatioSummary, Verdict, summarize_at};
use crate::output::statistics::min_for_interval_at;
use anyhow::Result;
use std::time::Duration;

/// Default `--max-rounds`.
pub const DEFAULT_MAX_ROUNDS: u32 = 200;

/// The chance of a wrong verdict that all the looks share: that of one 95% interval.
pub const ALPHA: f64 = 0.05;

/// Each planned look after the first comes at ⌈GROWTH × the previous look's rounds⌉.
pub const GROWTH: f64 = 1.5;

/// How long `--until-decided` may go on, per run of the command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// The last planned look's rounds, per engine (at least `ab::MIN_ROUNDS`).
    pub max_rounds: u32,
    /// Wall-clock time for the whole command, warm-up included (`None`: no limit).
    pub max_time: Option<Duration>,
}

/// The planned looks and the level of each look's interval.
#[derive(Clone, Debug, PartialEq)]
pub struct LookPlan {
    /// Rounds at each look, increasing; the last is the budget's `max_rounds`.
    pub looks: Vec<u32>,
    /// Each look's interval misses the median with probability at most `alpha`.
    pub alpha: f64,
    /// The number of looks [`ALPHA`] was split over (`alpha` = `ALPHA / split`; at least the
    /// number of looks).
    pub split: u32,
}

impl LookPlan {
    /// The plan up to `max_rounds` (at least `ab::MIN_ROUNDS`, the fewest with one 95%
    /// interval): the smallest split K of [`ALPHA`] whose geometric schedule, starting at the
    /// fewest rounds with a (1 − ALPHA/K) interval, has at most K looks.
    pub fn new(max_rounds: u32) -> LookPlan {
        for split in 1..=max_rounds {
            let alpha = ALPHA / f64::from(split);
            let first = u32::try_from(min_for_interval_at(alpha)).unwrap_or(u32::MAX);
            if first > max_rounds {
                break;
            }
            let looks = geometric(first, max_rounds);
            if looks.len() <= split as usize {
                return LookPlan {
                    looks,
                    alpha,
                    split,
                };
            }
        }
        // Not reached for max_rounds ≥ MIN_ROUNDS (tests check up to 10 000); one look at the
        // end is the fixed-rounds design, valid whenever it has a 95% interval.
        LookPlan {
            looks: vec![max_rounds],
            alpha: ALPHA,
            split: 1,
        }
    }

    /// Each look's interval as a confidence level in percent (99.44 for 5% over 9 looks).
    pub fn confidence_pct(&self) -> f64 {
        100.0 * (1.0 - self.alpha)
    }
}

/// `first`, then ⌈GROWTH ×⌉ the previous, up to and ending at `max_rounds`.
fn geometric(first: u32, max_rounds: u32) -> Vec<u32> {
    let mut looks = vec![first.min(max_rounds)];
    while let Some(&last) = looks.last().filter(|&&l| l < max_rounds) {
        let next = ((f64::from(last) * GROWTH).ceil() as u32).max(last + 1);
        looks.push(next.min(max_rounds));
    }
    looks
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
    /// A look's verdict was slower, faster or within.
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

/// Runs rounds through `round` and judges them at the plan's looks against `threshold_pct`,
/// until a look is decided or the plan ends. `round` runs one round and returns its ratio
/// (this / other), or `None` when the budget allows no more rounds (it sees how far the next
/// look is); its errors end the rounds.
pub fn decide(
    plan: &LookPlan,
    threshold_pct: f64,
    round: &mut dyn FnMut(Progress) -> Result<Option<f64>>,
) -> Result<Outcome> {
    let mut ratios = Vec::new();
    let mut looks = Vec::new();
    for &at in &plan.looks {
        while (ratios.len() as u32) < at {
            let progress = Progress {
                rounds: ratios.len() as u32,
                next_look: at,
            };
            match round(progress)? {
                Some(ratio) => ratios.push(ratio),
                None => {
                    return Ok(Outcome {
                        looks,
                        rounds: progress.rounds,
                        stop: Stop::Budget,
                    });
                }
            }
        }
        let summary = summarize_at(&ratios, threshold_pct, plan.alpha);
        looks.push(Look {
            rounds: at,
            summary,
        });
        if summary.verdict != Verdict::Undecided {
            return Ok(Outcome {
                looks,
                rounds: at,
                stop: Stop::Decided,
            });
        }
    }
    Ok(Outcome {
        looks,
        rounds: ratios.len() as u32,
        stop: Stop::MaxRounds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::statistics::median_interval_rank_at;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    /// The default plan, by hand: 5%/8 still needs 9 rounds (2·2^-9 ≤ 0.625%), and 9 → 14 →
    /// 21 → 32 → 48 → 72 → 108 → 162 → 200 is 9 looks, more than 8; 5%/9 also starts at 9.
    #[test]
    fn the_default_plan() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        assert_eq!(plan.looks, [9, 14, 21, 32, 48, 72, 108, 162, 200]);
        assert_eq!(plan.split, 9);
        assert_eq!(plan.alpha, 0.05 / 9.0);
        // At the fewest rounds there is, the plan is the fixed-rounds 95% interval.
        let fixed = LookPlan::new(6);
        assert_eq!((fixed.looks, fixed.alpha, fixed.split), (vec![6], ALPHA, 1));
    }

    /// Every budget's plan: at most `split` looks (so the union bound holds), increasing by
    /// the growth factor, ending at the budget, each look with an interval at its level, and no
    /// smaller split that would do.
    #[test]
    fn every_plan_splits_the_error_over_at_most_its_looks() {
        for max in (6..=1000).chain([2000, 5000, 10_000]) {
            let plan = LookPlan::new(max);
            let looks = &plan.looks;
            assert!(looks.len() <= plan.split as usize, "max {max}: {plan:?}");
            assert_eq!(plan.alpha, ALPHA / f64::from(plan.split), "max {max}");
            assert_eq!(*looks.last().unwrap(), max, "max {max}");
            assert!(
                median_interval_rank_at(looks[0] as usize, plan.alpha).is_some(),
                "max {max}: {plan:?}"
            );
            for w in looks.windows(2) {
                assert!(w[1] > w[0], "max {max}: {looks:?}");
                assert!(w[1] == max || f64::from(w[1]) >= 1.5 * f64::from(w[0]));
            }
            if plan.split > 1 {
                let fewer = plan.split - 1;
                let first = min_for_interval_at(ALPHA / f64::from(fewer)) as u32;
                assert!(geometric(first, max).len() > fewer as usize, "max {max}");
            }
        }
        assert_eq!(LookPlan::new(10_000).split, 18);
    }

    /// The exact chance that some look of `plan` calls an A/A comparison slower at threshold 0
    /// (the worst case: the true ratio on the boundary), and that it calls it slower or
    /// faster, for any continuous distribution of independent ratios with median 1: each ratio
    /// is below 1 with probability ½, so the count below 1 is a random walk, and a look at n
    /// rounds with rank k calls "slower" when fewer than k lie below 1 (its interval's low end
    /// is above 1) and "faster" when more than n − k do. Paths stop at their first call.
    fn exact_false_alarms(plan: &LookPlan) -> (f64, f64) {
        let last = *plan.looks.last().unwrap() as usize;
        let mut p = vec![0.0; last + 1]; // p[b]: still undecided with b of the n below 1
        p[0] = 1.0;
        let (mut slower, mut faster) = (0.0, 0.0);
        let mut looks = plan.looks.iter().peekable();
        for n in 1..=last {
            for b in (1..=n).rev() {
                p[b] = 0.5 * (p[b] + p[b - 1]);
            }
            p[0] *= 0.5;
            if looks.next_if(|&&l| l as usize == n).is_some() {
                let k = median_interval_rank_at(n, plan.alpha).unwrap();
                for (b, p) in p.iter_mut().enumerate().take(n + 1) {
                    if b < k {
                        slower += std::mem::take(p);
                    } else if b > n - k {
                        faster += std::mem::take(p);
                    }
                }
            }
        }
        (slower, slower + faster)
    }

    /// The plan's looks at 95% each: looking as the rounds come, without the correction.
    fn naive(plan: &LookPlan) -> LookPlan {
        LookPlan {
            looks: plan.looks.clone(),
            alpha: ALPHA,
            split: 1,
        }
    }

    #[test]
    fn the_exact_false_alarm_rate_is_within_5_percent_only_with_the_correction() {
        for max in 6..=500 {
            let (slower, any) = exact_false_alarms(&LookPlan::new(max));
            assert!(
                slower <= ALPHA / 2.0 && any <= ALPHA,
                "max {max}: {slower} {any}"
            );
        }
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let (slower, any) = exact_false_alarms(&plan);
        let (naive_slower, naive_any) = exact_false_alarms(&naive(&plan));
        println!(
            "default plan, exact: slower {:.2}%, slower or faster {:.2}%; naive {:.2}%, {:.2}%",
            100.0 * slower,
            100.0 * any,
            100.0 * naive_slower,
            100.0 * naive_any
        );
        assert!(naive_slower > 2.0 * ALPHA / 2.0 && naive_any > 2.0 * ALPHA);
    }

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

    /// Verdict counts of `runs` sequential runs of `plan` on [`Machine`]s (seeds 1..=runs),
    /// through [`decide`]: [slower, faster, within, undecided], and the mean rounds used.
    fn simulate(plan: &LookPlan, threshold_pct: f64, slowdown: f64, runs: u64) -> ([u32; 4], f64) {
        let mut counts = [0; 4];
        let mut rounds = 0;
        for seed in 1..=runs {
            let mut machine = Machine::new(seed, JITTER);
            let outcome = decide(plan, threshold_pct, &mut |at| {
                Ok(Some(machine.round(at.rounds, slowdown, 1.0)))
            })
            .unwrap();
            let slot = match outcome.verdict() {
                Verdict::Slower => 0,
                Verdict::Faster => 1,
                Verdict::Within => 2,
                Verdict::Undecided => 3,
            };
            counts[slot] += 1;
            rounds += u64::from(outcome.rounds);
        }
        (counts, rounds as f64 / runs as f64)
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

    /// 2000 A/A runs at threshold 0 (any call of slower or faster is wrong), up to 200 rounds:
    /// with the plan, at most 2.5% called slower and 5% slower or faster (each plus three
    /// binomial standard errors); with the same looks at 95% each, more than those limits.
    #[test]
    fn peeking_at_95_percent_inflates_false_alarms_and_the_plan_does_not() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let rate = |c: u32| f64::from(c) / RUNS as f64;
        let (corrected, _) = simulate(&plan, 0.0, 1.0, RUNS);
        let (peeking, _) = simulate(&naive(&plan), 0.0, 1.0, RUNS);
        println!("A/A at threshold 0, [slower, faster, within, undecided]:");
        println!("  corrected {corrected:?}, naive {peeking:?} of {RUNS}");
        let slower_limit = ALPHA / 2.0 + margin(ALPHA / 2.0, RUNS);
        let any_limit = ALPHA + margin(ALPHA, RUNS);
        assert!(rate(corrected[0]) <= slower_limit, "{corrected:?}");
        assert!(
            rate(corrected[0] + corrected[1]) <= any_limit,
            "{corrected:?}"
        );
        assert!(rate(peeking[0]) > slower_limit, "{peeking:?}");
        assert!(rate(peeking[0] + peeking[1]) > any_limit, "{peeking:?}");
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

    /// A build 15% slower, threshold 5%: called slower in at least 90% of the runs before 200
    /// rounds, never faster or within, and more often than by 20 fixed rounds.
    #[test]
    fn a_15_percent_slowdown_is_caught_before_the_budget() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let (counts, rounds) = simulate(&plan, 5.0, 1.15, RUNS);
        let (fixed, _) = simulate(&fixed_20(), 5.0, 1.15, RUNS);
        println!(
            "15% slower at threshold 5%: {counts:?}, {rounds:.1} rounds on average; 20 fixed \
             rounds: {fixed:?}"
        );
        assert!(f64::from(counts[0]) >= 0.9 * RUNS as f64, "{counts:?}");
        assert_eq!(counts[1] + counts[2], 0, "{counts:?}");
        assert!(counts[0] > fixed[0], "{counts:?} {fixed:?}");
    }

    /// The same build against itself at the default threshold: called slower in at most 2.5%
    /// of the runs (plus the margin), and "no change beyond 5%" more often than by 20 fixed
    /// rounds, which on this much noise hardly ever decide it.
    #[test]
    fn an_unchanged_build_is_decided_within_more_often_than_by_fixed_rounds() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        let (counts, rounds) = simulate(&plan, 5.0, 1.0, RUNS);
        let (fixed, _) = simulate(&fixed_20(), 5.0, 1.0, RUNS);
        println!(
            "A/A at threshold 5%: {counts:?}, {rounds:.1} rounds on average; 20 fixed rounds: \
             {fixed:?}"
        );
        let slower_limit = ALPHA / 2.0 + margin(ALPHA / 2.0, RUNS);
        assert!(
            f64::from(counts[0]) / RUNS as f64 <= slower_limit,
            "{counts:?}"
        );
        assert!(counts[2] > 2 * fixed[2], "{counts:?} {fixed:?}");
    }

    /// `decide` runs rounds only up to the looks, stops at the first decided one, and stops
    /// when the budget says so, with the looks taken so far.
    #[test]
    fn decide_stops_at_a_decided_look_or_the_budget() {
        let plan = LookPlan::new(DEFAULT_MAX_ROUNDS);
        // Ratios of 2: slower at the first look, after exactly its rounds.
        let mut asked = Vec::new();
        let outcome = decide(&plan, 5.0, &mut |at| {
            asked.push(at);
            Ok(Some(2.0))
        })
        .unwrap();
        assert_eq!(outcome.stop, Stop::Decided);
        assert_eq!(outcome.verdict(), Verdict::Slower);
        assert_eq!(outcome.rounds, plan.looks[0]);
        assert_eq!(outcome.looks.len(), 1);
        assert!(asked.iter().all(|a| a.next_look == plan.looks[0]));
        // Ratios alternating far above and below the threshold: never decided.
        let outcome = decide(&plan, 5.0, &mut |at| {
            Ok(Some(if at.rounds % 2 == 0 { 10.0 } else { 0.1 }))
        })
        .unwrap();
        assert_eq!(outcome.stop, Stop::MaxRounds);
        assert_eq!(outcome.rounds, DEFAULT_MAX_ROUNDS);
        assert_eq!(outcome.looks.len(), plan.looks.len());
        assert_eq!(outcome.verdict(), Verdict::Undecided);
        // A budget that ends after 30 rounds: the looks before it, then undecided.
        let outcome = decide(&plan, 5.0, &mut |at| {
            Ok((at.rounds < 30).then_some(if at.rounds % 2 == 0 { 10.0 } else { 0.1 }))
        })
        .unwrap();
        assert_eq!(outcome.stop, Stop::Budget);
        assert_eq!(outcome.rounds, 30);
        let taken: Vec<u32> = outcome.looks.iter().map(|l| l.rounds).collect();
        assert_eq!(taken, [9, 14, 21]);
        // An error in a round ends the rounds with it.
        let err = decide(&plan, 5.0, &mut |_| anyhow::bail!("build failed")).unwrap_err();
        assert!(err.to_string().contains("build failed"));
    }
}
