//! `--shard I/N`: one of N deterministic slices of a job list, balanced by each job's estimated
//! cost, for a batch system (a Slurm array, GNU parallel, a Kubernetes Indexed Job) to run.
//! raywave schedules nothing itself: every shard computes the same split from the same jobs and
//! runs only its own slice.
//!
//! ```text
//! order   = jobs by cost, largest first (ties: the earlier job first)
//! for job in order: give it to the shard with the least cost so far
//!                   (ties: the one with fewer jobs, then the lowest index)
//! shard i runs its jobs in job-list order
//! ```
//!
//! This is the longest-processing-time rule: its largest shard is at most 4/3 of the best
//! possible split's (Graham 1969), and it is exact whenever no job is larger than a fair share.

use std::fmt;
use std::str::FromStr;

/// Shard `index` of `count` (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    /// This shard, 0-based.
    pub index: u32,
    /// Shards in all.
    pub count: u32,
}

impl Shard {
    /// The whole job list as one shard.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The largest shard count accepted.
pub const MAX_SHARDS: u32 = 1 << 20;

impl FromStr for Shard {
    type Err = String;

    /// `I/N` with 0 ≤ I < N: a batch system's 0-based task index (`$SLURM_ARRAY_TASK_ID`,
    /// `$JOB_COMPLETION_INDEX`, GNU parallel's `{%}` minus one) over its task count.
    fn from_str(s: &str) -> Result<Shard, String> {
        let expected = "expected I/N with 0 <= I < N, such as 0/4 for the first of four shards";
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("'{s}' is not a shard: {expected}"))?;
        let parse = |part: &str, what: &str| {
            part.trim().parse::<u32>().map_err(|_| {
                format!(
                    "'{s}' is not a shard: its {what} '{part}' is not a whole number; {expected}"
                )
            })
        };
        let (index, count) = (parse(i, "index")?, parse(n, "count")?);
        if count == 0 {
            return Err(format!(
                "'{s}': a shard count of 0 leaves nothing to run; {expected}"
            ));
        }
        if count > MAX_SHARDS {
            return Err(format!(
                "'{s}': {count} shards is more than the {MAX_SHARDS} accepted"
            ));
        }
        if index >= count {
            return Err(format!(
                "'{s}': shard index {index} is out of range for {count} shards (indices are 0-based: 0 to {}); {expected}",
                count - 1
            ));
        }
        Ok(Shard { index, count })
    }
}

/// The jobs of each of `count` shards: indices into `costs`, each list in ascending order.
/// Deterministic; a cost that is not finite or is negative counts as 0.
pub fn partition(costs: &[f64], count: u32) -> Vec<Vec<usize>> {
    let count = count.max(1) as usize;
    let cost = |i: usize| {
        let c = costs[i];
        if c.is_finite() && c > 0.0 { c } else { 0.0 }
    };
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by(|&a, &b| cost(b).total_cmp(&cost(a)).then(a.cmp(&b)));
    let mut load = vec![0.0f64; count];
    let mut shards = vec![Vec::new(); count];
    for job in order {
        let least = (0..count)
            .min_by(|&a, &b| {
                load[a]
                    .total_cmp(&load[b])
                    .then(shards[a].len().cmp(&shards[b].len()))
                    .then(a.cmp(&b))
            })
            .unwrap_or(0);
        load[least] += cost(job);
        shards[least].push(job);
    }
    for s in &mut shards {
        s.sort_unstable();
    }
    shards
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_bad_ones_say_what_was_expected() {
        assert_eq!("2/4".parse(), Ok(Shard { index: 2, count: 4 }));
        assert_eq!("0/1".parse::<Shard>().unwrap().to_string(), "0/1");
        for (bad, says) in [
            ("0/0", "count of 0"),
            ("4/4", "out of range"),
            ("x/4", "index 'x'"),
            ("1", "expected I/N"),
            ("-1/4", "not a whole number"),
            ("1/", "count ''"),
        ] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn every_job_lands_in_exactly_one_shard_and_the_split_is_balanced_by_cost() {
        // One large job and many small ones: by count the large one's shard would take twice
        // the others' work; by cost it takes the large job alone.
        let mut costs = vec![12.0];
        costs.extend(std::iter::repeat_n(1.0, 36));
        let shards = partition(&costs, 4);
        let mut all: Vec<usize> = shards.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(all, (0..costs.len()).collect::<Vec<_>>());
        let loads: Vec<f64> = shards
            .iter()
            .map(|s| s.iter().map(|&i| costs[i]).sum())
            .collect();
        assert_eq!(loads, [12.0, 12.0, 12.0, 12.0], "{shards:?}");
        assert_eq!(shards[0], [0]);
        assert_eq!(partition(&costs, 4), shards, "deterministic");
    }

    #[test]
    fn more_shards_than_jobs_leaves_some_empty_and_odd_costs_count_as_nothing() {
        let shards = partition(&[1.0, f64::NAN, -3.0], 5);
        assert_eq!(shards.iter().filter(|s| s.is_empty()).count(), 2);
        assert_eq!(partition(&[], 3), vec![Vec::<usize>::new(); 3]);
        assert_eq!(partition(&[1.0, 2.0], 1), vec![vec![0, 1]]);
    }
}
