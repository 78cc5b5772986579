//! The lane layer: everything the 8-wide kernels share about lanes, in one place (like
//! memchr's `vector.rs`). It owns the lane count, the padded loads from columns, the mask
//! tables, the view of a vector as its 8 lanes, the bit casts between lane types, and the
//! iterator over a bitmask's set lanes.
//!
//! This is the only file of the crate that names the `wide` crate or `bytemuck`: the kernels
//! (`simd/`, `shade.rs`, `bvh/`) take the lane types from here, and `tests/layering.rs` checks
//! that nothing else reaches for them.

pub(crate) use wide::{f32x8, i32x8, u32x8};

/// The SIMD width: lanes per vector, children per BVH node, triangles per block.
pub const LANES: usize = 8;

/// `col[i..i + 8]` as one vector, `pad` in the lanes past the column's end.
#[inline(always)]
pub(crate) fn load(col: &[f32], i: usize, pad: f32) -> f32x8 {
    match col.get(i..i + LANES) {
        Some(s) => f32x8::new(s.try_into().expect("8 lanes")),
        None => {
            let mut a = [pad; LANES];
            let rest = &col[i.min(col.len())..];
            a[..rest.len()].copy_from_slice(rest);
            f32x8::new(a)
        }
    }
}

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

/// The live lanes of the chunk starting at `i` of a batch of `len`, as a bitmask.
#[inline(always)]
pub(crate) fn live_lanes(i: usize, len: usize) -> u32 {
    let n = (len - i).min(LANES);
    (1u32 << n) - 1
}

/// The 8 lanes of a vector, in place.
#[inline(always)]
pub(crate) fn view(v: &f32x8) -> &[f32; LANES] {
    wide::bytemuck::cast_ref(v)
}

/// The bits of every lane, as unsigned integers.
#[inline(always)]
pub(crate) fn f32_bits(v: f32x8) -> u32x8 {
    wide::bytemuck::cast(v)
}

/// The bits of every lane, as signed integers (a lane's sign bit is its sign).
#[inline(always)]
pub(crate) fn f32_bits_signed(v: f32x8) -> i32x8 {
    wide::bytemuck::cast(v)
}

/// Every lane's bits read as a float.
#[inline(always)]
pub(crate) fn f32_from_bits(v: u32x8) -> f32x8 {
    wide::bytemuck::cast(v)
}

/// Every lane's bits moved from a signed integer vector to a float vector (masks).
#[inline(always)]
pub(crate) fn f32_from_signed(v: i32x8) -> f32x8 {
    wide::bytemuck::cast(v)
}

/// Unsigned lanes reinterpreted as signed (same bits).
#[inline(always)]
pub(crate) fn signed(v: u32x8) -> i32x8 {
    wide::bytemuck::cast(v)
}

/// Signed lanes reinterpreted as unsigned (same bits).
#[inline(always)]
pub(crate) fn unsigned(v: i32x8) -> u32x8 {
    wide::bytemuck::cast(v)
}

/// 8 ids as signed lanes (same bits), to compare them in one instruction.
#[inline(always)]
pub(crate) fn ids(v: [u32; LANES]) -> i32x8 {
    wide::bytemuck::cast(v)
}

/// Lane k of an 8-lane bitmask as a bool, for all 256 masks: a chunk's results are stored with
/// one 8-byte copy instead of a loop over lanes (that loop was 6% of the lab benchmark's
/// instructions).
pub(crate) const MASK_BOOLS: [[bool; LANES]; 256] = {
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

/// The lane indices 0..8 as floats, to build "lane < count" masks.
pub(crate) const LANE_INDEX: [f32; LANES] = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];

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
    fn padded_loads() {
        let c = [1.0, 2.0, 3.0];
        assert_eq!(
            load(&c, 0, 9.0).to_array(),
            [1.0, 2.0, 3.0, 9.0, 9.0, 9.0, 9.0, 9.0]
        );
        let got = load_live(&c, 1, 2).to_array();
        assert_eq!(got[..2], [2.0, 3.0]);
        assert!(got[2..].iter().all(|x| x.is_nan()));
        assert_eq!(live_lanes(8, 11), 0b111);
    }
}
