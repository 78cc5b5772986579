//! Halton points in bases 2 and 3, Owen-scrambled independently for every stream.
//!
//! Point j of a stream is the radical inverse of j in base 2 (u) and in base 3 (v), each
//! Owen-scrambled (nested uniform scrambling): every digit is permuted by a random permutation
//! chosen by the digits above it, so the points keep the Halton sequence's stratification (any
//! prefix of 2^a·3^b points has one point in each of the 2^a × 3^b boxes) and each point is
//! uniform on the square, which makes the estimate unbiased.
//!
//! The permutations come from hashing the stream's seed with the path of digits above, one
//! hash per digit (pbrt-v4's `OwenScrambledRadicalInverse` draws a random shift per digit; the
//! permutation here is drawn among all b! of them). Only the digits the stream's indices use
//! are permuted one by one: below the last one, a fully scrambled point's digits are independent
//! and uniform, so they are drawn at once as one uniform number from the last node's hash, which
//! has the same distribution at a fraction of the cost.

use super::{ONE_MINUS_EPS, mix32};

/// The digits a stream of `count` points uses in each base: the smallest m with b^m ≥ count
/// (at least 1), for bases 2 and 3.
pub fn digits(count: u32) -> (u32, u32) {
    // b^m ≥ count ⇔ m > log_b(count − 1), for count ≥ 2.
    let needed = |base: u32| (count.max(2) - 1).ilog(base) + 1;
    (needed(2), needed(3))
}

/// The salt of a stream's root node: its hash is `mix32(seed ^ ROOT_SALT)`.
pub(crate) const ROOT_SALT: u32 = 0x3c6e_f372;
/// The child of a node with hash h along original digit d has hash
/// `mix32(h ^ (d + 1) · CHILD_STEP)`.
pub(crate) const CHILD_STEP: u32 = 0x9e37_79b9;
/// The digits below the last permuted one come from `mix32(h ^ TAIL_SALT)` of the last node.
pub(crate) const TAIL_SALT: u32 = 0x68e3_1da4;

/// The six permutations of {0, 1, 2}.
pub(crate) const PERMUTATIONS_3: [[u32; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// Digit `d` of base `base` (2 or 3) permuted by the node whose hash is `h`.
#[inline(always)]
fn permute(base: u32, h: u32, d: u32) -> u32 {
    if base == 2 {
        d ^ (h & 1)
    } else {
        // h % 6 is uniform within 2^-32 of each sixth.
        PERMUTATIONS_3[(h % 6) as usize][d as usize]
    }
}

/// The Owen-scrambled radical inverse of `index` in `base` (2 or 3), with its first `digits`
/// digits permuted one by one and the rest drawn as one uniform number; `seed` picks the
/// scramble. In [0, 1).
#[inline]
fn radical_inverse(base: u32, digits: u32, index: u32, seed: u32) -> f32 {
    let mut h = mix32(seed ^ ROOT_SALT);
    let mut n = index;
    let mut kept = 0u32;
    let mut scale = 1u32;
    for _ in 0..digits {
        let d = n % base;
        n /= base;
        kept = kept * base + permute(base, h, d);
        scale *= base;
        // The child node: the original digit picks it, so the permutations below depend on
        // the path above (nested scrambling).
        h = mix32(h ^ (d + 1).wrapping_mul(CHILD_STEP));
    }
    let rest = (mix32(h ^ TAIL_SALT) >> 8) as f32 * (1.0 / 16_777_216.0);
    ((kept as f32 + rest) / scale as f32).min(ONE_MINUS_EPS)
}

/// Point `index` of the stream whose scramble hashes are `seeds` (one per dimension), with
/// `digits` = [`digits`]`(count)`.
#[inline]
pub fn point(index: u32, digits: (u32, u32), seeds: (u32, u32)) -> (f32, f32) {
    (
        radical_inverse(2, digits.0, index, seeds.0),
        radical_inverse(3, digits.1, index, seeds.1),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digits_cover_the_indices() {
        assert_eq!(digits(1), (1, 1));
        assert_eq!(digits(2), (1, 1));
        assert_eq!(digits(3), (2, 1));
        assert_eq!(digits(4), (2, 2));
        assert_eq!(digits(16), (4, 3));
        assert_eq!(digits(27), (5, 3));
        assert_eq!(digits(28), (5, 4));
        assert_eq!(digits(65536), (16, 11));
    }

    /// The first 2^a·3^b points of a stream put one point in each of the 2^a × 3^b boxes.
    #[test]
    fn prefixes_stratify_their_boxes() {
        for (a, b) in [(1, 1), (2, 1), (3, 2), (4, 2), (2, 3)] {
            let (nx, ny) = (1u32 << a, 3u32.pow(b));
            let count = nx * ny;
            for seed in 0..20 {
                let mut seen = vec![0u32; count as usize];
                for j in 0..count {
                    let (u, v) = point(j, digits(count), (seed, seed ^ 0x55));
                    assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                    let cell = (v * ny as f32) as u32 * nx + (u * nx as f32) as u32;
                    seen[cell as usize] += 1;
                }
                assert!(seen.iter().all(|&c| c == 1), "{nx}×{ny}, seed {seed}");
            }
        }
    }

    /// Unscrambled, point 5 would be (0.101₂, 0.12₃) = (0.625, 5/9); scrambled, its digits
    /// move, so over many seeds every first digit is taken equally often.
    #[test]
    fn the_scramble_moves_every_digit_uniformly() {
        let mut first = [[0u32; 3]; 2];
        for seed in 0..6000 {
            let (u, v) = point(5, digits(8), (seed, seed.wrapping_mul(7)));
            first[0][(u * 2.0) as usize] += 1;
            first[1][(v * 3.0) as usize] += 1;
        }
        for (c, expected) in [(&first[0][..2], 3000.0), (&first[1][..], 2000.0)] {
            for &n in c {
                assert!(
                    (n as f64 - expected).abs() < 5.0 * expected.sqrt(),
                    "{first:?}"
                );
            }
        }
    }
}
