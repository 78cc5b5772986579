//! The per-stream point sets on N lanes (called from `light::stream_points`, out of line): Halton's scrambled digit loops, ZSobol's permuted
//! Morton index and PMJ02's table rows, each lane k the point `j + k` of one stream. The
//! scalar twins are the sampling module's own: `halton::point`, `zsobol::StreamIndex::point`
//! and `pmj02::point`, reached through `sampling::Stream::point`.
//!
//! The digit loops keep their twins' shape: the loop bounds depend only on the stream (its
//! digit counts, the index's length), so every lane runs the same iterations, and only the
//! digits differ. What the twins do with a scalar instruction that lanes lack:
//!
//! - `x % 3`, `h % 6`, `h % 24`: exact division by a constant, the high half of a product
//!   ([`LanesU::mul_high`]) then a shift, and the remainder as x − q·d;
//! - `PERMUTATIONS[p][d]`: the permutations packed 2 bits a digit into a few words, the word
//!   picked by a lookup in a vector ([`LanesU::lookup`]) and the digit by a per-lane shift.
//!
//! The blue-noise sampler stays one lane at a time (`light::per_lane`): its points are three
//! table reads at addresses that differ per lane, which lanes cannot gather any faster.

use crate::render::sampling::{ONE_MINUS_EPS, halton, mix32, zsobol};
use crate::render::wavefront::lanes::{Lanes, LanesU};

/// Chris Wellons' `lowbias32`, N lanes; twin of `sampling::mix32`.
#[inline(always)]
pub(super) fn mix32x8<U: LanesU>(mut x: U) -> U {
    x = x ^ (x >> 16);
    x = x * U::splat(0x7feb_352d);
    x = x ^ (x >> 15);
    x = x * U::splat(0x846c_a68b);
    x = x ^ (x >> 16);
    x
}

/// The 24-bit unit float of the top bits of `bits`: `(bits >> 8) as f32 · 2⁻²⁴`.
#[inline(always)]
pub(super) fn unit<U: LanesU>(bits: U) -> U::F {
    // bits >> 8 < 2^24, so the signed conversion is exact.
    (bits >> 8).to_f32_signed() * U::F::splat(1.0 / 16_777_216.0)
}

/// `sobol_burley::parts::owen_scramble_rev`, N lanes.
#[inline(always)]
pub(super) fn owen_scramble_rev8<U: LanesU>(mut n: U, scramble: u32) -> U {
    n = n ^ (n * U::splat(0x3d20_adea));
    n = n + U::splat(scramble);
    n = n * U::splat((scramble >> 16) | 1);
    n = n ^ (n * U::splat(0x0552_6c56));
    n = n ^ (n * U::splat(0x53a2_2864));
    n
}

/// `u32::reverse_bits`, N lanes.
#[inline(always)]
pub(super) fn reverse_bits8<U: LanesU>(mut x: U) -> U {
    for (shift, mask) in [
        (1, 0x5555_5555u32),
        (2, 0x3333_3333),
        (4, 0x0f0f_0f0f),
        (8, 0x00ff_00ff),
    ] {
        let m = U::splat(mask);
        x = ((x >> shift) & m) | ((x & m) << shift);
    }
    (x >> 16) | (x << 16)
}

/// x / 3 for every u32 x: 0xaaaa_aaab = ⌈2³³ / 3⌉.
#[inline(always)]
fn div3<U: LanesU>(x: U) -> U {
    x.mul_high(0xaaaa_aaab) >> 1
}

/// `PERMUTATIONS_3[p]` packed 2 bits a digit into lane p (p < 6): `(table[p] >> 2d) & 3` is
/// digit d's image.
const PERM3_CODES: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut p = 0;
    while p < 6 {
        let mut d = 0;
        while d < 3 {
            t[p] |= halton::PERMUTATIONS_3[p][d] << (2 * d);
            d += 1;
        }
        p += 1;
    }
    t
};

/// `PERMUTATIONS_4[p]` packed 8 bits a permutation, 4 permutations a word: `(table[p / 4] >>
/// (8 · (p % 4) + 2d)) & 3` is digit d's image under permutation p (p < 24).
const PERM4_WORDS: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut p = 0;
    while p < 24 {
        let mut d = 0;
        while d < 4 {
            t[p / 4] |= zsobol::PERMUTATIONS_4[p][d] << (8 * (p % 4) + 2 * d);
            d += 1;
        }
        p += 1;
    }
    t
};

/// A lookup table of the lane width: the first N entries of `table`.
#[inline(always)]
fn table<U: LanesU>(table: &[u32; 16]) -> U {
    U::from_fn(|k| table[k])
}

/// Halton points `j` of the stream with `digits` per base and scramble `seeds`: lane k
/// equals `halton::point(j[k], digits, seeds)`.
#[inline]
pub(super) fn halton<U: LanesU>(j: U, digits: (u32, u32), seeds: (u32, u32)) -> (U::F, U::F) {
    (
        radical_inverse_2(j, digits.0, seeds.0),
        radical_inverse_3(j, digits.1, seeds.1),
    )
}

/// `halton::radical_inverse(2, digits, index, seed)` on lanes.
#[inline(always)]
fn radical_inverse_2<U: LanesU>(index: U, digits: u32, seed: u32) -> U::F {
    let mut h = U::splat(mix32(seed ^ halton::ROOT_SALT));
    let (mut n, mut kept) = (index, U::ZERO);
    for _ in 0..digits {
        let d = n & U::ONE;
        n = n >> 1;
        kept = kept + kept + (d ^ (h & U::ONE));
        h = mix32x8(h ^ ((d + U::ONE) * U::splat(halton::CHILD_STEP)));
    }
    finish(kept, h, 1u32 << digits)
}

/// `halton::radical_inverse(3, digits, index, seed)` on lanes.
#[inline(always)]
fn radical_inverse_3<U: LanesU>(index: U, digits: u32, seed: u32) -> U::F {
    let codes: U = table(&PERM3_CODES);
    let mut h = U::splat(mix32(seed ^ halton::ROOT_SALT));
    let (mut n, mut kept) = (index, U::ZERO);
    let mut scale = 1u32;
    for _ in 0..digits {
        let q = div3(n);
        let d = n - q * U::splat(3);
        n = q;
        // h % 6 = h − 6·(h / 6), and h / 6 = (h / 3) / 2.
        let p = h - (h.mul_high(0xaaaa_aaab) >> 2) * U::splat(6);
        let permuted = p.lookup(codes).shr_each(d + d) & U::splat(3);
        kept = kept * U::splat(3) + permuted;
        scale *= 3;
        h = mix32x8(h ^ ((d + U::ONE) * U::splat(halton::CHILD_STEP)));
    }
    finish(kept, h, scale)
}

/// (kept + the tail's uniform) / scale, below 1: the end of `halton::radical_inverse`.
#[inline(always)]
fn finish<U: LanesU>(kept: U, h: U, scale: u32) -> U::F {
    let rest = unit(mix32x8(h ^ U::splat(halton::TAIL_SALT)));
    // kept < scale ≤ 3^11 < 2^24: exact as a float.
    ((kept.to_f32_signed() + rest) / U::F::splat(scale as f32)).fast_min(U::F::splat(ONE_MINUS_EPS))
}

/// Sobol dimension 1's direction numbers: v₀ = 2³¹, vₖ = vₖ₋₁ ⊕ vₖ₋₁ / 2.
const SOBOL_DIM1: [u32; 32] = {
    let mut t = [0u32; 32];
    t[0] = 1 << 31;
    let mut k = 1;
    while k < 32 {
        t[k] = t[k - 1] ^ (t[k - 1] >> 1);
        k += 1;
    }
    t
};

/// ZSobol points `j` of `stream`: lane k equals `stream.point(j[k])`.
#[inline]
pub(super) fn zsobol<U: LanesU>(j: U, stream: &zsobol::StreamIndex) -> (U::F, U::F) {
    let (bits, split) = (stream.bits, stream.point_bits);
    let index = U::splat(stream.base) | (j & U::splat(zsobol::low_mask(split)));

    // The digits below the split, permuted: `StreamIndex::permute_low`.
    let words: U = table(&PERM4_WORDS);
    let odd = bits % 2;
    let mut low = U::ZERO;
    let mut shift = i64::from(split) - 1;
    if shift >= 0 && (shift as u32) % 2 != odd {
        shift -= 1;
    }
    while shift >= i64::from(odd) && shift + 2 <= i64::from(bits) {
        let s = shift as u32;
        let digit = (index >> s) & U::splat(3);
        let above = if s + 2 >= 32 {
            U::ZERO
        } else {
            index >> (s + 2)
        };
        let h = mix32x8(above ^ U::splat(stream.depth_hash[s as usize]));
        // h % 24 = h − 24·(h / 24), and h / 24 = (h / 3) / 8.
        let p = h - (h.mul_high(0xaaaa_aaab) >> 4) * U::splat(24);
        let word = (p >> 2).lookup(words);
        let permuted = word.shr_each(((p & U::splat(3)) << 3) + digit + digit) & U::splat(3);
        low = low | (permuted << s);
        shift -= 2;
    }
    if odd == 1 && split > 0 {
        let h = mix32x8((index >> 1) ^ U::splat(stream.odd_salt));
        low = low | ((index & U::ONE) ^ (h & U::ONE));
    }

    // Sobol dimensions 0 and 1 of the low digits (`zsobol::sobol_2d`): the low index has
    // bits below split + 1 only (a digit may straddle the split).
    let x = reverse_bits8(low);
    let mut y = U::ZERO;
    for (k, &v) in SOBOL_DIM1
        .iter()
        .enumerate()
        .take((split + 1).min(32) as usize)
    {
        // All ones where bit k of the low index is set.
        let bit = (low << (31 - k as u32)).sign_fill();
        y = y ^ (bit & U::splat(v));
    }
    (
        unit(owen_scramble(
            U::splat(stream.high.0) ^ x,
            stream.scramble.0,
        )),
        unit(owen_scramble(
            U::splat(stream.high.1) ^ y,
            stream.scramble.1,
        )),
    )
}

/// `zsobol::owen_scramble` on lanes.
#[inline(always)]
fn owen_scramble<U: LanesU>(x: U, seed: u32) -> U {
    reverse_bits8(owen_scramble_rev8(reverse_bits8(x), seed))
}

/// PMJ02 points `j0..j0 + N` of the stream reading `table` with the digital shift `masks`:
/// lane k equals `pmj02::point(table, j0 + k, masks)`.
#[inline]
pub(super) fn pmj02<U: LanesU>(table: &[(u32, u32)], j0: u32, masks: (u32, u32)) -> (U::F, U::F) {
    let n = <U::F as Lanes>::N;
    let at = j0 as usize;
    let (x, y): (U, U) = match table.get(at..at + n) {
        Some(rows) => (U::from_fn(|k| rows[k].0), U::from_fn(|k| rows[k].1)),
        // The stream's end: the twin wraps the index (lanes past the count are dropped).
        None => {
            let row = |k: usize| table[(at + k) % table.len()];
            (U::from_fn(|k| row(k).0), U::from_fn(|k| row(k).1))
        }
    };
    (unit(x ^ U::splat(masks.0)), unit(y ^ U::splat(masks.1)))
}
