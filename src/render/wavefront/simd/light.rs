//! Light sampling on N lanes (8 or 16, one source generic over [`Lanes`]): the hashed
//! uniforms, jittered strata and Owen-scrambled Sobol points of one (pixel, sample, bounce,
//! light) stream on a parallelogram light (the per-stream point sets in `point_sets.rs`), and
//! the shadow rays from a hit to them.

use super::point_sets::{self, mix32x8, owen_scramble_rev8, reverse_bits8, unit};
use crate::render::sampling::Stream;
use crate::render::spawn::{LightEnd, SurfaceHit};
use crate::render::wavefront::batch::ShadowBlock;
use crate::render::wavefront::lanes::{Lanes, LanesU};
use glam::Vec3;

/// Uniform numbers in [0, 1) for dimensions `dims` of the stream whose hash prefix is `prefix`
/// (see `shadow::key_prefix`): twin of `sampling::uniform`.
#[inline(always)]
fn uniform8<U: LanesU>(prefix: u32, dims: U) -> U::F {
    unit(mix32x8(U::splat(prefix) ^ dims))
}

/// How a block's (u, v) are drawn: the samplers with a SIMD twin.
#[derive(Clone, Copy, Debug)]
pub enum BlockSampler<'a> {
    /// Two hashed uniforms per point: random sampling, and the lab's strategy for N > 1.
    Random,
    /// Jittered strata: the stratum column and row of every sample index, as floats (from
    /// `sampling::strata_grid`), and the grid size.
    Stratified {
        /// Column of sample j.
        cell_x: &'a [f32],
        /// Row of sample j.
        cell_y: &'a [f32],
        /// Columns.
        nx: f32,
        /// Rows.
        ny: f32,
    },
    /// Owen-scrambled Sobol, dimensions 0 and 1, with the stream's scramble seed
    /// `sampling::hash(key, SOBOL_SEED_DIM)`.
    Sobol {
        /// The scramble seed.
        scramble: u32,
    },
    /// The samplers with per-stream state (halton, pmj02, zsobol, bluenoise): Halton's digit
    /// loops, ZSobol's index and PMJ02's table rows on N lanes (`point_sets.rs`), the
    /// blue-noise tables one lane at a time through the scalar `Stream::point`.
    Stream {
        /// The stream's state (`PointSet::stream`), taken once per (hit, light).
        stream: Stream<'a>,
        /// Points per light.
        count: u32,
    },
}

/// Where N consecutive light samples `j0..j0 + N` of one (pixel, sample, bounce, light) stream
/// land on a parallelogram light.
#[derive(Clone, Copy, Debug)]
pub struct LightBlock<'a> {
    /// `shadow::key_prefix` of the stream's SampleKey.
    pub prefix: u32,
    /// First sample index of the block.
    pub j0: u32,
    /// The sampler.
    pub sampler: BlockSampler<'a>,
    /// Corner a of the light.
    pub origin: Vec3,
    /// b − a.
    pub edge_u: Vec3,
    /// d − a.
    pub edge_v: Vec3,
}

/// x / n, as a multiplication when n is a power of two (16 and 64 points make 4×4 and 8×8
/// strata): x · 2⁻ᵏ and x / 2ᵏ are both the correctly rounded value of the same real number,
/// so the bits are the same, and a multiply is several times cheaper than a divide.
#[inline(always)]
fn divide<V: Lanes>(x: V, n: f32) -> V {
    if n > 0.0 && n.is_normal() && n.to_bits() & 0x007f_ffff == 0 {
        x * V::splat(1.0 / n)
    } else {
        x / V::splat(n)
    }
}

/// Light points x, y, z of samples `j0..j0 + N`: lane k equals
/// `light.point(points.point(key, j0 + k))` for the render's `PointSet`.
#[inline(always)]
pub fn light_points<V: Lanes>(b: &LightBlock) -> [V::Array; 3] {
    let j = V::U::splat(b.j0) + V::U::LANE_INDEX;
    let (u, v) = match b.sampler {
        BlockSampler::Random => (
            uniform8(b.prefix, j + j),
            uniform8(b.prefix, j + j + V::U::ONE),
        ),
        BlockSampler::Stratified {
            cell_x,
            cell_y,
            nx,
            ny,
        } => {
            let xi0 = uniform8(b.prefix, j + j);
            let xi1 = uniform8(b.prefix, j + j + V::U::ONE);
            let at = b.j0 as usize;
            let cx = V::load(cell_x, at, 0.0);
            let cy = V::load(cell_y, at, 0.0);
            let one_minus_eps = V::splat(crate::render::sampling::ONE_MINUS_EPS);
            (
                divide(cx + xi0, nx).fast_min(one_minus_eps),
                divide(cy + xi1, ny).fast_min(one_minus_eps),
            )
        }
        BlockSampler::Sobol { scramble } => sobol8(j, scramble),
        BlockSampler::Stream { stream, count } => stream_points::<V>(&stream, count, b.j0),
    };
    parallelogram_points8(b.origin, b.edge_u, b.edge_v, u, v)
}

/// Points `j0..j0 + N` of a per-stream sampler: Halton, ZSobol and PMJ02 on lanes, the
/// blue-noise tables per lane. Out of line, so that the lab's four samplers' path keeps its
/// code (the instruction-count gate, `tests/gates/icount.rs`).
#[inline(never)]
fn stream_points<V: Lanes>(stream: &Stream, count: u32, j0: u32) -> (V, V) {
    let j = V::U::splat(j0) + V::U::LANE_INDEX;
    match stream {
        Stream::Halton { digits, seeds } => point_sets::halton(j, *digits, *seeds),
        Stream::Zsobol(index) => point_sets::zsobol(j, index),
        Stream::Pmj02 { table, masks } => point_sets::pmj02::<V::U>(table, j0, *masks),
        Stream::Bluenoise { .. } => per_lane::<V>(stream, count, j0),
    }
}

/// Points `j0..j0 + N` of a stream of `count`, each from the scalar `Stream::point`; lanes
/// past the count get (0, 0). Out of line, as `Stream::point` is.
#[inline(never)]
fn per_lane<V: Lanes>(stream: &Stream, count: u32, j0: u32) -> (V, V) {
    let (mut u, mut v) = (V::ZERO.to_array(), V::ZERO.to_array());
    let live = (count.saturating_sub(j0) as usize).min(V::N);
    for k in 0..live {
        let (pu, pv) = stream.point(j0 + k as u32);
        u[k] = pu;
        v[k] = pv;
    }
    (V::from_array(u), V::from_array(v))
}

/// The first 16 reversed-bit direction numbers of Sobol dimensions 0 and 1, as
/// `sobol_burley::parts::sobol_rev` uses them: vector k is what a reversed index with only bit
/// 31 − k set selects.
static SOBOL_VECTORS: std::sync::LazyLock<[[u32; 16]; 2]> = std::sync::LazyLock::new(|| {
    let vectors = |d| std::array::from_fn(|k| sobol_burley::parts::sobol_rev(1 << (31 - k), d));
    [vectors(0), vectors(1)]
});

/// `sobol_burley::parts::u32_to_f32_norm`, N lanes.
#[inline(always)]
fn u32_to_f32_norm8<U: LanesU>(n: U) -> U::F {
    let bits = (n >> 9) | U::splat(0x3f80_0000);
    bits.bits_to_f32() - U::F::ONE
}

/// Dimensions 0 and 1 of Owen-scrambled Sobol points `j`: lane k equals
/// `sobol_burley::sample(j[k], 0 | 1, scramble)`, the crate's own steps on 8 lanes (the
/// index shuffle, the direction-number XOR over the top 16 bits, the per-dimension scramble).
#[inline(always)]
fn sobol8<U: LanesU>(j: U, scramble: u32) -> (U::F, U::F) {
    use sobol_burley::parts::hash;
    let index = owen_scramble_rev8(reverse_bits8(j), hash(scramble ^ 0x79c6_8e4a));
    let vectors = &*SOBOL_VECTORS;
    let (mut s0, mut s1) = (U::ZERO, U::ZERO);
    for (k, (&v0, &v1)) in vectors[0].iter().zip(&vectors[1]).enumerate() {
        // All ones where bit 31 − k of the index is set.
        let bit = (index << k as u32).sign_fill();
        s0 = s0 ^ (bit & U::splat(v0));
        s1 = s1 ^ (bit & U::splat(v1));
    }
    let seed = scramble.wrapping_mul(0x9c8f_2d3b);
    let s0 = owen_scramble_rev8(s0, hash(seed ^ 0x912f_69ba));
    let s1 = owen_scramble_rev8(s1, hash(seed ^ 0x174f_18ab));
    (
        u32_to_f32_norm8(reverse_bits8(s0)),
        u32_to_f32_norm8(reverse_bits8(s1)),
    )
}

/// origin + u·edge_u + v·edge_v on N lanes: lane k equals `light.point(u[k], v[k])`.
#[inline(always)]
fn parallelogram_points8<V: Lanes>(
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    u: V,
    v: V,
) -> [V::Array; 3] {
    // origin + u·edge_u + v·edge_v, evaluated left to right like glam.
    let axis =
        |o: f32, eu: f32, ev: f32| (V::splat(o) + u * V::splat(eu) + v * V::splat(ev)).to_array();
    [
        axis(origin.x, edge_u.x, edge_v.x),
        axis(origin.y, edge_u.y, edge_v.y),
        axis(origin.z, edge_u.z, edge_v.z),
    ]
}

/// Shadow rays from `hit` to N light points, the first `lanes` of them real: lane k equals
/// `spawn::shadow_ray(hit, target_k, end)` (l, tmax and the distance; the origin is the
/// block's). Lanes for which the twin returns `None`, or past `lanes`, come back dead: tmax = 0.
#[inline]
pub fn shadow_rays<V: Lanes>(
    hit: &SurfaceHit,
    target: &[V::Array; 3],
    end: &LightEnd,
    lanes: usize,
) -> ShadowBlock<V::Array> {
    let n = hit.normal;
    let x = V::from_array(target[0]) - V::splat(hit.point.x);
    let y = V::from_array(target[1]) - V::splat(hit.point.y);
    let z = V::from_array(target[2]) - V::splat(hit.point.z);
    let above = V::splat(n.x) * x + V::splat(n.y) * y + V::splat(n.z) * z;
    let dist = (x * x + y * y + z * z).sqrt();
    let (lx, ly, lz) = (x / dist, y / dist, z / dist);
    let n_dot_l = V::splat(n.x) * lx + V::splat(n.y) * ly + V::splat(n.z) * lz;
    let tmax = dist * V::splat(end.ratio);
    let first = V::LANE_INDEX.simd_lt(V::splat(lanes as f32));
    let live = above.simd_gt(V::splat(end.margin)) & tmax.simd_gt(V::ZERO) & first;
    ShadowBlock {
        origin: hit.leaving_point(),
        l: [lx.to_array(), ly.to_array(), lz.to_array()],
        tmax: live.select(tmax, V::ZERO).to_array(),
        n_dot_l: live.select(n_dot_l, V::ZERO).to_array(),
        dist: dist.to_array(),
        live: live.to_bitmask(),
    }
}
