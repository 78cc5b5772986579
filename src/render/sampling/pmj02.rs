//! Progressive multi-jittered (0,2) points (Christensen, Kensler and Kilpatrick, EGSR 2018),
//! from a generator of our own, and their use as a light sampler.
//!
//! A (0,2) sequence in base 2: for every m, each aligned block of 2^m points is a (0,m,2)-net,
//! one point in every elementary interval of area 2^-m (every grid of 2^k × 2^(m−k) cells).
//! The sequence is progressive: the points are placed one at a time, each in a cell that the
//! points before it leave empty at the next power of two, so every prefix is well spread, not
//! only the powers of two.
//!
//! ```text
//! generate(n, seed):  point 0 uniform
//!   point i, 2^(m-1) ≤ i < 2^m:       (occupancy grids of level m: every shape k = 0..m)
//!     prefer the sub-quadrant the paper gives it, from its partner i − 2^(m−1):
//!       m odd:  the diagonally opposite one within the partner's square cell;
//!       m even: one of the two left free (flip x or y, at random), the partner's partner
//!               flipping the same axis, which lands in the other
//!     choose a finest cell (X, Y), 2^-m on a side, in no occupied interval of any shape:
//!       X in random order among the free 1-D columns, Y bit by bit from the top with
//!       random branch order, pruned by the shape each bit completes
//!     (no free cell with the preference: the same search without it)
//!     the point: uniform within that cell (32-bit fixed point)
//! ```
//!
//! The light sampler reads [`SETS`] tables of [`TABLE_POINTS`] points, generated once from
//! fixed seeds on first use. A stream takes one table by its hash and XORs both coordinates'
//! bits with two hashed masks (a random digital shift): XOR maps every elementary interval
//! onto another of the same shape, so the shifted points are still a (0,2) sequence, and it
//! makes each point uniform on the square, which makes the estimate unbiased.

use super::SplitMix64;
use std::sync::OnceLock;

/// Points per table: the most points per light the `pmj02` sampler takes.
pub const TABLE_POINTS: usize = 4096;

/// Tables the streams choose among.
const SETS: usize = 8;

/// The tables of each power-of-two size, generated on first use: a set of 4096 points takes
/// about 25 ms, one of 16 points 5 µs, and a stream of N points reads the tables of the next
/// power of two. The generator is progressive and its random bits per point do not depend on
/// the length asked for, so a smaller table is a prefix of a larger one from the same seed.
static TABLES: [OnceLock<Vec<Table>>; LEVELS] = [const { OnceLock::new() }; LEVELS];

/// One generated sequence: 32-bit fixed-point (x, y).
pub type Table = Vec<(u32, u32)>;

/// Table sizes: 1, 2, 4, ..., [`TABLE_POINTS`].
const LEVELS: usize = TABLE_POINTS.trailing_zeros() as usize + 1;

/// The [`SETS`] tables that hold at least `points` points (at most [`TABLE_POINTS`]), as
/// 32-bit fixed-point coordinates.
pub fn tables(points: u32) -> &'static [Table] {
    let size = (points.max(1) as usize)
        .next_power_of_two()
        .min(TABLE_POINTS);
    TABLES[size.trailing_zeros() as usize].get_or_init(|| {
        (0..SETS as u64)
            .map(|set| generate(size, 0x706d_6a30_3262 ^ set))
            .collect()
    })
}

/// Point `index` of `table`, its bits XORed with `masks`: in [0, 1)² to 24 bits.
#[inline]
pub fn point(table: &[(u32, u32)], index: u32, masks: (u32, u32)) -> (f32, f32) {
    let (x, y) = table[index as usize % table.len()];
    let unit = |bits: u32| (bits >> 8) as f32 * (1.0 / 16_777_216.0);
    (unit(x ^ masks.0), unit(y ^ masks.1))
}

/// The top `bits` bits of `x` (0 for none).
#[inline]
fn top(x: u32, bits: u32) -> u32 {
    if bits == 0 { 0 } else { x >> (32 - bits) }
}

/// Bit `k` of `x`, counted from the top (k = 0 the highest).
#[inline]
fn bit(x: u32, k: u32) -> u32 {
    (x >> (31 - k)) & 1
}

/// Which elementary intervals of level m hold a point of the points so far: for each shape k
/// (2^k columns × 2^(m−k) rows), a cell per interval, column-major.
struct Occupancy {
    m: u32,
    /// `shapes[k][cell]`.
    shapes: Vec<Vec<bool>>,
}

impl Occupancy {
    fn new(m: u32, points: &[(u32, u32)]) -> Self {
        let mut o = Occupancy {
            m,
            shapes: vec![vec![false; 1 << m]; m as usize + 1],
        };
        for &p in points {
            o.mark(p);
        }
        o
    }

    fn mark(&mut self, (x, y): (u32, u32)) {
        let m = self.m;
        for k in 0..=m {
            let cell = (top(x, k) << (m - k)) | top(y, m - k);
            self.shapes[k as usize][cell as usize] = true;
        }
    }

    /// True when the interval of shape k = m − d of the finest cell with column X (m bits)
    /// and top d row bits `y_top` holds a point.
    fn taken(&self, x: u32, d: u32, y_top: u32) -> bool {
        self.shapes[(self.m - d) as usize][(((x >> d) << d) | y_top) as usize]
    }

    /// A row Y for column X (both m-bit) in no occupied interval, its top `prefix.0` bits equal
    /// to `prefix.1` when given; `None` when there is none. Y is built from its top bit down
    /// (`d` bits chosen so far, `y_top`; start at 0, 0): with d bits chosen, the shape whose rows
    /// have d bits is complete and is checked.
    fn row(
        &self,
        x: u32,
        d: u32,
        y_top: u32,
        prefix: Option<(u32, u32)>,
        rng: &mut SplitMix64,
    ) -> Option<u32> {
        if self.taken(x, d, y_top) {
            return None;
        }
        if d == self.m {
            return Some(y_top);
        }
        let first = (rng.next_u64() & 1) as u32;
        for b in [first, first ^ 1] {
            if let Some((bits, value)) = prefix
                && d < bits
                && b != (value >> (bits - 1 - d)) & 1
            {
                continue;
            }
            if let Some(y) = self.row(x, d + 1, (y_top << 1) | b, prefix, rng) {
                return Some(y);
            }
        }
        None
    }
}

/// The cell (X, Y) for a new point at level m: with the preferred top bits of X and Y first,
/// then without; `None` at a dead end.
fn choose(
    grid: &Occupancy,
    prefer: Option<((u32, u32), (u32, u32))>,
    rng: &mut SplitMix64,
) -> Option<(u32, u32)> {
    let m = grid.m;
    let mut columns: Vec<u32> = (0..1u32 << m).filter(|&x| !grid.taken(x, 0, 0)).collect();
    // Fisher–Yates: the columns in random order.
    for i in (1..columns.len()).rev() {
        columns.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
    let mut attempts = Vec::new();
    if let Some(p) = prefer {
        attempts.push(Some(p));
    }
    attempts.push(None);
    for attempt in attempts {
        for &x in &columns {
            if let Some(((bits, value), _)) = attempt
                && x >> (m - bits) != value
            {
                continue;
            }
            if let Some(y) = grid.row(x, 0, 0, attempt.map(|(_, py)| py), rng) {
                return Some((x, y));
            }
        }
    }
    None
}

/// The first `n` points of a PMJ(0,2) sequence from `seed`, as 32-bit fixed point. Restarts
/// with the next seed at a dead end (a point with no free cell: not met for the tables'
/// seeds, and tested).
pub fn generate(n: usize, seed: u64) -> Vec<(u32, u32)> {
    let mut seed = seed;
    loop {
        if let Some(points) = try_generate(n, seed) {
            return points;
        }
        seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    }
}

/// [`generate`] without the restart: `None` at a dead end.
fn try_generate(n: usize, seed: u64) -> Option<Vec<(u32, u32)>> {
    let mut rng = SplitMix64(seed);
    let mut points = Vec::with_capacity(n);
    if n == 0 {
        return Some(points);
    }
    points.push((rng.next_u64() as u32, rng.next_u64() as u32));
    let mut grid = Occupancy::new(0, &points);
    // For even levels: whether point j's new partner flips x (else y).
    let mut flips: Vec<bool> = Vec::new();
    for i in 1..n {
        let m = usize::BITS - i.leading_zeros();
        if i.is_power_of_two() {
            grid = Occupancy::new(m, &points);
            flips.clear();
        }
        let j = i - (1 << (m - 1));
        let (xo, yo) = points[j];
        let prefer = if m % 2 == 1 {
            // From 4^k points (square cells 2^-k on a side) to twice as many: the diagonally
            // opposite sub-quadrant of the partner's cell.
            let k = (m - 1) / 2;
            let px = (top(xo, k) << 1) | (bit(xo, k) ^ 1);
            let py = (top(yo, k) << 1) | (bit(yo, k) ^ 1);
            Some(((k + 1, px), (k + 1, py)))
        } else {
            // From 2·4^k points to 4^(k+1): each square cell holds two points in opposite
            // sub-quadrants; the new points take the other two, one flipping x, one y.
            let k = (m - 2) / 2;
            let half = 1usize << (m - 2);
            let flip_x = if j < half {
                let f = rng.next_u64() & 1 == 1;
                flips.push(f);
                f
            } else {
                // The partner sits in the diagonally opposite sub-quadrant: the same flip
                // lands in the other free one.
                flips[j - half]
            };
            let px = (top(xo, k) << 1) | (bit(xo, k) ^ u32::from(flip_x));
            let py = (top(yo, k) << 1) | (bit(yo, k) ^ u32::from(!flip_x));
            Some(((k + 1, px), (k + 1, py)))
        };
        let (x, y) = choose(&grid, prefer, &mut rng)?;
        let jitter = |r: u64| if m == 32 { 0 } else { (r as u32) >> m };
        let p = (
            (x << (32 - m)) | jitter(rng.next_u64()),
            (y << (32 - m)) | jitter(rng.next_u64()),
        );
        grid.mark(p);
        points.push(p);
    }
    Some(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every prefix of `points` is stratified at its level: the first n points, 2^(m−1) < n ≤
    /// 2^m, put at most one point in each elementary interval of area 2^-m, of every shape
    /// 2^k × 2^(m−k) (exactly one when n = 2^m: a (0,m,2)-net).
    fn assert_progressive_02(points: &[(u32, u32)]) {
        for n in 1..=points.len() {
            let m = usize::BITS - (n - 1).leading_zeros();
            for k in 0..=m {
                let mut seen = vec![false; 1 << m];
                for &(x, y) in &points[..n] {
                    let cell = ((top(x, k) << (m - k)) | top(y, m - k)) as usize;
                    assert!(
                        !seen[cell],
                        "prefix {n}, shape {k} of level {m}: two points in cell {cell}"
                    );
                    seen[cell] = true;
                }
            }
        }
    }

    #[test]
    fn generated_sequences_are_progressive_02_without_a_restart() {
        for seed in 0..20u64 {
            let points = try_generate(256, seed).expect("no dead end");
            assert_progressive_02(&points);
        }
    }

    #[test]
    fn smaller_tables_are_prefixes_of_larger_ones() {
        let (small, large) = (tables(16), tables(64));
        assert_eq!(small.len(), SETS);
        for (s, l) in small.iter().zip(large) {
            assert_eq!((s.len(), l.len()), (16, 64));
            assert_eq!(s[..], l[..16]);
        }
        assert_eq!(tables(17)[0].len(), 32);
        assert_eq!(tables(0)[0].len(), 1);
        assert_eq!(tables(1 << 20)[0].len(), TABLE_POINTS);
    }
}
