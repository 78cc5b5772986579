//! One stream's points, for the samplers whose per-stream work is large: what they compute
//! once per (pixel, sample, bounce, light) is kept, and [`Stream::point`] does only the work
//! of one point. `PointSet::point(key, j)` is `PointSet::stream(key).point(j)` for them.

use super::{PointSet, SampleKey, bluenoise, halton, pmj02, zsobol};

/// The per-stream state of the table and digit-loop samplers.
#[derive(Clone, Copy, Debug)]
pub enum Stream<'a> {
    /// The scramble seeds of the two bases.
    Halton {
        /// Digits per base (`halton::digits`).
        digits: (u32, u32),
        /// Scramble seeds of bases 2 and 3.
        seeds: (u32, u32),
    },
    /// The stream's table and its XOR masks.
    Pmj02 {
        /// The table.
        table: &'a [(u32, u32)],
        /// The digital shift of x and y.
        masks: (u32, u32),
    },
    /// The index's digits above the points', permuted once, and their Sobol contribution.
    Zsobol(zsobol::StreamIndex),
    /// The tables and where the stream reads them.
    Bluenoise {
        /// The tables.
        tables: bluenoise::Tables,
        /// The stream's place in them.
        stream: bluenoise::Stream,
    },
}

impl Stream<'_> {
    /// Point `j` of the stream. Out of line: inlined into the engines' loops beside the lab's
    /// four samplers, these samplers' code cost those instructions (tests/gates/icount.rs).
    #[inline(never)]
    pub fn point(&self, j: u32) -> (f32, f32) {
        match self {
            Stream::Halton { digits, seeds } => halton::point(j, *digits, *seeds),
            Stream::Pmj02 { table, masks } => pmj02::point(table, j, *masks),
            Stream::Zsobol(index) => index.point(j),
            Stream::Bluenoise { tables, stream } => stream.point(tables, j),
        }
    }
}

impl PointSet {
    /// The stream of `key` for the table and digit-loop samplers (halton, pmj02, zsobol,
    /// bluenoise); `None` for the lab's four, whose points need no per-stream state.
    pub fn stream(&self, key: &SampleKey) -> Option<Stream<'_>> {
        use super::{HALTON_SEED_DIM, LightSampler, PMJ02_SEED_DIM, hash, mix32};
        let count = self.count;
        Some(match self.sampler {
            LightSampler::Halton => Stream::Halton {
                digits: self.halton_digits,
                seeds: (hash(key, HALTON_SEED_DIM), hash(key, HALTON_SEED_DIM - 1)),
            },
            LightSampler::Pmj02 => {
                let h = hash(key, PMJ02_SEED_DIM);
                let tables = self.pmj02.unwrap_or_else(|| pmj02::tables(count));
                Stream::Pmj02 {
                    table: &tables[h as usize % tables.len()],
                    masks: (mix32(h ^ 0x243f_6a88), mix32(h ^ 0x85a3_08d3)),
                }
            }
            LightSampler::Zsobol => Stream::Zsobol(zsobol::StreamIndex::new(&self.zsobol, key)),
            LightSampler::Bluenoise => Stream::Bluenoise {
                tables: self
                    .bluenoise
                    .unwrap_or_else(|| bluenoise::Tables::for_samples(count)),
                stream: bluenoise::Stream::new(key, self.width, count),
            },
            _ => return None,
        })
    }
}
