//! The lane layer: everything the SIMD kernels share about lanes, in one place (like
//! memchr's `vector.rs`): the lane count, padded loads from columns, mask tables, the view of
//! a vector as its 8 lanes, bit casts, and the iterator over a bitmask's set lanes.
//!
//! It also owns the one lane abstraction, [`Lanes`] (and its unsigned sibling [`LanesU`]),
//! implemented for `f32x8` and `f32x16` by one macro: the brute-force, light-sampling and
//! shading kernels are written once against it and monomorphised for 8 and 16 lanes (the
//! engine picks the width, [`LaneWidth`]). The mesh BVH stays 8-wide (8 children, 8 triangles
//! per block) and uses the concrete `f32x8` and the free functions below.
//!
//! This is the only file of the crate that names the `wide` crate or `bytemuck`
//! (`tests/gates/layering.rs` checks): the kernels take the lane types from here.

use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Shl, Shr, Sub};
pub use wide::{f32x8, f32x16};
pub(crate) use wide::{i32x8, u32x8};

/// The mesh BVH's width (children per node, triangles per block) and the lanes of `f32x8`; the
/// width-generic kernels use `Lanes::N` instead.
pub const LANES: usize = 8;

/// `c[i..i + live]` in lanes 0..live (live ≤ 8), NaN in the lanes after them (which may lie
/// inside the column: a packet's dead lanes).
#[inline(always)]
pub(crate) fn load_live(c: &[f32], i: usize, live: usize) -> f32x8 {
    match c.get(i..i + LANES) {
        // A full packet is one vector load.
        Some(lanes) if live == LANES => {
            f32x8::from(<[f32; LANES]>::try_from(lanes).expect("LANES lanes"))
        }
        _ => f32x8::new(std::array::from_fn(|k| {
            if k < live { c[i + k] } else { f32::NAN }
        })),
    }
}

/// The live lanes of the chunk of `V::N` starting at `i` of a batch of `len`, as a bitmask.
#[inline(always)]
pub(crate) fn live_lanes<V: Lanes>(i: usize, len: usize) -> u32 {
    let n = (len - i).min(V::N);
    (1u32 << n) - 1
}

/// The 8 lanes of a vector, in place.
#[inline(always)]
pub(crate) fn view(v: &f32x8) -> &[f32; LANES] {
    wide::bytemuck::cast_ref(v)
}

/// The same bits as another type of the same size: a float vector's lanes as unsigned or
/// signed integers (a lane's sign bit is its sign) and back (masks), or 8 ids as signed lanes
/// (to compare them in one instruction).
#[inline(always)]
pub(crate) fn cast<A: wide::bytemuck::Pod, B: wide::bytemuck::Pod>(a: A) -> B {
    wide::bytemuck::cast(a)
}

/// Lane k of an 8-lane bitmask as a bool, for all 256 masks: a chunk's results are stored with
/// one 8-byte copy instead of a loop over lanes (that loop was 6% of the lab benchmark's
/// instructions).
const MASK_BOOLS: [[bool; LANES]; 256] = {
    let mut table = [[false; LANES]; 256];
    let mut mask = 0;
    while mask < 256 {
        let mut lane = 0;
        while lane < LANES {
            table[mask][lane] = mask & (1 << lane) != 0;
            lane += 1;
        }
        mask += 1;
    }
    table
};

/// Lane masks by bitmask: `MASK_LANES[m]` is all ones in lane k where bit k of m is set.
pub(crate) static MASK_LANES: [f32x8; 256] = {
    let mut table = [f32x8::ZERO; 256];
    let mut m = 0;
    while m < 256 {
        let mut lanes = [0.0f32; LANES];
        let mut k = 0;
        while k < LANES {
            if m & (1 << k) != 0 {
                lanes[k] = f32::from_bits(u32::MAX);
            }
            k += 1;
        }
        table[m] = f32x8::new(lanes);
        m += 1;
    }
    table
};

/// Which lane width the wavefront engine's brute-force, light and shading kernels run at (the
/// mesh BVH is 8-wide either way). It changes speed only: both widths give the same bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LaneWidth {
    /// 16 lanes when the binary was built for AVX-512 (`target_feature = "avx512f"`, where
    /// `f32x16` is one register), else 8.
    #[default]
    Auto,
    /// `f32x8` (one AVX2 register, or two SSE halves).
    Eight,
    /// `f32x16` (one AVX-512 register, or two AVX2 halves without AVX-512).
    Sixteen,
}

impl LaneWidth {
    /// The width `Auto` stands for in this build: 16 with AVX-512, else 8.
    pub const NATIVE: LaneWidth = if cfg!(target_feature = "avx512f") {
        LaneWidth::Sixteen
    } else {
        LaneWidth::Eight
    };

    /// `Auto` resolved for this build: `Eight` or `Sixteen`.
    pub fn resolve(self) -> LaneWidth {
        match self {
            LaneWidth::Auto => LaneWidth::NATIVE,
            w => w,
        }
    }

    /// Lanes per vector once resolved: 8 or 16.
    pub fn lanes(self) -> usize {
        match self.resolve() {
            LaneWidth::Sixteen => 16,
            _ => 8,
        }
    }
}

/// Evaluates `$body` with the type `$V` standing for the lane type of `$width` (`Auto` resolved
/// for this build): `at_width!(ctx.lane_width, V => simd::closest_hits::<V>(..))`. The one
/// place a lane width chosen at run time becomes a type; only the arm of each width is
/// compiled for it. Exported (as `lanes::at_width`) for the peer benchmark's engines.
#[doc(hidden)]
#[macro_export]
macro_rules! __at_width {
    ($width:expr, $V:ident => $body:expr) => {
        match $width.resolve() {
            $crate::render::wavefront::lanes::LaneWidth::Sixteen => {
                type $V = $crate::render::wavefront::lanes::f32x16;
                $body
            }
            _ => {
                type $V = $crate::render::wavefront::lanes::f32x8;
                $body
            }
        }
    };
}
pub use crate::__at_width as at_width;

/// A float lane vector, as the width-generic kernels use it: lane k of every operation is the
/// scalar operation on lane k (no fused multiply-add, no reordering), so a kernel written once
/// gives the same bits per lane at either width. Implemented for `f32x8` and `f32x16` only.
pub trait Lanes:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Not<Output = Self>
{
    /// Lanes per vector.
    const N: usize;
    /// All lanes 0.
    const ZERO: Self;
    /// All lanes 1.
    const ONE: Self;
    /// The lanes as an array, `[f32; N]`.
    type Array: Copy
        + Default
        + std::fmt::Debug
        + AsRef<[f32]>
        + AsMut<[f32]>
        + std::ops::Index<usize, Output = f32>
        + std::ops::IndexMut<usize>;
    /// The unsigned integer vector of the same width (the hash-based samplers).
    type U: LanesU<F = Self>;

    /// Every lane `x`.
    fn splat(x: f32) -> Self;
    /// From an array.
    fn from_array(a: Self::Array) -> Self;
    /// Lane k = `f(k)`.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    /// To an array.
    fn to_array(self) -> Self::Array;
    /// `col[i..i + N]`, `pad` in the lanes past the column's end.
    fn load(col: &[f32], i: usize, pad: f32) -> Self;
    /// The lane indices 0..N as floats.
    const LANE_INDEX: Self;
    /// Lane-wise `<`, all ones where true.
    fn simd_lt(self, rhs: Self) -> Self;
    /// Lane-wise `>`.
    fn simd_gt(self, rhs: Self) -> Self;
    /// Lane-wise `<=`.
    fn simd_le(self, rhs: Self) -> Self;
    /// Lane-wise `>=`.
    fn simd_ge(self, rhs: Self) -> Self;
    /// Lane-wise `!=`.
    fn simd_ne(self, rhs: Self) -> Self;
    /// Where this mask is set `t`, else `f`.
    fn select(self, t: Self, f: Self) -> Self;
    /// The sign bit of every lane, lane k in bit k.
    fn to_bitmask(self) -> u32;
    /// Every lane's mask set.
    fn all(self) -> bool;
    /// No lane's mask set.
    fn none(self) -> bool;
    /// Lane-wise square root (correctly rounded).
    fn sqrt(self) -> Self;
    /// Lane-wise |x|.
    fn abs(self) -> Self;
    /// Lane-wise minimum, NaN handling unspecified (`minps`).
    fn fast_min(self, rhs: Self) -> Self;
}

/// The unsigned sibling of a [`Lanes`] type: u32 lanes, wrapping arithmetic.
pub trait LanesU:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + Not<Output = Self>
    + Shr<u32, Output = Self>
    + Shl<u32, Output = Self>
{
    /// The float vector of the same width.
    type F: Lanes<U = Self>;
    /// All lanes 0.
    const ZERO: Self;
    /// All lanes 1.
    const ONE: Self;
    /// Every lane `x`.
    fn splat(x: u32) -> Self;
    /// The lane indices 0..N.
    const LANE_INDEX: Self;
    /// All ones in the lanes whose top bit is set, else 0 (an arithmetic shift right by 31).
    fn sign_fill(self) -> Self;
    /// Every lane converted to float as a signed integer (exact below 2^24).
    fn to_f32_signed(self) -> Self::F;
    /// Every lane's bits read as a float.
    fn bits_to_f32(self) -> Self::F;
    /// Lane k is `f(k)`.
    fn from_fn(f: impl FnMut(usize) -> u32) -> Self;
    /// The high 32 bits of each lane's 64-bit product with `m` (exact division by a constant:
    /// x / 3 = `x.mul_high(0xaaaa_aaab) >> 1` for every u32 x).
    fn mul_high(self, m: u32) -> Self;
    /// Each lane shifted right by its own lane of `by` (each below 32).
    fn shr_each(self, by: Self) -> Self;
    /// Lane k is `table[self[k]]`: a lookup in a table of up to N entries held in a vector
    /// (every index below N).
    fn lookup(self, table: Self) -> Self;
}

/// Trait methods that are the lane type's inherent method of the same name.
macro_rules! forward {
    ($t:ident: $(fn $name:ident(self $(, $arg:ident: $ty:ty)*) -> $ret:ty;)*) => {$(
        #[inline(always)]
        fn $name(self $(, $arg: $ty)*) -> $ret {
            $t::$name(self $(, $arg)*)
        }
    )*};
}

macro_rules! impl_lanes {
    ($f:ident, $u:ident, $i:ident, $n:literal, $from_i:ident) => {
        impl Lanes for $f {
            const N: usize = $n;
            const ZERO: Self = $f::ZERO;
            const ONE: Self = $f::ONE;
            type Array = [f32; $n];
            type U = $u;

            #[inline(always)]
            fn splat(x: f32) -> Self {
                $f::splat(x)
            }
            #[inline(always)]
            fn from_array(a: [f32; $n]) -> Self {
                $f::new(a)
            }
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
                $f::new(std::array::from_fn(f))
            }
            #[inline(always)]
            fn load(col: &[f32], i: usize, pad: f32) -> Self {
                match col.get(i..i + $n) {
                    Some(s) => $f::new(s.try_into().expect("N lanes")),
                    None => {
                        let mut a = [pad; $n];
                        let rest = &col[i.min(col.len())..];
                        a[..rest.len()].copy_from_slice(rest);
                        $f::new(a)
                    }
                }
            }
            const LANE_INDEX: Self = {
                let mut a = [0.0f32; $n];
                let mut k = 0;
                while k < $n {
                    a[k] = k as f32;
                    k += 1;
                }
                $f::new(a)
            };
            forward! { $f:
                fn to_array(self) -> [f32; $n];
                fn simd_lt(self, rhs: Self) -> Self;
                fn simd_gt(self, rhs: Self) -> Self;
                fn simd_le(self, rhs: Self) -> Self;
                fn simd_ge(self, rhs: Self) -> Self;
                fn simd_ne(self, rhs: Self) -> Self;
                fn select(self, t: Self, f: Self) -> Self;
                fn to_bitmask(self) -> u32;
                fn all(self) -> bool;
                fn none(self) -> bool;
                fn sqrt(self) -> Self;
                fn abs(self) -> Self;
                fn fast_min(self, rhs: Self) -> Self;
            }
        }

        impl LanesU for $u {
            type F = $f;
            const ZERO: Self = $u::ZERO;
            const ONE: Self = $u::ONE;
            #[inline(always)]
            fn splat(x: u32) -> Self {
                $u::splat(x)
            }
            const LANE_INDEX: Self = {
                let mut a = [0u32; $n];
                let mut k = 0;
                while k < $n {
                    a[k] = k as u32;
                    k += 1;
                }
                $u::new(a)
            };
            #[inline(always)]
            fn sign_fill(self) -> Self {
                let s: $i = wide::bytemuck::cast(self);
                wide::bytemuck::cast(s >> 31)
            }
            #[inline(always)]
            fn to_f32_signed(self) -> $f {
                $f::$from_i(wide::bytemuck::cast(self))
            }
            #[inline(always)]
            fn bits_to_f32(self) -> $f {
                wide::bytemuck::cast(self)
            }
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> u32) -> Self {
                $u::new(std::array::from_fn(f))
            }
            #[inline(always)]
            fn mul_high(self, m: u32) -> Self {
                self.mul_keep_high($u::splat(m))
            }
            #[inline(always)]
            fn shr_each(self, by: Self) -> Self {
                self.unbounded_shr(by)
            }
            #[inline(always)]
            fn lookup(self, table: Self) -> Self {
                table.shuffle(self)
            }
        }
    };
}

impl_lanes!(f32x8, u32x8, i32x8, 8, from_i32x8);
impl_lanes!(f32x16, u32x16, i32x16, 16, from_i32x16);

use wide::{i32x16, u32x16};

/// Stores lane k of `mask` as `out[k]` for the `out.len()` ≤ `V::N` lanes of a chunk, 8 lanes
/// per lookup in [`MASK_BOOLS`]: one lookup at 8 lanes (the 8-lane kernels' one copy), two at
/// 16 (not a 65536-entry table).
#[inline(always)]
pub(crate) fn store_mask<V: Lanes>(out: &mut [bool], mask: u32) {
    debug_assert!(out.len() <= V::N && V::N <= 2 * LANES);
    let (low, high) = out.split_at_mut(out.len().min(LANES));
    low.copy_from_slice(&MASK_BOOLS[(mask & 0xff) as usize][..low.len()]);
    // `V::N` is a constant: at 8 lanes this is gone.
    if V::N > LANES {
        high.copy_from_slice(&MASK_BOOLS[((mask >> 8) & 0xff) as usize][..high.len()]);
    }
}

/// The set bits of a mask, lowest first: `for k in set_bits(m)` visits every lane k whose bit is
/// set, as the loop `while m != 0 { k = m.trailing_zeros(); m &= m - 1; ... }` does.
#[inline(always)]
pub(crate) fn set_bits(mask: u32) -> SetBits {
    SetBits(mask)
}

/// Iterator of [`set_bits`].
#[derive(Clone, Copy)]
pub(crate) struct SetBits(u32);

impl Iterator for SetBits {
    type Item = usize;

    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let k = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_bits_visits_every_set_lane_in_order() {
        assert_eq!(set_bits(0).count(), 0);
        assert_eq!(set_bits(0b1011_0001).collect::<Vec<_>>(), [0, 4, 5, 7]);
        assert_eq!(set_bits(u32::MAX).count(), 32);
    }

    #[test]
    fn mask_tables_match_the_bits() {
        for m in 0..256usize {
            let lanes = view(&MASK_LANES[m]);
            for k in 0..LANES {
                let set = m & (1 << k) != 0;
                assert_eq!(MASK_BOOLS[m][k], set);
                assert_eq!(lanes[k].to_bits() == u32::MAX, set);
            }
        }
    }

    #[test]
    fn masks_store_in_two_byte_lookups() {
        for mask in [0u32, 1, 0x80, 0x100, 0x8001, 0xffff, 0xa5c3] {
            for len in [0, 1, 7, 8, 9, 15, 16] {
                let mut out = vec![true; len];
                if len <= 8 {
                    store_mask::<f32x8>(&mut out, mask);
                    for (k, &b) in out.iter().enumerate() {
                        assert_eq!(b, mask & (1 << k) != 0, "8 lanes: mask {mask:#x} lane {k}");
                    }
                }
                store_mask::<f32x16>(&mut out, mask);
                for (k, &b) in out.iter().enumerate() {
                    assert_eq!(b, mask & (1 << k) != 0, "mask {mask:#x} lane {k}");
                }
            }
        }
    }

    #[test]
    fn both_widths_have_their_lane_indices_and_sign_fill() {
        assert_eq!(<f32x16 as Lanes>::LANE_INDEX.to_array()[15], 15.0);
        assert_eq!(<f32x8 as Lanes>::LANE_INDEX.to_array()[7], 7.0);
        assert_eq!(<u32x16 as LanesU>::LANE_INDEX.to_array()[9], 9);
        let u = <u32x16 as LanesU>::splat(0x8000_0001).sign_fill();
        assert_eq!(u.to_array(), [u32::MAX; 16]);
        let u = <u32x8 as LanesU>::splat(0x7fff_ffff).sign_fill();
        assert_eq!(u.to_array(), [0; 8]);
        assert_eq!(LaneWidth::Eight.lanes(), 8);
        assert_eq!(LaneWidth::Sixteen.lanes(), 16);
        assert_eq!(LaneWidth::Auto.resolve(), LaneWidth::NATIVE);
    }

    /// mul_high, shr_each and lookup at both widths, against u64 products, shifts and indexing
    /// on edge values.
    fn integer_ops_equal_scalar<U: LanesU>(to_array: impl Fn(U) -> Vec<u32>) {
        let n = <U::F as Lanes>::N;
        let values = [
            0u32,
            1,
            2,
            3,
            23,
            24,
            25,
            0x7fff_ffff,
            0x8000_0000,
            0xffff_fffe,
            u32::MAX,
        ];
        let x =
            U::from_fn(|k| values[k % values.len()].wrapping_add(k as u32 / values.len() as u32));
        let xs = to_array(x);
        for m in [0xaaaa_aaabu32, 3, u32::MAX] {
            let want: Vec<u32> = xs
                .iter()
                .map(|&v| ((u64::from(v) * u64::from(m)) >> 32) as u32)
                .collect();
            assert_eq!(to_array(x.mul_high(m)), want, "mul_high by {m:#x}");
        }
        for v in xs.iter().copied() {
            assert_eq!(to_array(U::splat(v).mul_high(0xaaaa_aaab) >> 1)[0], v / 3);
        }
        let by = U::from_fn(|k| (k as u32 * 7) % 32);
        let want: Vec<u32> = xs
            .iter()
            .enumerate()
            .map(|(k, &v)| v >> ((k as u32 * 7) % 32))
            .collect();
        assert_eq!(to_array(x.shr_each(by)), want);
        let table = U::from_fn(|k| 100 + k as u32);
        let idx = U::from_fn(|k| ((k * 5 + 3) % n) as u32);
        let want: Vec<u32> = (0..n).map(|k| 100 + ((k * 5 + 3) % n) as u32).collect();
        assert_eq!(to_array(idx.lookup(table)), want);
    }

    #[test]
    fn integer_ops_at_both_widths() {
        integer_ops_equal_scalar::<u32x8>(|v| v.to_array().to_vec());
        integer_ops_equal_scalar::<u32x16>(|v| v.to_array().to_vec());
    }

    #[test]
    fn padded_loads() {
        let c = [1.0, 2.0, 3.0];
        assert_eq!(
            <f32x8 as Lanes>::load(&c, 0, 9.0).to_array(),
            [1.0, 2.0, 3.0, 9.0, 9.0, 9.0, 9.0, 9.0]
        );
        let wide = <f32x16 as Lanes>::load(&c, 1, 9.0).to_array();
        assert_eq!(wide[..2], [2.0, 3.0]);
        assert!(wide[2..].iter().all(|&x| x == 9.0));
        let got = load_live(&c, 1, 2).to_array();
        assert_eq!(got[..2], [2.0, 3.0]);
        assert!(got[2..].iter().all(|x| x.is_nan()));
        assert_eq!(live_lanes::<f32x8>(8, 11), 0b111);
        assert_eq!(live_lanes::<f32x16>(0, 40), 0xffff);
        assert_eq!(live_lanes::<f32x16>(32, 40), 0xff);
    }
}
