//! The 8-wide kernels: with `bvh.rs` (the mesh BVH's node and leaf tests), the only module that
//! names `wide` types.
//!
//! Every kernel here is a lane-by-lane copy of a scalar twin, with the same operations in the
//! same order, so that with IEEE arithmetic (no FMA contraction: Rust never fuses `a * b + c`,
//! and neither does `wide`) each lane gives the same bits as the twin:
//!
//! | kernel               | scalar twin                                              |
//! |----------------------|----------------------------------------------------------|
//! | [`moller_trumbore8`] | `geometry::intersect_triangle` (8 rays × 1 triangle in [`triangle8`], 1 ray × 8 triangles in `bvh.rs`) |
//! | [`sphere8`]          | `geometry::intersect_sphere`                             |
//! | [`closest_hits`]     | `Accel::closest` without a BVH                           |
//! | [`occluded`]         | `Accel::occluded` without a BVH                          |
//! | [`light_points8`]    | `sampling::square_sample` then `Light::point`            |
//! | [`shadow_rays8`]     | the start of `Reference::direct` (l, dist, n·l)          |
//!
//! Branches become masks: a lane that misses gets `f32::INFINITY`, exactly like the twins'
//! sentinel. Batches whose length is not a multiple of 8 are padded with lanes that cannot hit
//! (tmax = 0, NaN directions), and the padding is never stored back.

use super::batch::ShadowBlock;
use super::context::MaterialTerms;
use super::lanes::{
    LANE_INDEX, LANES, MASK_BOOLS, f32_from_bits, f32x8, live_lanes, load, signed, u32x8, unsigned,
};
use crate::geometry::Ray;
use crate::geometry::{EDGE_EPSILON, MISS_MARGIN, T_MIN};
use crate::scene::{NO_HIT, Sphere, Triangle};
use crate::spawn::{LightEnd, SurfaceHit};
use glam::Vec3;

/// Ray columns of a batch, borrowed: origin, direction and tmax.
#[derive(Clone, Copy)]
pub struct RayColumns<'a> {
    /// origin x, y, z.
    pub origin: [&'a [f32]; 3],
    /// direction x, y, z.
    pub direction: [&'a [f32]; 3],
    /// End of the interval (T_MIN, tmax).
    pub tmax: &'a [f32],
}

impl RayColumns<'_> {
    /// Number of rays.
    pub fn len(&self) -> usize {
        self.tmax.len()
    }
    /// True without rays.
    pub fn is_empty(&self) -> bool {
        self.tmax.is_empty()
    }
    /// Ray `i`.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        let (o, d) = (self.origin, self.direction);
        Ray {
            origin: Vec3::new(o[0][i], o[1][i], o[2][i]),
            direction: Vec3::new(d[0][i], d[1][i], d[2][i]),
        }
    }
}

/// Eight rays in registers.
#[derive(Clone, Copy)]
pub struct Rays8 {
    ox: f32x8,
    oy: f32x8,
    oz: f32x8,
    dx: f32x8,
    dy: f32x8,
    dz: f32x8,
}

impl Rays8 {
    /// Loads rays `i..i + 8` (padding past the end with NaN directions).
    #[inline(always)]
    fn load(r: &RayColumns, i: usize) -> Rays8 {
        Rays8 {
            ox: load(r.origin[0], i, 0.0),
            oy: load(r.origin[1], i, 0.0),
            oz: load(r.origin[2], i, 0.0),
            dx: load(r.direction[0], i, f32::NAN),
            dy: load(r.direction[1], i, f32::NAN),
            dz: load(r.direction[2], i, f32::NAN),
        }
    }
}

/// Möller–Trumbore's operands on 8 lanes, as columns: ray origin o and direction d, triangle
/// corner v0 and edges e1, e2. [`triangle8`] splats the triangle (8 rays, one triangle), the
/// mesh BVH's leaf test splats the ray (one ray, 8 triangles); the arithmetic is
/// [`moller_trumbore8`] and [`moller_trumbore8_blocks`] either way.
#[derive(Clone, Copy)]
pub(crate) struct TriangleLanes {
    pub o: [f32x8; 3],
    pub d: [f32x8; 3],
    pub v0: [f32x8; 3],
    pub e1: [f32x8; 3],
    pub e2: [f32x8; 3],
}

impl TriangleLanes {
    /// One triangle against 8 rays.
    #[inline(always)]
    fn splat_triangle(tri: &Triangle, r: &Rays8) -> TriangleLanes {
        let splat = |v: Vec3| [f32x8::splat(v.x), f32x8::splat(v.y), f32x8::splat(v.z)];
        TriangleLanes {
            o: [r.ox, r.oy, r.oz],
            d: [r.dx, r.dy, r.dz],
            v0: splat(tri.v0),
            e1: splat(tri.e1),
            e2: splat(tri.e2),
        }
    }
}

/// Möller–Trumbore on 8 lanes; lane k equals `intersect_triangle(tri_k, ray_k, tmax_k,
/// two_sided)`, the same operations in the same order.
///
/// ```text
/// p = d × e2; det = e1·p; facing = det > 0 (det ≠ 0 if two-sided)
/// s = o − v0; u = s·p / det; q = s × e1; v = d·q / det; t = e2·q / det
/// hit = facing ∧ u ≥ −ε ∧ v ≥ −ε ∧ u + v ≤ 1 + ε ∧ T_MIN < t < tmax   → t, else ∞
/// ```
#[inline(always)]
pub(crate) fn moller_trumbore8(m: &TriangleLanes, tmax: f32x8, two_sided: bool) -> f32x8 {
    let [ox, oy, oz] = m.o;
    let [dx, dy, dz] = m.d;
    let [e1x, e1y, e1z] = m.e1;
    let [e2x, e2y, e2z] = m.e2;
    // pvec = d × e2 (glam's cross: self.y * rhs.z - rhs.y * self.z, ...)
    let px = dy * e2z - e2y * dz;
    let py = dz * e2x - e2z * dx;
    let pz = dx * e2y - e2x * dy;
    let det = e1x * px + e1y * py + e1z * pz;
    let facing = if two_sided {
        det.simd_ne(f32x8::ZERO)
    } else {
        det.simd_gt(f32x8::ZERO)
    };
    let inv_det = f32x8::ONE / det;
    let tx = ox - m.v0[0];
    let ty = oy - m.v0[1];
    let tz = oz - m.v0[2];
    let u = (tx * px + ty * py + tz * pz) * inv_det;
    // qvec = tvec × e1
    let qx = ty * e1z - e1y * tz;
    let qy = tz * e1x - e1z * tx;
    let qz = tx * e1y - e1x * ty;
    let v = (dx * qx + dy * qy + dz * qz) * inv_det;
    let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
    let hit = facing
        & u.simd_ge(f32x8::splat(-EDGE_EPSILON))
        & v.simd_ge(f32x8::splat(-EDGE_EPSILON))
        & (u + v).simd_le(f32x8::splat(1.0 + EDGE_EPSILON))
        & t.simd_gt(f32x8::splat(T_MIN))
        & t.simd_lt(tmax);
    hit.select(t, f32x8::splat(f32::INFINITY))
}

/// The lanes that block, as a bitmask: `moller_trumbore8(..) < tmax`, with the same values
/// computed in an order that lets all 8 lanes leave early: after det when no lane faces its
/// triangle (for one-sided faces about half the walls of a box, seen from a coherent packet of
/// shadow rays), and after t when no lane's t is in (T_MIN, tmax) (the walls behind the light).
#[inline(always)]
pub(crate) fn moller_trumbore8_blocks(m: &TriangleLanes, tmax: f32x8, two_sided: bool) -> u32 {
    let [ox, oy, oz] = m.o;
    let [dx, dy, dz] = m.d;
    let [e1x, e1y, e1z] = m.e1;
    let [e2x, e2y, e2z] = m.e2;
    let px = dy * e2z - e2y * dz;
    let py = dz * e2x - e2z * dx;
    let pz = dx * e2y - e2x * dy;
    let det = e1x * px + e1y * py + e1z * pz;
    let facing = if two_sided {
        det.simd_ne(f32x8::ZERO)
    } else {
        det.simd_gt(f32x8::ZERO)
    };
    if facing.none() {
        return 0;
    }
    let inv_det = f32x8::ONE / det;
    let tx = ox - m.v0[0];
    let ty = oy - m.v0[1];
    let tz = oz - m.v0[2];
    let qx = ty * e1z - e1y * tz;
    let qy = tz * e1x - e1z * tx;
    let qz = tx * e1y - e1x * ty;
    let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
    let in_range = facing & t.simd_gt(f32x8::splat(T_MIN)) & t.simd_lt(tmax);
    if in_range.none() {
        return 0;
    }
    let u = (tx * px + ty * py + tz * pz) * inv_det;
    let v = (dx * qx + dy * qy + dz * qz) * inv_det;
    (in_range
        & u.simd_ge(f32x8::splat(-EDGE_EPSILON))
        & v.simd_ge(f32x8::splat(-EDGE_EPSILON))
        & (u + v).simd_le(f32x8::splat(1.0 + EDGE_EPSILON)))
    .to_bitmask()
}

/// Möller–Trumbore for 8 rays against one triangle; lane k equals
/// `intersect_triangle(tri, ray_k, tmax_k, two_sided)`.
#[inline(always)]
pub fn triangle8(tri: &Triangle, r: &Rays8, tmax: f32x8, two_sided: bool) -> f32x8 {
    moller_trumbore8(&TriangleLanes::splat_triangle(tri, r), tmax, two_sided)
}

/// The lanes that `tri` blocks, as a bitmask (`moller_trumbore8_blocks`).
#[inline(always)]
fn triangle8_blocks(tri: &Triangle, r: &Rays8, tmax: f32x8, two_sided: bool) -> u32 {
    moller_trumbore8_blocks(&TriangleLanes::splat_triangle(tri, r), tmax, two_sided)
}

/// Ray–sphere for 8 rays; lane k equals `intersect_sphere(sphere, ray_k, tmax_k)`: the stable
/// form, see there.
///
/// ```text
/// oc = o − c; a = d·d; b = oc·d; f = oc − b·(1/a)·d; disc = a·(r² − f·f)
/// q = −(b + sign(b)·√disc); t0 = (oc·oc − r²)/q; t1 = q·(1/a); near, far = sorted(t0, t1)
/// t = near > T_MIN ? near : far;  hit = disc ≥ 0 ∧ T_MIN < t < tmax   → t, else ∞
/// ```
#[inline(always)]
pub fn sphere8(s: &Sphere, r: &Rays8, tmax: f32x8) -> f32x8 {
    let ocx = r.ox - f32x8::splat(s.center.x);
    let ocy = r.oy - f32x8::splat(s.center.y);
    let ocz = r.oz - f32x8::splat(s.center.z);
    let a = r.dx * r.dx + r.dy * r.dy + r.dz * r.dz;
    let b = ocx * r.dx + ocy * r.dy + ocz * r.dz;
    let inv_a = f32x8::ONE / a;
    let k = b * inv_a;
    let fx = ocx - k * r.dx;
    let fy = ocy - k * r.dy;
    let fz = ocz - k * r.dz;
    let r2 = f32x8::splat(s.radius * s.radius);
    let disc = a * (r2 - (fx * fx + fy * fy + fz * fz));
    let ok = disc.simd_ge(f32x8::ZERO);
    let root = disc.sqrt();
    // copysign(√disc, b): the sign bit of b on the magnitude of √disc.
    let sign = f32x8::splat(-0.0);
    let signed_root = (root & !sign) | (b & sign);
    let q = -(b + signed_root);
    let c = (ocx * ocx + ocy * ocy + ocz * ocz) - r2;
    let t0 = c / q;
    let t1 = q * inv_a;
    let first = t0.simd_lt(t1);
    let near = first.select(t0, t1);
    let far = first.select(t1, t0);
    let t_min = f32x8::splat(T_MIN);
    let t = near.simd_gt(t_min).select(near, far);
    let hit = ok & t.simd_gt(t_min) & t.simd_lt(tmax);
    hit.select(t, f32x8::splat(f32::INFINITY))
}

/// Closest hit of every ray against every primitive, in the reference's order (triangles by
/// index, then spheres; a later primitive wins only when strictly closer). Writes `t`
/// (`f32::INFINITY` on a miss) and the global primitive id (`NO_HIT` on a miss).
pub fn closest_hits(
    triangles: &[Triangle],
    spheres: &[Sphere],
    rays: &RayColumns,
    two_sided: bool,
    t_out: &mut [f32],
    prim_out: &mut [u32],
) {
    let n = rays.len();
    debug_assert!(t_out.len() == n && prim_out.len() == n);
    let no_hit = f32x8::splat(f32::from_bits(NO_HIT));
    let base = triangles.len() as u32;
    for i in (0..n).step_by(LANES) {
        let r = Rays8::load(rays, i);
        let mut best_t = load(rays.tmax, i, 0.0);
        // Primitive ids ride in float lanes as raw bits: `select` only moves bits.
        let mut best_prim = no_hit;
        for (k, tri) in triangles.iter().enumerate() {
            let t = triangle8(tri, &r, best_t, two_sided);
            let closer = t.simd_lt(best_t);
            best_t = closer.select(t, best_t);
            best_prim = closer.select(f32x8::splat(f32::from_bits(k as u32)), best_prim);
        }
        for (k, s) in spheres.iter().enumerate() {
            let t = sphere8(s, &r, best_t);
            let closer = t.simd_lt(best_t);
            best_t = closer.select(t, best_t);
            best_prim = closer.select(f32x8::splat(f32::from_bits(base + k as u32)), best_prim);
        }
        let ts = best_t.to_array();
        let ps = best_prim.to_array();
        for lane in 0..(n - i).min(LANES) {
            let prim = ps[lane].to_bits();
            prim_out[i + lane] = prim;
            t_out[i + lane] = if prim == NO_HIT {
                f32::INFINITY
            } else {
                ts[lane]
            };
        }
    }
}

/// For every ray, whether anything blocks it in (T_MIN, tmax). Spheres first, then triangles;
/// a chunk of 8 stops as soon as all its live lanes are blocked.
pub fn occluded(
    triangles: &[Triangle],
    spheres: &[Sphere],
    rays: &RayColumns,
    two_sided: bool,
    out: &mut [bool],
) {
    let n = rays.len();
    debug_assert!(out.len() == n);
    for i in (0..n).step_by(LANES) {
        let r = Rays8::load(rays, i);
        let tmax = load(rays.tmax, i, 0.0);
        // A lane with tmax ≤ 0 (dead, or a light point within T_MIN) can never be blocked, so
        // it does not hold up the early exit.
        let live = live_lanes(i, n) & tmax.simd_gt(f32x8::ZERO).to_bitmask();
        let blocked = if live == 0 {
            0
        } else {
            occluded8(
                triangles,
                spheres,
                live,
                |s| sphere8_blocks(s, &r, tmax),
                |tri| triangle8_blocks(tri, &r, tmax, two_sided),
            )
        };
        let lanes = (n - i).min(LANES);
        out[i..i + lanes].copy_from_slice(&MASK_BOOLS[(blocked & 0xff) as usize][..lanes]);
    }
}

/// Spheres, then triangles, until every live lane is blocked; returns the blocked lanes.
#[inline(always)]
fn occluded8(
    triangles: &[Triangle],
    spheres: &[Sphere],
    live: u32,
    sphere_blocks: impl Fn(&Sphere) -> u32,
    triangle_blocks: impl Fn(&Triangle) -> u32,
) -> u32 {
    let mut blocked = 0;
    for s in spheres {
        blocked |= sphere_blocks(s);
        if blocked & live == live {
            return blocked;
        }
    }
    for tri in triangles {
        blocked |= triangle_blocks(tri);
        if blocked & live == live {
            return blocked;
        }
    }
    blocked
}

/// The lanes `s` blocks: `sphere8(..) < tmax`, but returning early when no lane can hit
/// (most shadow rays miss most spheres; that skips the square root and both divisions).
///
/// The early test is the textbook discriminant b² − a·c, which needs no division, with a margin
/// that makes it prove the stable discriminant negative too (`geometry::MISS_MARGIN`), so the
/// lanes it drops are misses for `sphere8` as well and the result is `sphere8`'s bit for bit.
/// (With the margin added as a separate term, this test cost 15% more instructions in the
/// occlusion loop than folded into c.)
#[inline(always)]
fn sphere8_blocks(s: &Sphere, r: &Rays8, tmax: f32x8) -> u32 {
    let ocx = r.ox - f32x8::splat(s.center.x);
    let ocy = r.oy - f32x8::splat(s.center.y);
    let ocz = r.oz - f32x8::splat(s.center.z);
    let a = r.dx * r.dx + r.dy * r.dy + r.dz * r.dz;
    let b = ocx * r.dx + ocy * r.dy + ocz * r.dz;
    let oc2 = ocx * ocx + ocy * ocy + ocz * ocz;
    // b² − a·c with the margin folded into c: c − k·(|oc|² + r²) = (1 − k)·|oc|² − (1 + k)·r².
    let r2 = s.radius * s.radius;
    let c = oc2 * f32x8::splat(1.0 - MISS_MARGIN) - f32x8::splat(r2 * (1.0 + MISS_MARGIN));
    // NaN compares false: such a lane is not proven a miss and goes to the exact test.
    if (b * b - a * c).simd_lt(f32x8::ZERO).all() {
        return 0;
    }
    sphere8(s, r, tmax).simd_lt(tmax).to_bitmask()
}

/// Chris Wellons' `lowbias32`, 8 lanes; twin of `sampling::mix32`.
#[inline(always)]
fn mix32x8(mut x: u32x8) -> u32x8 {
    x ^= x >> 16;
    x *= u32x8::splat(0x7feb_352d);
    x ^= x >> 15;
    x *= u32x8::splat(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Uniform numbers in [0, 1) for dimensions `dims` of the stream whose hash prefix is `prefix`
/// (see `shadow::key_prefix`): twin of `sampling::uniform`.
#[inline(always)]
fn uniform8(prefix: u32, dims: u32x8) -> f32x8 {
    let h = mix32x8(u32x8::splat(prefix) ^ dims) >> 8;
    // h < 2^24, so the signed conversion is exact.
    f32x8::from_i32x8(signed(h)) * f32x8::splat(1.0 / 16_777_216.0)
}

/// How a block's (u, v) are drawn: the samplers with an 8-wide twin.
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
}

/// Where 8 consecutive light samples `j0..j0 + 8` of one (pixel, sample, bounce, light) stream
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
fn divide(x: f32x8, n: f32) -> f32x8 {
    if n > 0.0 && n.is_normal() && n.to_bits() & 0x007f_ffff == 0 {
        x * f32x8::splat(1.0 / n)
    } else {
        x / f32x8::splat(n)
    }
}

/// Light points x, y, z of samples `j0..j0 + 8`: lane k equals
/// `light.point(square_sample(sampler, key, j0 + k, count))`.
#[inline]
pub fn light_points8(b: &LightBlock) -> [[f32; LANES]; 3] {
    let j = u32x8::splat(b.j0) + u32x8::new([0, 1, 2, 3, 4, 5, 6, 7]);
    let (u, v) = match b.sampler {
        BlockSampler::Random => (
            uniform8(b.prefix, j + j),
            uniform8(b.prefix, j + j + u32x8::ONE),
        ),
        BlockSampler::Stratified {
            cell_x,
            cell_y,
            nx,
            ny,
        } => {
            let xi0 = uniform8(b.prefix, j + j);
            let xi1 = uniform8(b.prefix, j + j + u32x8::ONE);
            let at = b.j0 as usize;
            let cx = load(cell_x, at, 0.0);
            let cy = load(cell_y, at, 0.0);
            let one_minus_eps = f32x8::splat(crate::sampling::ONE_MINUS_EPS);
            (
                divide(cx + xi0, nx).fast_min(one_minus_eps),
                divide(cy + xi1, ny).fast_min(one_minus_eps),
            )
        }
        BlockSampler::Sobol { scramble } => sobol8(j, scramble),
    };
    parallelogram_points8(b.origin, b.edge_u, b.edge_v, u, v)
}

/// The first 16 reversed-bit direction numbers of Sobol dimensions 0 and 1, as
/// `sobol_burley::parts::sobol_rev` uses them: vector k is what a reversed index with only bit
/// 31 − k set selects.
static SOBOL_VECTORS: std::sync::LazyLock<[[u32; 16]; 2]> = std::sync::LazyLock::new(|| {
    let vectors = |d| std::array::from_fn(|k| sobol_burley::parts::sobol_rev(1 << (31 - k), d));
    [vectors(0), vectors(1)]
});

/// `sobol_burley::parts::owen_scramble_rev`, 8 lanes.
#[inline(always)]
fn owen_scramble_rev8(mut n: u32x8, scramble: u32) -> u32x8 {
    n ^= n * u32x8::splat(0x3d20_adea);
    n += u32x8::splat(scramble);
    n *= u32x8::splat((scramble >> 16) | 1);
    n ^= n * u32x8::splat(0x0552_6c56);
    n ^= n * u32x8::splat(0x53a2_2864);
    n
}

/// `u32::reverse_bits`, 8 lanes.
#[inline(always)]
fn reverse_bits8(mut x: u32x8) -> u32x8 {
    for (shift, mask) in [
        (1, 0x5555_5555u32),
        (2, 0x3333_3333),
        (4, 0x0f0f_0f0f),
        (8, 0x00ff_00ff),
    ] {
        let m = u32x8::splat(mask);
        x = ((x >> shift) & m) | ((x & m) << shift);
    }
    (x >> 16) | (x << 16)
}

/// `sobol_burley::parts::u32_to_f32_norm`, 8 lanes.
#[inline(always)]
fn u32_to_f32_norm8(n: u32x8) -> f32x8 {
    let bits = (n >> 9) | u32x8::splat(0x3f80_0000);
    f32_from_bits(bits) - f32x8::ONE
}

/// Dimensions 0 and 1 of Owen-scrambled Sobol points `j`: lane k equals
/// `sobol_burley::sample(j[k], 0 | 1, scramble)`, the crate's own steps on 8 lanes (the
/// index shuffle, the direction-number XOR over the top 16 bits, the per-dimension scramble).
#[inline(always)]
fn sobol8(j: u32x8, scramble: u32) -> (f32x8, f32x8) {
    use sobol_burley::parts::hash;
    let index = owen_scramble_rev8(reverse_bits8(j), hash(scramble ^ 0x79c6_8e4a));
    let vectors = &*SOBOL_VECTORS;
    let (mut s0, mut s1) = (u32x8::ZERO, u32x8::ZERO);
    for (k, (&v0, &v1)) in vectors[0].iter().zip(&vectors[1]).enumerate() {
        // All ones where bit 31 − k of the index is set.
        let bit = unsigned(signed(index << k as u32) >> 31);
        s0 ^= bit & u32x8::splat(v0);
        s1 ^= bit & u32x8::splat(v1);
    }
    let seed = scramble.wrapping_mul(0x9c8f_2d3b);
    let s0 = owen_scramble_rev8(s0, hash(seed ^ 0x912f_69ba));
    let s1 = owen_scramble_rev8(s1, hash(seed ^ 0x174f_18ab));
    (
        u32_to_f32_norm8(reverse_bits8(s0)),
        u32_to_f32_norm8(reverse_bits8(s1)),
    )
}

/// origin + u·edge_u + v·edge_v on 8 lanes: lane k equals `light.point(u[k], v[k])`.
#[inline(always)]
fn parallelogram_points8(
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    u: f32x8,
    v: f32x8,
) -> [[f32; LANES]; 3] {
    // origin + u·edge_u + v·edge_v, evaluated left to right like glam.
    let axis = |o: f32, eu: f32, ev: f32| {
        (f32x8::splat(o) + u * f32x8::splat(eu) + v * f32x8::splat(ev)).to_array()
    };
    [
        axis(origin.x, edge_u.x, edge_v.x),
        axis(origin.y, edge_u.y, edge_v.y),
        axis(origin.z, edge_u.z, edge_v.z),
    ]
}

/// Shadow rays from `hit` to 8 light points, the first `lanes` of them real: lane k equals
/// `spawn::shadow_ray(hit, target_k, end)` (l, tmax and the distance; the origin is the
/// block's). Lanes for which the twin returns `None`, or past `lanes`, come back dead: tmax = 0.
#[inline]
pub fn shadow_rays8(
    hit: &SurfaceHit,
    target: &[[f32; LANES]; 3],
    end: &LightEnd,
    lanes: usize,
) -> ShadowBlock {
    let n = hit.normal;
    let x = f32x8::new(target[0]) - f32x8::splat(hit.point.x);
    let y = f32x8::new(target[1]) - f32x8::splat(hit.point.y);
    let z = f32x8::new(target[2]) - f32x8::splat(hit.point.z);
    let above = f32x8::splat(n.x) * x + f32x8::splat(n.y) * y + f32x8::splat(n.z) * z;
    let dist = (x * x + y * y + z * z).sqrt();
    let (lx, ly, lz) = (x / dist, y / dist, z / dist);
    let n_dot_l = f32x8::splat(n.x) * lx + f32x8::splat(n.y) * ly + f32x8::splat(n.z) * lz;
    let tmax = dist * f32x8::splat(end.ratio);
    let first = f32x8::new(LANE_INDEX).simd_lt(f32x8::splat(lanes as f32));
    let live = above.simd_gt(f32x8::splat(end.margin)) & tmax.simd_gt(f32x8::ZERO) & first;
    ShadowBlock {
        origin: hit.leaving_point(),
        l: [lx.to_array(), ly.to_array(), lz.to_array()],
        tmax: live.select(tmax, f32x8::ZERO).to_array(),
        n_dot_l: live.select(n_dot_l, f32x8::ZERO).to_array(),
        dist: dist.to_array(),
        live: live.to_bitmask(),
    }
}

/// Shade · weight of 8 shadow rays cast from one hit towards one light: lane k equals
/// `shadow::shade_terms(m, n, e, l_k, n·l_k, light_color) * weight` bit for bit (`powf`
/// runs per lane, in scalar, only where the scalar twin calls it). Lanes that add nothing (dead,
/// n·l ≤ 0, or `blocked`) come back as −0.0, the exact identity of IEEE addition (x + −0 = x for
/// every x, −0 included), so the caller adds all 8 lanes in order without a branch.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn shade8(
    m: &MaterialTerms,
    n: Vec3,
    e: Vec3,
    l: [&[f32]; 3],
    n_dot_l: &[f32],
    blocked: &[bool],
    light_color: Vec3,
    falloff: Option<&[f32; LANES]>,
    weight: f32,
) -> [[f32; LANES]; 3] {
    let ndl = load(n_dot_l, 0, 0.0);
    // Each lane's light colour: Lc · falloff (`spawn::falloff`), or Lc itself in the lab's
    // model, whose fall-off is exactly 1 (x · 1 = x, so both give the twin's bits).
    let lc = {
        let splat = |c: f32| f32x8::splat(c);
        let (r, g, b) = (
            splat(light_color.x),
            splat(light_color.y),
            splat(light_color.z),
        );
        match falloff {
            None => [r, g, b],
            Some(f) => {
                let f = f32x8::new(*f);
                [r * f, g * f, b * f]
            }
        }
    };
    let open = f32x8::new(std::array::from_fn(|k| if blocked[k] { 0.0 } else { 1.0 }));
    let adds = ndl.simd_gt(f32x8::ZERO) & open.simd_gt(f32x8::ZERO);
    let nothing = f32x8::splat(-0.0);
    let cr = f32x8::splat(m.ambient_emitted.x) + lc[0] * f32x8::splat(m.diffuse.x) * ndl;
    let cg = f32x8::splat(m.ambient_emitted.y) + lc[1] * f32x8::splat(m.diffuse.y) * ndl;
    let cb = f32x8::splat(m.ambient_emitted.z) + lc[2] * f32x8::splat(m.diffuse.z) * ndl;
    let positive = m.shininess > 0.0;
    let w = f32x8::splat(weight);
    if positive && !m.is_reflective {
        let out = |c: f32x8| adds.select(c * w, nothing).to_array();
        return [out(cr), out(cg), out(cb)];
    }
    let (lx, ly, lz) = (load(l[0], 0, 0.0), load(l[1], 0, 0.0), load(l[2], 0, 0.0));
    // r = normalize(2(n·l) n − l), glam's normalize: v · (1 / |v|).
    let k = f32x8::splat(2.0) * ndl;
    let rx = k * f32x8::splat(n.x) - lx;
    let ry = k * f32x8::splat(n.y) - ly;
    let rz = k * f32x8::splat(n.z) - lz;
    let recip = f32x8::ONE / (rx * rx + ry * ry + rz * rz).sqrt();
    let (rx, ry, rz) = (rx * recip, ry * recip, rz * recip);
    let e_dot_r =
        (f32x8::splat(e.x) * rx + f32x8::splat(e.y) * ry + f32x8::splat(e.z) * rz).to_array();
    let mut spec = [0.0f32; LANES];
    let mut with_highlight = [0.0f32; LANES];
    for k in 0..LANES {
        let base = e_dot_r[k].max(0.0);
        if !positive || base > 0.0 {
            spec[k] = base.powf(m.shininess);
            with_highlight[k] = 1.0;
        }
    }
    let on = f32x8::new(with_highlight).simd_gt(f32x8::ZERO);
    let s = f32x8::new(spec) * ndl;
    let sc = m.specular;
    let add = |c: f32x8, lc: f32x8, sc: f32| {
        adds.select(on.select(c + lc * f32x8::splat(sc) * s, c) * w, nothing)
    };
    [
        add(cr, lc[0], sc.x).to_array(),
        add(cg, lc[1], sc.y).to_array(),
        add(cb, lc[2], sc.z).to_array(),
    ]
}

/// Lane-level entry points for tests: 8 rays given as arrays, the kernels' answers as arrays.
pub mod lanes {
    use super::*;

    fn rays8(rays: &[Ray; LANES]) -> Rays8 {
        let col = |f: fn(&Ray) -> f32| f32x8::new(std::array::from_fn(|k| f(&rays[k])));
        Rays8 {
            ox: col(|r| r.origin.x),
            oy: col(|r| r.origin.y),
            oz: col(|r| r.origin.z),
            dx: col(|r| r.direction.x),
            dy: col(|r| r.direction.y),
            dz: col(|r| r.direction.z),
        }
    }

    /// [`triangle8`] on arrays.
    pub fn triangle(
        tri: &Triangle,
        rays: &[Ray; LANES],
        tmax: [f32; LANES],
        two_sided: bool,
    ) -> [f32; LANES] {
        triangle8(tri, &rays8(rays), f32x8::new(tmax), two_sided).to_array()
    }

    /// [`sphere8`] on arrays.
    pub fn sphere(s: &Sphere, rays: &[Ray; LANES], tmax: [f32; LANES]) -> [f32; LANES] {
        sphere8(s, &rays8(rays), f32x8::new(tmax)).to_array()
    }
}
