//! Ray–primitive kernels: Möller–Trumbore and the stable sphere test on N lanes (8 or 16, one
//! source generic over [`Lanes`]), and the brute-force closest-hit and occlusion loops of
//! scenes without a BVH.

use super::{RayColumns, Rays};
use crate::render::geometry::{EDGE_EPSILON, MISS_MARGIN, T_MIN};
use crate::render::scene::{NO_HIT, Sphere, Triangle};
use crate::render::wavefront::batch::{HitRays, ShadowBlock};
use crate::render::wavefront::cost::{Costs, Counter};
use crate::render::wavefront::lanes::{Lanes, f32x8, live_lanes, store_mask};
use glam::Vec3;

/// Möller–Trumbore's operands on N lanes (8 by default), as columns: ray origin o and
/// direction d, triangle corner v0 and edges e1, e2. [`triangle8`] splats the triangle, the
/// mesh BVH's leaf test splats the ray; the arithmetic is the same either way.
#[derive(Clone, Copy)]
pub(crate) struct TriangleLanes<V = f32x8> {
    pub o: [V; 3],
    pub d: [V; 3],
    pub v0: [V; 3],
    pub e1: [V; 3],
    pub e2: [V; 3],
}

impl<V: Lanes> TriangleLanes<V> {
    /// One triangle against N rays.
    #[inline(always)]
    fn splat_triangle(tri: &Triangle, r: &Rays<V>) -> TriangleLanes<V> {
        let splat = |v: Vec3| [V::splat(v.x), V::splat(v.y), V::splat(v.z)];
        TriangleLanes {
            o: [r.ox, r.oy, r.oz],
            d: [r.dx, r.dy, r.dz],
            v0: splat(tri.v0),
            e1: splat(tri.e1),
            e2: splat(tri.e2),
        }
    }
}

/// Möller–Trumbore on N lanes; lane k equals `intersect_triangle(tri_k, ray_k, tmax_k,
/// two_sided)`, the same operations in the same order.
///
/// ```text
/// p = d × e2; det = e1·p; facing = det > 0 (det ≠ 0 if two-sided)
/// s = o − v0; u = s·p / det; q = s × e1; v = d·q / det; t = e2·q / det
/// hit = facing ∧ u ≥ −ε ∧ v ≥ −ε ∧ u + v ≤ 1 + ε ∧ T_MIN < t < tmax   → t, else ∞
/// ```
#[inline(always)]
pub(crate) fn moller_trumbore8<V: Lanes>(m: &TriangleLanes<V>, tmax: V, two_sided: bool) -> V {
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
        det.simd_ne(V::ZERO)
    } else {
        det.simd_gt(V::ZERO)
    };
    let inv_det = V::ONE / det;
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
        & u.simd_ge(V::splat(-EDGE_EPSILON))
        & v.simd_ge(V::splat(-EDGE_EPSILON))
        & (u + v).simd_le(V::splat(1.0 + EDGE_EPSILON))
        & t.simd_gt(V::splat(T_MIN))
        & t.simd_lt(tmax);
    hit.select(t, V::splat(f32::INFINITY))
}

/// The lanes that block, as a bitmask: `moller_trumbore8(..) < tmax`, with the same values
/// computed in an order that lets all N lanes leave early: after det when no lane faces its
/// triangle (for one-sided faces about half the walls of a box, seen from a coherent packet of
/// shadow rays), and after t when no lane's t is in (T_MIN, tmax) (the walls behind the light).
#[inline(always)]
pub(crate) fn moller_trumbore8_blocks<V: Lanes>(
    m: &TriangleLanes<V>,
    tmax: V,
    two_sided: bool,
) -> u32 {
    let [ox, oy, oz] = m.o;
    let [dx, dy, dz] = m.d;
    let [e1x, e1y, e1z] = m.e1;
    let [e2x, e2y, e2z] = m.e2;
    let px = dy * e2z - e2y * dz;
    let py = dz * e2x - e2z * dx;
    let pz = dx * e2y - e2x * dy;
    let det = e1x * px + e1y * py + e1z * pz;
    let facing = if two_sided {
        det.simd_ne(V::ZERO)
    } else {
        det.simd_gt(V::ZERO)
    };
    if facing.none() {
        return 0;
    }
    let inv_det = V::ONE / det;
    let tx = ox - m.v0[0];
    let ty = oy - m.v0[1];
    let tz = oz - m.v0[2];
    let qx = ty * e1z - e1y * tz;
    let qy = tz * e1x - e1z * tx;
    let qz = tx * e1y - e1x * ty;
    let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
    let in_range = facing & t.simd_gt(V::splat(T_MIN)) & t.simd_lt(tmax);
    if in_range.none() {
        return 0;
    }
    let u = (tx * px + ty * py + tz * pz) * inv_det;
    let v = (dx * qx + dy * qy + dz * qz) * inv_det;
    (in_range
        & u.simd_ge(V::splat(-EDGE_EPSILON))
        & v.simd_ge(V::splat(-EDGE_EPSILON))
        & (u + v).simd_le(V::splat(1.0 + EDGE_EPSILON)))
    .to_bitmask()
}

/// Möller–Trumbore for N rays against one triangle; lane k equals
/// `intersect_triangle(tri, ray_k, tmax_k, two_sided)`.
#[inline(always)]
pub fn triangle8<V: Lanes>(tri: &Triangle, r: &Rays<V>, tmax: V, two_sided: bool) -> V {
    moller_trumbore8(&TriangleLanes::splat_triangle(tri, r), tmax, two_sided)
}

/// The lanes that `tri` blocks, as a bitmask (`moller_trumbore8_blocks`).
#[inline(always)]
fn triangle8_blocks<V: Lanes>(tri: &Triangle, r: &Rays<V>, tmax: V, two_sided: bool) -> u32 {
    moller_trumbore8_blocks(&TriangleLanes::splat_triangle(tri, r), tmax, two_sided)
}

/// Ray–sphere for N rays; lane k equals `intersect_sphere(sphere, ray_k, tmax_k)`: the stable
/// form, see there.
///
/// ```text
/// oc = o − c; a = d·d; b = oc·d; f = oc − b·(1/a)·d; disc = a·(r² − f·f)
/// q = −(b + sign(b)·√disc); t0 = (oc·oc − r²)/q; t1 = q·(1/a); near, far = sorted(t0, t1)
/// t = near > T_MIN ? near : far;  hit = disc ≥ 0 ∧ T_MIN < t < tmax   → t, else ∞
/// ```
#[inline(always)]
pub fn sphere8<V: Lanes>(s: &Sphere, r: &Rays<V>, tmax: V) -> V {
    let Roots {
        ok, inv_a, c, q, ..
    } = SphereLanes::new(s, r).roots(r);
    let t0 = c / q;
    let t1 = q * inv_a;
    let first = t0.simd_lt(t1);
    let near = first.select(t0, t1);
    let far = first.select(t1, t0);
    let t_min = V::splat(T_MIN);
    let t = near.simd_gt(t_min).select(near, far);
    let hit = ok & t.simd_gt(t_min) & t.simd_lt(tmax);
    hit.select(t, V::splat(f32::INFINITY))
}

/// One sphere against N rays, up to the discriminant: what [`sphere8`] and `sphere8_blocks`
/// share (lane-wise twin of `geometry::sphere_roots`).
struct SphereLanes<V> {
    oc: [V; 3],
    a: V,
    b: V,
    oc2: V,
    r2: f32,
}

/// The roots' parts, t0 = c/q and t1 = q·(1/a), and which lanes have them (`ok`).
struct Roots<V> {
    ok: V,
    a: V,
    inv_a: V,
    c: V,
    q: V,
}

impl<V: Lanes> SphereLanes<V> {
    #[inline(always)]
    fn new(s: &Sphere, r: &Rays<V>) -> SphereLanes<V> {
        let ocx = r.ox - V::splat(s.center.x);
        let ocy = r.oy - V::splat(s.center.y);
        let ocz = r.oz - V::splat(s.center.z);
        SphereLanes {
            a: r.dx * r.dx + r.dy * r.dy + r.dz * r.dz,
            b: ocx * r.dx + ocy * r.dy + ocz * r.dz,
            oc2: ocx * ocx + ocy * ocy + ocz * ocz,
            oc: [ocx, ocy, ocz],
            r2: s.radius * s.radius,
        }
    }

    /// True when the textbook discriminant b² − a·c proves every lane a miss, with the margin
    /// that makes the stable discriminant negative too (`geometry::MISS_MARGIN`), folded into
    /// c: c − k·(|oc|² + r²) = (1 − k)·|oc|² − (1 + k)·r². NaN compares false: such a lane is
    /// not proven a miss and goes to the exact test.
    #[inline(always)]
    fn all_miss(&self) -> bool {
        let (a, b) = (self.a, self.b);
        let c = self.oc2 * V::splat(1.0 - MISS_MARGIN) - V::splat(self.r2 * (1.0 + MISS_MARGIN));
        (b * b - a * c).simd_lt(V::ZERO).all()
    }

    /// The stable discriminant a·(r² − |oc − (b/a)·d|²) and q = −(b + sign(b)·√disc).
    #[inline(always)]
    fn roots(&self, r: &Rays<V>) -> Roots<V> {
        let (a, b, [ocx, ocy, ocz]) = (self.a, self.b, self.oc);
        let inv_a = V::ONE / a;
        let k = b * inv_a;
        let fx = ocx - k * r.dx;
        let fy = ocy - k * r.dy;
        let fz = ocz - k * r.dz;
        let r2 = V::splat(self.r2);
        let disc = a * (r2 - (fx * fx + fy * fy + fz * fz));
        // copysign(√disc, b): the sign bit of b on the magnitude of √disc.
        let sign = V::splat(-0.0);
        let signed_root = (disc.sqrt() & !sign) | (b & sign);
        Roots {
            ok: disc.simd_ge(V::ZERO),
            a,
            inv_a,
            c: self.oc2 - r2,
            q: -(b + signed_root),
        }
    }
}

/// Closest hit of every ray against every primitive, N rays at a time (`V`: 8 or 16 lanes,
/// the same answers), in the reference's order (triangles by index, then spheres; a later
/// primitive wins only when strictly closer). Writes `t` (`f32::INFINITY` on a miss) and the
/// global primitive id (`NO_HIT` on a miss).
///
/// Never inlined, and its callers choose the width with `lanes::at_width!`: with the 16-lane
/// loop inlined into `intersect::closest`, that stage's own per-hit loop took 1.1–1.75% more
/// instructions at 8 lanes (tests/gates/icount.rs).
#[inline(never)]
pub fn closest_hits<V: Lanes>(
    triangles: &[Triangle],
    spheres: &[Sphere],
    rays: &RayColumns,
    two_sided: bool,
    t_out: &mut [f32],
    prim_out: &mut [u32],
) {
    let n = rays.len();
    debug_assert!(t_out.len() == n && prim_out.len() == n);
    let no_hit = V::splat(f32::from_bits(NO_HIT));
    let base = triangles.len() as u32;
    for i in (0..n).step_by(V::N) {
        let r = Rays::<V>::load(rays, i);
        let mut best_t = V::load(rays.tmax, i, 0.0);
        // Primitive ids ride in float lanes as raw bits: `select` only moves bits.
        let mut best_prim = no_hit;
        for (k, tri) in triangles.iter().enumerate() {
            let t = triangle8(tri, &r, best_t, two_sided);
            let closer = t.simd_lt(best_t);
            best_t = closer.select(t, best_t);
            best_prim = closer.select(V::splat(f32::from_bits(k as u32)), best_prim);
        }
        for (k, s) in spheres.iter().enumerate() {
            let t = sphere8(s, &r, best_t);
            let closer = t.simd_lt(best_t);
            best_t = closer.select(t, best_t);
            best_prim = closer.select(V::splat(f32::from_bits(base + k as u32)), best_prim);
        }
        let ts = best_t.to_array();
        let ps = best_prim.to_array();
        for lane in 0..(n - i).min(V::N) {
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

/// For every ray, whether anything blocks it in (T_MIN, tmax), N rays at a time. Spheres
/// first, then triangles; a block of N lanes stops as soon as all its live lanes are blocked,
/// and each of its live rays is charged the primitives the block tested, in `costs`. Never
/// inlined, so that the queued shadow stage calls it as a function of its own at either width.
#[inline(never)]
pub fn occluded<V: Lanes, S: Costs>(
    triangles: &[Triangle],
    spheres: &[Sphere],
    rays: &RayColumns,
    two_sided: bool,
    out: &mut [bool],
    costs: &mut S,
) {
    let n = rays.len();
    debug_assert!(out.len() == n);
    for i in (0..n).step_by(V::N) {
        let r = Rays::<V>::load(rays, i);
        let tmax = V::load(rays.tmax, i, 0.0);
        // A lane with tmax ≤ 0 (dead, or a light point within T_MIN) can never be blocked, so
        // it does not hold up the early exit.
        let live = live_lanes::<V>(i, n) & tmax.simd_gt(V::ZERO).to_bitmask();
        let blocked = if live == 0 {
            0
        } else {
            let mut c = S::Counter::default();
            let blocked = occluded8(
                triangles,
                spheres,
                live,
                |s| sphere8_blocks(s, &r, tmax),
                |tri| triangle8_blocks(tri, &r, tmax, two_sided),
                &mut c,
            );
            costs.add_lanes(i, live, c);
            blocked
        };
        let lanes = (n - i).min(V::N);
        store_mask::<V>(&mut out[i..i + lanes], blocked);
    }
}

/// The lanes of one block of shadow rays (`simd::shadow_rays`: N rays from one origin, dead
/// lanes with tmax = 0) that something blocks, as a bit mask: for every live lane, the answer
/// [`occluded`] gives for the same ray in a queue; dead lanes' bits mean nothing. The
/// primitives tested are counted in `c` once for the block (each live ray did those tests).
#[inline(always)]
pub fn block_occluded<V: Lanes, C: Counter>(
    triangles: &[Triangle],
    spheres: &[Sphere],
    block: &ShadowBlock<V::Array>,
    two_sided: bool,
    c: &mut C,
) -> u32 {
    let o = block.origin;
    let r = Rays {
        ox: V::splat(o.x),
        oy: V::splat(o.y),
        oz: V::splat(o.z),
        dx: V::from_array(block.l[0]),
        dy: V::from_array(block.l[1]),
        dz: V::from_array(block.l[2]),
    };
    let tmax = V::from_array(block.tmax);
    let live = tmax.simd_gt(V::ZERO).to_bitmask();
    rays_occluded(triangles, spheres, &r, tmax, live, two_sided, c)
}

/// [`block_occluded`] for one ray per hit (`simd::hit_shadow_rays`), `live` the lanes with a
/// ray.
#[inline(always)]
pub fn hit_rays_occluded<V: Lanes, C: Counter>(
    triangles: &[Triangle],
    spheres: &[Sphere],
    rays: &HitRays<V::Array>,
    live: u32,
    two_sided: bool,
    c: &mut C,
) -> u32 {
    let r = Rays {
        ox: V::from_array(rays.origin[0]),
        oy: V::from_array(rays.origin[1]),
        oz: V::from_array(rays.origin[2]),
        dx: V::from_array(rays.l[0]),
        dy: V::from_array(rays.l[1]),
        dz: V::from_array(rays.l[2]),
    };
    rays_occluded(
        triangles,
        spheres,
        &r,
        V::from_array(rays.tmax),
        live,
        two_sided,
        c,
    )
}

/// [`occluded8`] on rays in registers, `live` the lanes that count.
#[inline(always)]
fn rays_occluded<V: Lanes, C: Counter>(
    triangles: &[Triangle],
    spheres: &[Sphere],
    r: &Rays<V>,
    tmax: V,
    live: u32,
    two_sided: bool,
    c: &mut C,
) -> u32 {
    if live == 0 {
        return 0;
    }
    occluded8(
        triangles,
        spheres,
        live,
        |s| sphere8_blocks(s, r, tmax),
        |tri| triangle8_blocks(tri, r, tmax, two_sided),
        c,
    )
}

/// Spheres, then triangles, until every live lane is blocked; returns the blocked lanes. `c`
/// counts the primitives tested.
#[inline(always)]
fn occluded8<C: Counter>(
    triangles: &[Triangle],
    spheres: &[Sphere],
    live: u32,
    sphere_blocks: impl Fn(&Sphere) -> u32,
    triangle_blocks: impl Fn(&Triangle) -> u32,
    c: &mut C,
) -> u32 {
    let mut blocked = 0;
    for s in spheres {
        c.tests(1);
        blocked |= sphere_blocks(s);
        if blocked & live == live {
            return blocked;
        }
    }
    for tri in triangles {
        c.tests(1);
        blocked |= triangle_blocks(tri);
        if blocked & live == live {
            return blocked;
        }
    }
    blocked
}

/// The lanes `s` blocks: lane k is `geometry::sphere_blocks(s, ray_k, tmax_k)` (the roots
/// tested against (0, tmax) by multiplication, no division of c by q). Most shadow rays miss
/// most spheres, so it returns before the square root and the division when
/// [`SphereLanes::all_miss`] proves every lane a miss (with the margin as a separate term
/// rather than folded into c, that test cost 15% more instructions in the occlusion loop).
#[inline(always)]
fn sphere8_blocks<V: Lanes>(s: &Sphere, r: &Rays<V>, tmax: V) -> u32 {
    let lanes = SphereLanes::new(s, r);
    if lanes.all_miss() {
        return 0;
    }
    let Roots { ok, a, c, q, .. } = lanes.roots(r);
    let t1_in_range = q.simd_gt(V::ZERO) & q.simd_lt(tmax * a);
    let t0_in_range = (c * q).simd_gt(V::ZERO) & c.abs().simd_lt(tmax * q.abs());
    (ok & (t1_in_range | t0_in_range)).to_bitmask()
}
