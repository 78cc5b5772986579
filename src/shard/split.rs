//! The split: [`Shard`] is one job's `I/N` (shard I of N, 0-based), and [`partition`] deals
//! items out by estimated cost, not by count, so that every shard takes about as long. Nothing
//! here knows what an item is (a point of a bench sweep, a job of a variance study).
//!
//! ```text
//! partition(costs, n): longest processing time first (Graham's LPT rule)
//!   order items by cost, largest first (ties: lower item index first)
//!   each in turn goes to the shard with the least cost so far (ties: lower shard index)
//!   each shard's items in ascending order
//! ```
//!
//! LPT's longest shard is at most 4/3 − 1/(3n) times the best possible split's; dealing by
//! count can be n times worse (every expensive item in one shard).

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Shard `index` of `count`, 0-based: `--shard 0/3` is the first of three.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Shard {
    /// Which shard, from 0 to `count - 1`.
    pub index: usize,
    /// How many shards the work is split into (at least 1).
    pub count: usize,
}

/// The most shards a command accepts: more than any farm would run, few enough that a typo
/// (`0/30000000`) is an error rather than millions of empty shards.
pub const MAX_SHARDS: usize = 10_000;

impl Shard {
    /// This shard's items of a split of `costs` ([`partition`] into `count` shards).
    pub fn items(&self, costs: &[f64]) -> Vec<usize> {
        partition(costs, self.count)
            .into_iter()
            .nth(self.index)
            .unwrap_or_default()
    }
}

impl FromStr for Shard {
    type Err = String;

    /// Parses `I/N`: two plain decimal numbers, 0 ≤ I < N ≤ [`MAX_SHARDS`].
    fn from_str(s: &str) -> Result<Shard, String> {
        let expected = "expected I/N, shard I (0-based) of N shards with 0 <= I < N, e.g. 0/3";
        // Digits only (no sign, no spaces); an empty or too long number does not parse.
        let number = |x: &str| -> Option<usize> {
            x.bytes()
                .all(|b| b.is_ascii_digit())
                .then(|| x.parse().ok())?
        };
        let Some((Some(index), Some(count))) =
            s.split_once('/').map(|(i, n)| (number(i), number(n)))
        else {
            return Err(format!("`{}`: {expected}", s.escape_debug()));
        };
        if count == 0 {
            return Err(format!("`{s}`: N is 0, expected at least 1 shard"));
        }
        if count > MAX_SHARDS {
            return Err(format!(
                "`{s}`: {count} shards, expected at most {MAX_SHARDS}"
            ));
        }
        if index >= count {
            return Err(format!(
                "`{s}`: shard {index} does not exist, expected I below N (the shards of {count} \
                 are 0 to {})",
                count - 1
            ));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    /// `I/N`, as it is parsed.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Splits the items `0..costs.len()` into `n` shards by longest processing time first (the
/// module's pseudo-code): deterministic, each item in exactly one shard, each shard's items in
/// ascending order; shards may be empty when there are fewer items than shards. A cost that
/// is negative or not finite counts as 0. `n = 0` gives no shards.
pub fn partition(costs: &[f64], n: usize) -> Vec<Vec<usize>> {
    let mut shards = vec![Vec::new(); n];
    if n == 0 {
        return shards;
    }
    let cost = |i: usize| {
        let c = costs[i];
        if c.is_finite() && c > 0.0 { c } else { 0.0 }
    };
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by(|&a, &b| cost(b).total_cmp(&cost(a)).then(a.cmp(&b)));
    let mut load = vec![0.0f64; n];
    for item in order {
        let least = (0..n)
            .min_by(|&a, &b| load[a].total_cmp(&load[b]).then(a.cmp(&b)))
            .unwrap_or(0);
        load[least] += cost(item);
        shards[least].push(item);
    }
    for shard in &mut shards {
        shard.sort_unstable();
    }
    shards
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_print_as_i_of_n() {
        for (text, index, count) in [("0/1", 0, 1), ("0/3", 0, 3), ("2/3", 2, 3), ("9/10", 9, 10)] {
            let s: Shard = text.parse().unwrap();
            assert_eq!((s.index, s.count), (index, count));
            assert_eq!(s.to_string(), text);
        }
    }

    #[test]
    fn bad_shards_say_what_was_expected() {
        for (text, needle) in [
            ("0/0", "N is 0"),
            ("4/4", "shard 4 does not exist"),
            ("5/4", "the shards of 4 are 0 to 3"),
            ("x/4", "expected I/N"),
            ("1", "expected I/N"),
            ("1/", "expected I/N"),
            ("/2", "expected I/N"),
            ("-1/2", "expected I/N"),
            ("+1/2", "expected I/N"),
            (" 1/2", "expected I/N"),
            ("1/2/3", "expected I/N"),
            ("1.0/2", "expected I/N"),
            ("0/99999999999999999999999", "expected I/N"),
            ("0/10001", "at most 10000"),
            ("", "expected I/N"),
        ] {
            let e = text.parse::<Shard>().unwrap_err();
            assert!(e.contains(needle), "`{text}`: {e}");
        }
    }

    /// Every item lands in exactly one shard, and each shard lists its items in order.
    fn check_is_a_partition(shards: &[Vec<usize>], items: usize) {
        let mut seen = vec![0; items];
        for shard in shards {
            assert!(shard.windows(2).all(|w| w[0] < w[1]), "{shards:?}");
            for &i in shard {
                seen[i] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "{shards:?}");
    }

    #[test]
    fn the_largest_cost_goes_first_to_the_least_loaded_shard() {
        // 5 → s0; 4 → s1; 3 (item 2) → s1 (4 < 5); 3 (item 3) → s0 (5 < 7); 3 (item 4) → s1.
        assert_eq!(
            partition(&[5.0, 4.0, 3.0, 3.0, 3.0], 2),
            [vec![0, 3], vec![1, 2, 4]]
        );
        // Ties: equal costs in item order, each to the lowest-numbered least-loaded shard.
        assert_eq!(partition(&[1.0; 5], 3), [vec![0, 3], vec![1, 4], vec![2]]);
        // By cost, not by count: one expensive item alone against many cheap ones.
        assert_eq!(
            partition(&[1.0, 1.0, 8.0, 1.0, 1.0], 2),
            [vec![2], vec![0, 1, 3, 4]]
        );
    }

    #[test]
    fn edges_empty_shards_no_items_and_odd_costs() {
        assert_eq!(
            partition(&[2.0, 1.0], 4),
            [vec![0], vec![1], vec![], vec![]]
        );
        assert_eq!(partition(&[], 2), [Vec::<usize>::new(), vec![]]);
        assert!(partition(&[1.0], 0).is_empty());
        let odd = [f64::NAN, -1.0, f64::INFINITY, 2.0, -0.0];
        let shards = partition(&odd, 2);
        check_is_a_partition(&shards, odd.len());
        // NaN, -1, ∞ and -0 count as 0: the one real cost goes first, then the rest in order.
        assert_eq!(shards, [vec![3], vec![0, 1, 2, 4]]);
        let s = Shard { index: 1, count: 2 };
        assert_eq!(s.items(&odd), [0, 1, 2, 4]);
    }

    /// The best split's longest shard, by trying every assignment.
    fn optimum(costs: &[f64], n: usize) -> f64 {
        let mut best = f64::INFINITY;
        for code in 0..n.pow(costs.len() as u32) {
            let mut load = vec![0.0; n];
            let mut c = code;
            for &x in costs {
                load[c % n] += x;
                c /= n;
            }
            best = best.min(load.iter().copied().fold(0.0, f64::max));
        }
        best
    }

    #[test]
    fn the_longest_shard_is_within_grahams_bound_of_the_best() {
        // A fixed pseudo-random table (a multiplicative hash), so that the test is the same on
        // every run.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for case in 0..300 {
            let items = 1 + case % 7;
            let n = 1 + case % 3;
            let costs: Vec<f64> = (0..items)
                .map(|_| {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    1.0 + (state >> 40) as f64 % 50.0
                })
                .collect();
            let shards = partition(&costs, n);
            check_is_a_partition(&shards, items);
            let longest = shards
                .iter()
                .map(|s| s.iter().map(|&i| costs[i]).sum::<f64>())
                .fold(0.0, f64::max);
            let bound = (4.0 / 3.0 - 1.0 / (3.0 * n as f64)) * optimum(&costs, n);
            assert!(longest <= bound + 1e-9, "{costs:?} into {n}: {shards:?}");
            assert_eq!(partition(&costs, n), shards, "not deterministic");
        }
    }
}
