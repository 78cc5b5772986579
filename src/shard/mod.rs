//! Sharding, once for every command that shards: `raywave bench --shard I/N` (the points of a
//! sweep) and `raywave variance --shard I/N` (the jobs of a study). A command supplies only its
//! [`Work`]: what its items are, what each costs, how two of them differ, and what one item's
//! result is. The split, the identity, the part file, its checks and the merge are here.
//!
//! ```text
//! split.rs     Shard (I/N), partition(costs, N): longest processing time first
//! identity.rs  Identity<W> = raywave version, build, SIMD path, executable hash + the work W
//! part.rs      Part<W> = identity, shard, items, Host, extra, results; the one file format:
//!                magic "RWPART3\n" · kind (8 bytes) · length u64 · FNV-1a u64 · CBOR payload
//! merge.rs     merge::<W>(inputs): every part read and checked, then checked against the
//!              others: shard counts, SIMD path, build, work, each shard once, none missing,
//!              one machine unless the command allows several
//! ```
//!
//! One shard of a command computes the whole work's identity and the same split as every other,
//! runs only its own items, and writes one self-describing part; the merge hands the command its
//! results in item order.

mod identity;
mod merge;
mod part;
mod split;

pub use identity::{Identity, Work};
pub(crate) use merge::same_file;
pub use merge::{HostSummary, Machines, Merged, merge};
pub use part::{Host, Part, part_name, read_part, write_part};
pub use split::{MAX_SHARDS, Shard, partition};

/// A work of a few items for the layer's own tests: item i costs `costs[i]`, and its result is
/// its index squared.
#[cfg(test)]
pub(crate) mod toy {
    use super::{Identity, Work};
    use serde::{Deserialize, Serialize};

    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    pub(crate) struct Toy {
        pub(crate) costs: Vec<f64>,
    }

    impl Work for Toy {
        const KIND: &'static str = "toy";
        const NOUN: &'static str = "toy run";
        const COMMAND: &'static str = "raywave toy --shard I/N";
        const SAME_RUN: &'static str = "run every shard with the same toys";
        type Result = u64;
        type Extra = String;

        fn costs(&self) -> Vec<f64> {
            self.costs.clone()
        }

        fn differences(&self, other: &Toy, a: &str, b: &str) -> Vec<String> {
            (self.costs != other.costs)
                .then(|| format!("costs: {:?} {a}, {:?} {b}", self.costs, other.costs))
                .into_iter()
                .collect()
        }

        fn check_results(_: &Identity<Toy>, items: &[usize], results: &[u64]) -> Option<String> {
            items
                .iter()
                .zip(results)
                .find(|&(&i, &r)| r != (i * i) as u64)
                .map(|(i, r)| format!("item {i} has result {r}, expected {}", i * i))
        }
    }

    /// Shard `index` of `count` of a toy run of `costs`, its results right.
    pub(crate) fn part(costs: &[f64], index: usize, count: usize) -> super::Part<Toy> {
        let shard = super::Shard { index, count };
        let items = shard.items(costs);
        super::Part {
            identity: Identity::current(
                "scalar",
                Toy {
                    costs: costs.to_vec(),
                },
            ),
            shard,
            results: items.iter().map(|&i| (i * i) as u64).collect(),
            items,
            host: super::Host::start(1),
            extra: format!("shard {index}"),
        }
    }
}
