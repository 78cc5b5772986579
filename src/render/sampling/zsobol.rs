//! ZSobol: Sobol points indexed through the pixel's Morton order (Ahmed and Wonka, SIGGRAPH
//! Asia 2020, "Screen-space blue-noise diffusion of Monte Carlo sampling error via hierarchical
//! ordering of pixels"), as pbrt-v4's ZSobolSampler does it.
//!
//! ```text
//! index  = morton(x, y) · 2^S + (aa sample · 2^n + j)     S = s + n bits of samples per pixel,
//!                                                         2^s ≥ aa samples, 2^n ≥ N points
//! index' = index with every base-4 digit (from the top; the lowest is one bit when the
//!          length is odd) permuted by one of the 24 permutations, chosen by hashing the
//!          digits above it with the stream's seed
//! (u, v) = Sobol dimensions 0 and 1 of index', each Owen-scrambled with the stream's seed
//! ```
//!
//! The stream's seed hashes the render's seed, the bounce and the light, and not the pixel: so
//! neighbouring pixels take neighbouring runs of one scrambled Sobol sequence, which is
//! stratified as a whole, and their errors are negatively correlated: the error moves to high
//! frequencies in screen space (blue noise). The digit permutations hide the Morton order's
//! structure. Every point is still uniform on the square (the Owen scramble alone makes it so),
//! so the estimate is unbiased.
//!
//! The Sobol points are computed here on 32-bit indices (`sobol_burley`, used by the `sobol`
//! sampler, takes indices below 2^16), so the image and the samples per pixel may use up to
//! 32 index bits together: [`Layout::index_bits`].

use super::{SampleKey, mix32};

/// How a render's pixels and samples make up a ZSobol index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Bits of each pixel coordinate: 2^b ≥ width and height.
    pub pixel_bits: u32,
    /// Bits of the antialiasing sample: 2^s ≥ samples per pixel.
    pub aa_bits: u32,
    /// Bits of the point index: 2^n ≥ points per light.
    pub point_bits: u32,
    /// The image's width, to turn a pixel index into (x, y).
    pub width: u32,
}

/// The smallest b with 2^b ≥ n (0 for n ≤ 1).
fn bits_for(n: u32) -> u32 {
    n.max(1).next_power_of_two().trailing_zeros()
}

impl Layout {
    /// The layout of a width × height image with `aa` samples per pixel and `points` per light.
    pub fn new(width: u32, height: u32, aa: u32, points: u32) -> Self {
        Layout {
            pixel_bits: bits_for(width.max(height)),
            aa_bits: bits_for(aa),
            point_bits: bits_for(points),
            width: width.max(1),
        }
    }

    /// The bits of an index: two per pixel-coordinate bit, then the samples'. At most 32.
    pub fn index_bits(&self) -> u32 {
        2 * self.pixel_bits + self.aa_bits + self.point_bits
    }

    /// The Morton-ordered index of point `j` of `key`'s stream, before the digit permutation.
    #[inline]
    pub fn index(&self, key: &SampleKey, j: u32) -> u32 {
        let (x, y) = (key.pixel % self.width, key.pixel / self.width);
        let sample_bits = self.aa_bits + self.point_bits;
        // Past 32 bits (which `sampling::check` refuses) the high bits are dropped, not a panic.
        let sample =
            key.sample.checked_shl(self.point_bits).unwrap_or(0) | (j & low_mask(self.point_bits));
        morton(x, y).checked_shl(sample_bits).unwrap_or(0) | sample
    }
}

/// x's bits in the even positions, y's in the odd ones (each below 2^16).
#[inline]
fn morton(x: u32, y: u32) -> u32 {
    let spread = |v: u32| {
        let mut v = v & 0xffff;
        v = (v | (v << 8)) & 0x00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333;
        (v | (v << 1)) & 0x5555_5555
    };
    spread(x) | (spread(y) << 1)
}

/// The 24 permutations of {0, 1, 2, 3}.
pub(crate) const PERMUTATIONS_4: [[u32; 4]; 24] = {
    let mut table = [[0u32; 4]; 24];
    let mut n = 0;
    let mut a = 0;
    while a < 4 {
        let mut b = 0;
        while b < 4 {
            let mut c = 0;
            while c < 4 {
                if a != b && a != c && b != c {
                    table[n] = [a, b, c, 6 - a - b - c];
                    n += 1;
                }
                c += 1;
            }
            b += 1;
        }
        a += 1;
    }
    table
};

/// `index` (of `bits` bits) with its base-4 digits permuted from the top, each by the
/// permutation that hashing the digits above it with `seed` picks (an odd length's lowest digit
/// is one bit, flipped by a hashed bit); only digits whose lowest bit's position `keep` accepts,
/// the others 0, so that a stream permutes the digits above its points' once ([`StreamIndex`]).
#[inline(always)]
fn permute_part(index: u32, bits: u32, seed: u32, keep: impl Fn(u32) -> bool) -> u32 {
    let odd = bits % 2;
    let mut out = 0;
    let mut shift = bits;
    while shift >= 2 + odd {
        shift -= 2;
        if !keep(shift) {
            continue;
        }
        let digit = (index >> shift) & 3;
        let above = if shift + 2 >= 32 {
            0
        } else {
            index >> (shift + 2)
        };
        // `shift` tells the depth apart: an empty prefix at two depths must not share a hash.
        let h = mix32(above ^ mix32(seed ^ shift.wrapping_mul(0x9e37_79b9)));
        out |= PERMUTATIONS_4[(h % 24) as usize][digit as usize] << shift;
    }
    if odd == 1 && keep(0) {
        let h = mix32((index >> 1) ^ mix32(seed ^ ODD_SALT));
        out |= (index & 1) ^ (h & 1);
    }
    out
}

/// An odd-length index's one-bit lowest digit is flipped by bit 0 of
/// `mix32((index >> 1) ^ mix32(seed ^ ODD_SALT))`.
const ODD_SALT: u32 = 0x5bd1_e995;

/// One stream's ZSobol state: the permuted digits above the point's bits are computed once, as
/// Sobol bits (Sobol points are linear over GF(2) in the index's bits, so the two parts'
/// contributions XOR together). The wavefront engine computes [`StreamIndex::point`] on lanes
/// from these fields (`wavefront/simd/point_sets.rs`).
#[derive(Clone, Copy, Debug)]
pub struct StreamIndex {
    /// The stream's index with the point's bits 0.
    pub(crate) base: u32,
    /// The index's length in bits ([`Layout::index_bits`]).
    pub(crate) bits: u32,
    /// The point's bits: the low `point_bits` of the index.
    pub(crate) point_bits: u32,
    /// `mix32(seed ^ ODD_SALT)`: the hash salt of an odd length's one-bit digit.
    pub(crate) odd_salt: u32,
    /// The Sobol bits (dimensions 0 and 1) of the permuted digits above the point's.
    pub(crate) high: (u32, u32),
    /// The Owen scramble seeds of dimensions 0 and 1.
    pub(crate) scramble: (u32, u32),
    /// `mix32(seed ^ shift · φ)` for the digit at each shift below `point_bits`.
    pub(crate) depth_hash: [u32; 32],
}

impl StreamIndex {
    /// The state of `key`'s stream under `layout`.
    #[inline]
    pub fn new(layout: &Layout, key: &SampleKey) -> Self {
        let seed = stream_seed(key);
        let base = layout.index(key, 0);
        let bits = layout.index_bits();
        let split = layout.point_bits;
        let high = permute_part(base, bits, seed, |shift| shift >= split);
        let mut depth_hash = [0; 32];
        for (shift, h) in depth_hash
            .iter_mut()
            .enumerate()
            .take(split.min(32) as usize)
        {
            *h = mix32(seed ^ (shift as u32).wrapping_mul(0x9e37_79b9));
        }
        StreamIndex {
            base,
            bits,
            point_bits: split,
            odd_salt: mix32(seed ^ ODD_SALT),
            high: sobol_2d(high),
            scramble: (mix32(seed ^ 0x6a09_e667), mix32(seed ^ 0xbb67_ae85)),
            depth_hash,
        }
    }

    /// Point `j` of the stream (j below 2^point_bits; above, its high bits are dropped).
    #[inline]
    pub fn point(&self, j: u32) -> (f32, f32) {
        let low = self.permute_low(self.base | (j & low_mask(self.point_bits)));
        let (lx, ly) = sobol_2d(low);
        let unit = |bits: u32| (bits >> 8) as f32 * (1.0 / 16_777_216.0);
        (
            unit(owen_scramble(self.high.0 ^ lx, self.scramble.0)),
            unit(owen_scramble(self.high.1 ^ ly, self.scramble.1)),
        )
    }

    /// `permute_part(index, bits, seed, |shift| shift < point_bits)`, visiting only those
    /// digits, with their depth hashes from the table.
    #[inline]
    fn permute_low(&self, index: u32) -> u32 {
        let (bits, split) = (self.bits, self.point_bits);
        let odd = bits % 2;
        let mut out = 0;
        // Digit shifts have the parity of `bits` and are at least `odd`: the highest below
        // the split first.
        let mut shift = i64::from(split) - 1;
        if shift >= 0 && (shift as u32) % 2 != odd {
            shift -= 1;
        }
        while shift >= i64::from(odd) && shift + 2 <= i64::from(bits) {
            let s = shift as u32;
            let digit = (index >> s) & 3;
            let above = if s + 2 >= 32 { 0 } else { index >> (s + 2) };
            let h = mix32(above ^ self.depth_hash[s as usize]);
            out |= PERMUTATIONS_4[(h % 24) as usize][digit as usize] << s;
            shift -= 2;
        }
        if odd == 1 && split > 0 {
            let h = mix32((index >> 1) ^ self.odd_salt);
            out |= (index & 1) ^ (h & 1);
        }
        out
    }
}

/// The lowest `bits` bits set.
#[inline]
pub(crate) fn low_mask(bits: u32) -> u32 {
    if bits >= 32 {
        u32::MAX
    } else {
        (1 << bits) - 1
    }
}

/// Owen scrambling of `x` with `seed` (a well-mixed value): `sobol_burley`'s hash-based nested
/// uniform scramble on the reversed bits, in which each output bit depends only on the input
/// bits above it. Burley's (2020) original Laine–Karras constants were weaker: they left part
/// of the Sobol sequence's relation between dimensions 0 and 1 in the scrambled points, which
/// `tests/sampling/point_statistics.rs` sees as a diagonal band integrated worse than its
/// shifted copy (docs/TRIED.md).
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    sobol_burley::parts::owen_scramble_rev(x.reverse_bits(), seed).reverse_bits()
}

/// Sobol dimensions 0 and 1 of `index`, as 32-bit fractions: dimension 0 is the van der
/// Corput sequence, dimension 1 the one of the primitive polynomial x + 1 (direction numbers
/// v₀ = 2⁻¹, vₖ = vₖ₋₁ ⊕ vₖ₋₁/2).
#[inline]
fn sobol_2d(index: u32) -> (u32, u32) {
    let mut v = 1u32 << 31;
    let mut y = 0;
    let mut i = index;
    while i != 0 {
        if i & 1 == 1 {
            y ^= v;
        }
        i >>= 1;
        v ^= v >> 1;
    }
    (index.reverse_bits(), y)
}

/// The stream seed: the render's seed, the bounce and the light, not the pixel or sample.
#[inline]
fn stream_seed(key: &SampleKey) -> u32 {
    let mut h = mix32(key.seed ^ 0x2f1e_5c3b);
    h = mix32(h ^ key.bounce);
    mix32(h ^ key.light)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every digit of `index` permuted: what a stream's two parts make together.
    fn permute_digits(index: u32, bits: u32, seed: u32) -> u32 {
        permute_part(index, bits, seed, |_| true)
    }

    #[test]
    fn the_first_sobol_points_are_the_textbook_ones() {
        let unit = |b: u32| b as f64 / 4_294_967_296.0;
        let dim0 = [0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875];
        let dim1 = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for i in 0..8 {
            let (x, y) = sobol_2d(i);
            assert_eq!(
                (unit(x), unit(y)),
                (dim0[i as usize], dim1[i as usize]),
                "{i}"
            );
        }
    }

    /// Dimensions 0 and 1 are a (0,2)-sequence: every aligned block of 2^m points has one point
    /// in each elementary interval of area 2^-m; the Owen scramble keeps it so.
    #[test]
    fn scrambled_blocks_are_02_nets() {
        for m in 0..=8u32 {
            for block in [0u32, 3, 1000] {
                for k in 0..=m {
                    let mut seen = vec![false; 1 << m];
                    for i in 0..1u32 << m {
                        let (x, y) = sobol_2d((block << m) | i);
                        let (x, y) = (owen_scramble(x, 7), owen_scramble(y, 11));
                        let top = |v: u32, b: u32| if b == 0 { 0 } else { v >> (32 - b) };
                        let cell = ((top(x, k) << (m - k)) | top(y, m - k)) as usize;
                        assert!(!seen[cell], "m {m}, block {block}, shape {k}");
                        seen[cell] = true;
                    }
                }
            }
        }
    }

    #[test]
    fn the_digit_permutation_is_a_bijection_that_keeps_aligned_blocks() {
        for bits in [1u32, 2, 5, 8] {
            let n = 1u32 << bits;
            let mut seen = vec![false; n as usize];
            for i in 0..n {
                let p = permute_digits(i, bits, 42);
                assert!(p < n && !seen[p as usize], "bits {bits}");
                seen[p as usize] = true;
                // The digits above the lowest one (two bits, or one for odd lengths) decide
                // the block: the lowest digit is permuted within it.
                let low = if bits % 2 == 1 { 1 } else { 2 };
                let block = permute_digits(i & !((1 << low) - 1), bits, 42) >> low;
                assert_eq!(p >> low, block, "bits {bits}");
            }
        }
        assert_eq!(PERMUTATIONS_4.len(), 24);
    }

    /// A stream's two parts, permuted apart and XORed through Sobol, are the whole index's
    /// point: for odd and even lengths, and a split inside a digit.
    #[test]
    fn a_stream_s_parts_make_the_whole_point() {
        for (w, h, aa, points) in [
            (64, 64, 1, 16),
            (64, 64, 2, 16),
            (9, 9, 2, 1),
            (100, 30, 2, 8),
            (5, 5, 1, 1),
            (512, 512, 3, 64),
        ] {
            let layout = Layout::new(w, h, aa, points);
            for pixel in [0u32, 7, 99, w * h - 1] {
                let key = SampleKey {
                    pixel,
                    sample: aa - 1,
                    bounce: 2,
                    light: 1,
                    seed: 3,
                };
                let stream = StreamIndex::new(&layout, &key);
                for j in 0..points {
                    let seed = stream_seed(&key);
                    let index = permute_digits(layout.index(&key, j), layout.index_bits(), seed);
                    let (x, y) = sobol_2d(index);
                    let unit = |bits: u32| (bits >> 8) as f32 * (1.0 / 16_777_216.0);
                    let whole = (
                        unit(owen_scramble(x, mix32(seed ^ 0x6a09_e667))),
                        unit(owen_scramble(y, mix32(seed ^ 0xbb67_ae85))),
                    );
                    assert_eq!(
                        stream.point(j),
                        whole,
                        "{w}×{h}, aa {aa}, N {points}, j {j}"
                    );
                }
            }
        }
    }

    #[test]
    fn morton_interleaves_x_in_the_even_bits() {
        assert_eq!(morton(0, 0), 0);
        assert_eq!(morton(1, 0), 1);
        assert_eq!(morton(0, 1), 2);
        assert_eq!(morton(3, 3), 15);
        assert_eq!(morton(0xffff, 0), 0x5555_5555);
    }

    #[test]
    fn layouts_count_their_bits() {
        let l = Layout::new(512, 300, 1, 16);
        assert_eq!((l.pixel_bits, l.aa_bits, l.point_bits), (9, 0, 4));
        assert_eq!(l.index_bits(), 22);
        assert_eq!(Layout::new(1, 1, 1, 1).index_bits(), 0);
        assert_eq!(Layout::new(16384, 16384, 4, 4).index_bits(), 32);
    }
}
