//! Scalar ray–primitive intersection: the reference kernels. The SIMD kernels of the wavefront
//! engine are tested against these functions, lane by lane.
//!
//! Conventions (the lab's): faces are one-sided, hit only from the front (n·d < 0, n from the
//! counter-clockwise winding) unless `two_sided`; spheres are hit from both sides and report the
//! outward normal; a hit needs t > `T_MIN` = 0. A miss returns `f32::INFINITY`, never `None`, and
//! any NaN in the input makes a miss (every test is written so that NaN compares false).
//!
//! There is no self-intersection epsilon on t: an absolute one is wrong at some scale (the lab's
//! 1e-4 is 5% of a box scaled by 1e-3, and less than the error of a hit point in a box scaled by
//! 10). Instead hit points are put back on their surface and secondary rays start a bound on that
//! error away from it (`crate::render::spawn`), and the sphere test is the numerically stable one.

use crate::render::scene::{Light, NO_HIT, Scene, Sphere, Triangle};
use glam::{Vec3, Vec3A};
use obvhs::{BvhBuildParams, cwbvh::CwBvh, ray::RayHit};
use std::time::Duration;

/// Where a ray's interval starts: a hit needs t > 0 (no epsilon: see the module doc).
pub const T_MIN: f32 = 0.0;

/// Slack on the barycentric edge tests (u ≥ −ε, v ≥ −ε, u + v ≤ 1 + ε), so that a ray crossing
/// the edge two triangles share (a quad's a–c diagonal) hits at least one of them: without it,
/// rounding put both u of one triangle and v of the other just below 0 and rays leaked through
/// (2 of 9216 camera rays into the lab's box). Both engines use the same constant.
pub const EDGE_EPSILON: f32 = 1e-6;

/// The relative margin by which the textbook discriminant b² − a·c proves a ray misses a
/// sphere: both it and the stable discriminant are within 50 ulps of a·(|oc|² + r²) of the
/// exact value (b² ≤ a·|oc|²), so b² − a·c < −2^-16·a·(|oc|² + r²) (256 ulps) makes the stable
/// one negative too, and skipping the rest changes no result. Written with the margin folded
/// into c, b² − a·((1 − k)·|oc|² − (1 + k)·r²), it costs one multiply.
pub const MISS_MARGIN: f32 = 1.0 / 65_536.0;

/// Below this many triangles the reference tests every primitive; above it, it uses a BVH.
pub const BVH_MIN_TRIANGLES: usize = 64;

/// A ray with a half-open interval (T_MIN, tmax).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction (unit length for camera, reflection and shadow rays).
    pub direction: Vec3,
}

/// The closest hit along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray; `f32::INFINITY` for a miss.
    pub t: f32,
    /// Global primitive id (triangles, then spheres); `NO_HIT` for a miss.
    pub prim: u32,
}

impl Hit {
    /// No hit.
    pub const MISS: Hit = Hit {
        t: f32::INFINITY,
        prim: NO_HIT,
    };
    /// True when something was hit.
    pub fn is_hit(&self) -> bool {
        self.prim != NO_HIT
    }
}

/// Möller–Trumbore. Returns t in (T_MIN, tmax) or infinity.
///
/// det = e1·(d × e2) = −d·n, so det > 0 means the ray meets the front.
#[inline]
pub fn intersect_triangle(tri: &Triangle, ray: &Ray, tmax: f32, two_sided: bool) -> f32 {
    let pvec = ray.direction.cross(tri.e2);
    let det = tri.e1.dot(pvec);
    let facing = if two_sided { det != 0.0 } else { det > 0.0 };
    if !facing {
        return f32::INFINITY;
    }
    let inv_det = 1.0 / det;
    let tvec = ray.origin - tri.v0;
    let u = tvec.dot(pvec) * inv_det;
    let qvec = tvec.cross(tri.e1);
    let v = ray.direction.dot(qvec) * inv_det;
    let t = tri.e2.dot(qvec) * inv_det;
    if u >= -EDGE_EPSILON
        && v >= -EDGE_EPSILON
        && u + v <= 1.0 + EDGE_EPSILON
        && t > T_MIN
        && t < tmax
    {
        t
    } else {
        f32::INFINITY
    }
}

/// Nearest root of |o + t·d − c|² = r² with t in (T_MIN, tmax), or infinity.
///
/// The numerically stable form (Haines et al., *Ray Tracing Gems* ch. 7): the discriminant is
/// taken from the ray's perpendicular distance to the centre, f = oc − (b/a)·d, as
/// a·(r² − f·f), which keeps its precision when the eye is far from a small sphere (b² − a·c
/// loses it all: the lab's camera ray landed 4e-5 inside a sphere of radius 0.3), and the roots
/// are c/q and q/a with q = −(b + sign(b)·√disc), which never subtracts nearly equal numbers.
/// Two divisions, as the textbook form has.
#[inline]
pub fn intersect_sphere(sphere: &Sphere, ray: &Ray, tmax: f32) -> f32 {
    let Some(SphereRoots { inv_a, c, q, .. }) = sphere_roots(sphere, ray) else {
        return f32::INFINITY;
    };
    let (t0, t1) = (c / q, q * inv_a);
    let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
    let t = if near > T_MIN { near } else { far };
    if t > T_MIN && t < tmax {
        t
    } else {
        f32::INFINITY
    }
}

/// Whether `sphere` blocks `ray` in (0, tmax): `intersect_sphere(..) < tmax` without the
/// division of the root c/q and without sorting the roots, for the occlusion tests.
///
/// Same miss proof (`MISS_MARGIN`), same stable discriminant and same q = −(b + sign(b)·√disc)
/// as `intersect_sphere`; then a root n/m lies in (0, tmax) when n and m have the same sign and
/// |n| < tmax·|m|, so t1 = q/a (a > 0) is tested as 0 < q < tmax·a and t0 = c/q as c·q > 0,
/// |c| < tmax·|q|. A root in the interval blocks whichever of the two it is: the far root counts
/// only when the near one is ≤ 0, and when the near one is ≥ tmax so is the far one. The
/// products round differently from the quotients only for a root within an ulp of 0 or tmax,
/// where the start and end offsets of shadow rays (`spawn`) keep every surface away.
/// (`raywave bench --against`, the lab benchmark, 20 rounds: 0.987× the time of the form with
/// the division, 95% interval [0.981, 0.992].)
#[inline]
pub fn sphere_blocks(sphere: &Sphere, ray: &Ray, tmax: f32) -> bool {
    let Some(SphereRoots { a, c, q, .. }) = sphere_roots(sphere, ray) else {
        return false;
    };
    // T_MIN is 0: "> 0" below is "> T_MIN".
    let t1_in_range = q > 0.0 && q < tmax * a;
    let t0_in_range = c * q > 0.0 && c.abs() < tmax * q.abs();
    t1_in_range || t0_in_range
}

/// What both sphere tests need before they judge the roots t0 = c/q and t1 = q/a.
struct SphereRoots {
    a: f32,
    inv_a: f32,
    c: f32,
    q: f32,
}

/// The shared first half of [`intersect_sphere`] and [`sphere_blocks`]: `None` when the ray's
/// line misses the sphere. Most rays miss most spheres: the textbook discriminant, which needs
/// no division, proves it with a margin (`MISS_MARGIN`), and the stable one is computed only
/// for the rest.
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x >= 0)` is on purpose: NaN must miss
fn sphere_roots(sphere: &Sphere, ray: &Ray) -> Option<SphereRoots> {
    let oc = ray.origin - sphere.center;
    let a = ray.direction.length_squared();
    let b = oc.dot(ray.direction);
    let r2 = sphere.radius * sphere.radius;
    let oc2 = oc.length_squared();
    // The margin folded into c: c − k·(|oc|² + r²) = (1 − k)·|oc|² − (1 + k)·r².
    if b * b - a * ((1.0 - MISS_MARGIN) * oc2 - (1.0 + MISS_MARGIN) * r2) < 0.0 {
        return None;
    }
    // One division for 1/a, used twice by `intersect_sphere` (a multiply is cheaper than a
    // division, and the extra rounding is an ulp).
    let inv_a = 1.0 / a;
    let f = oc - (b * inv_a) * ray.direction;
    let disc = a * (r2 - f.length_squared());
    if !(disc >= 0.0) {
        return None;
    }
    Some(SphereRoots {
        a,
        inv_a,
        c: oc2 - r2,
        q: -(b + disc.sqrt().copysign(b)),
    })
}

/// The order every closest-hit query over a BVH minimises: (t, prim) beats the best so far when
/// closer, or as close with a lower id, so that ties (a shared edge, a corner where two walls
/// meet) go to the lowest id whatever order a tree visits them in, as in a loop over the
/// primitives. A miss (t = ∞) never wins, not even against an infinite best. Used by
/// `Accel::closest` and both walks of the wavefront engine's mesh BVH.
#[inline(always)]
pub fn closer(t: f32, prim: u32, best_t: f32, best_prim: u32) -> bool {
    t < best_t || (t == best_t && t < f32::INFINITY && prim < best_prim)
}

/// How the reference finds hits: every primitive in turn, or a BVH over the triangles.
pub struct Accel {
    bvh: Option<CwBvh>,
    /// The power of two the tree's coordinates are scaled by (`bvh_scale`).
    scale: f32,
    /// Without a BVH, the triangles that shadow rays test when faces are one-sided (see
    /// `shadow_casters`).
    casters: Vec<Triangle>,
    /// BVH build time, for reporting (zero without a BVH).
    pub build_time: Duration,
}

impl Accel {
    /// Builds a CWBVH over the triangles when there are at least `BVH_MIN_TRIANGLES` of them.
    pub fn new(scene: &Scene) -> Accel {
        if scene.triangles.len() < BVH_MIN_TRIANGLES {
            return Accel {
                bvh: None,
                scale: 1.0,
                casters: shadow_casters(scene),
                build_time: Duration::ZERO,
            };
        }
        let start = std::time::Instant::now();
        let scale = bvh_scale(scene);
        let bvh = build_cwbvh_scaled(scene, scale);
        Accel {
            bvh: Some(bvh),
            scale,
            casters: Vec::new(),
            build_time: start.elapsed(),
        }
    }

    /// True when a BVH is in use.
    pub fn uses_bvh(&self) -> bool {
        self.bvh.is_some()
    }

    /// Closest hit in (T_MIN, tmax).
    pub fn closest(&self, scene: &Scene, ray: &Ray, tmax: f32, two_sided: bool) -> Hit {
        let mut best = Hit {
            t: tmax,
            prim: NO_HIT,
        };
        match &self.bvh {
            None => {
                for (i, tri) in scene.triangles.iter().enumerate() {
                    let t = intersect_triangle(tri, ray, best.t, two_sided);
                    if t < best.t {
                        best = Hit { t, prim: i as u32 };
                    }
                }
            }
            Some(bvh) => {
                // Ties go to the lowest triangle id, as in the loop above (`closer`), whatever
                // order the CWBVH visits them in: obvhs keeps only strictly closer hits, so the
                // pair (t, id) is tracked here.
                // The tree works in coordinates scaled by `self.scale`, and so do the
                // distances it is given back: a power of two, so both ways are exact.
                let scale = self.scale;
                let bray = obvhs_ray_scaled(ray, best.t, scale);
                let mut hit = RayHit::none();
                bvh.ray_traverse(bray, &mut hit, |_, id| {
                    let prim = bvh.primitive_indices[id];
                    let limit = if best.prim == NO_HIT {
                        best.t
                    } else {
                        best.t.next_up()
                    };
                    let t =
                        intersect_triangle(&scene.triangles[prim as usize], ray, limit, two_sided);
                    if closer(t, prim, best.t, best.prim) {
                        best = Hit { t, prim };
                    }
                    t * scale
                });
            }
        }
        let base = scene.triangles.len() as u32;
        for (i, sphere) in scene.spheres.iter().enumerate() {
            let t = intersect_sphere(sphere, ray, best.t);
            if t < best.t {
                best = Hit {
                    t,
                    prim: base + i as u32,
                };
            }
        }
        if best.prim == NO_HIT { Hit::MISS } else { best }
    }

    /// True when anything blocks the ray in (T_MIN, tmax): stops at the first blocker.
    pub fn occluded(&self, scene: &Scene, ray: &Ray, tmax: f32, two_sided: bool) -> bool {
        if scene.spheres.iter().any(|s| sphere_blocks(s, ray, tmax)) {
            return true;
        }
        match &self.bvh {
            None => casters(scene, &self.casters, two_sided)
                .iter()
                .any(|tri| intersect_triangle(tri, ray, tmax, two_sided) < tmax),
            Some(bvh) => {
                !bvh.ray_traverse_miss(obvhs_ray_scaled(ray, tmax, self.scale), |_, id| {
                    self.scale
                        * intersect_triangle(
                            &scene.triangles[bvh.primitive_indices[id] as usize],
                            ray,
                            tmax,
                            two_sided,
                        )
                })
            }
        }
    }
}

/// The triangles that can block a shadow ray toward one of the scene's lights when faces are
/// one-sided: every triangle except those with every light wholly on their front side.
///
/// A shadow ray runs from just off a surface towards a point p on a light, ending before the
/// light's plane (`spawn::shadow_ray`). A one-sided face is hit only by a ray going from its
/// front half-space to its back one, so it meets the face's plane at or beyond p when p is on
/// the front side or on the plane: it can never block (exactly for faces at right angles to the
/// light or coplanar with it; within the ray's offset, 2^-18 of the scene, for a face touching
/// the light at another angle). In the lab's box the light is a wall, so no wall can shadow it;
/// only the spheres can. Signed distances are taken in f64 with a tolerance of 1e-6 of the light
/// corner's coordinates and distance from the face, so a light *touching* a face's plane (the
/// lab's light shares an edge with four walls) counts as in front of it despite rounding. Both
/// engines test this same list, so they still agree bit for bit; with `--two-sided` every
/// triangle is tested.
pub fn shadow_casters(scene: &Scene) -> Vec<Triangle> {
    let corners: Vec<Vec3> = scene.lights.iter().flat_map(Light::corners).collect();
    scene
        .triangles
        .iter()
        .filter(|tri| {
            let (e1, e2) = (tri.e1.as_dvec3(), tri.e2.as_dvec3());
            let normal = e1.cross(e2);
            let length = normal.length();
            // A degenerate triangle is never hit (det = 0); keep it anyway, it costs nothing.
            if length.is_nan() || length == 0.0 {
                return true;
            }
            let normal = normal / length;
            let v0 = tri.v0.as_dvec3();
            corners.iter().any(|c| {
                // The tolerance is relative to this corner's own coordinates and its distance
                // from the face (what rounding in the light point and the face's edges scales
                // with), so one far-away vertex elsewhere cannot widen it for a small face.
                let c = c.as_dvec3();
                let tolerance = 1e-6 * (c - v0).abs().max_element().max(c.abs().max_element());
                normal.dot(c - v0) < -tolerance
            })
        })
        .copied()
        .collect()
}

/// The triangles a shadow ray tests without a BVH: the casters for one-sided faces, all of
/// them for two-sided ones.
#[inline]
pub fn casters<'a>(scene: &'a Scene, casters: &'a [Triangle], two_sided: bool) -> &'a [Triangle] {
    if two_sided { &scene.triangles } else { casters }
}

/// The CWBVH over a scene's triangles, with the preset every raywave BVH uses
/// (`medium_build`); `bvh.primitive_indices` maps its leaves back to `scene.triangles`.
pub fn build_cwbvh(scene: &Scene) -> CwBvh {
    build_cwbvh_scaled(scene, 1.0)
}

/// The larger of `m` and `v`'s largest absolute coordinate: fold a set of points with it.
pub fn largest_coordinate(m: f32, v: Vec3) -> f32 {
    m.max(v.abs().max_element())
}

/// The power of two that brings a scene's largest triangle coordinate to about 2^16.
///
/// obvhs's CWBVH node test clamps a ray's entry distance to an absolute 1e-4
/// (`cwbvh::node::EPSILON`), so a box nearer than that along a ray is skipped: in a scene a
/// thousand times smaller than the lab's, hits were lost (hundreds of pixels against the f64
/// oracle). The reference builds and walks the tree in coordinates scaled by this factor,
/// where 1e-4 is 1.5e-9 of the scene; a power of two changes no bits.
fn bvh_scale(scene: &Scene) -> f32 {
    let largest = scene
        .triangles
        .iter()
        .flat_map(|t| [t.v0, t.v0 + t.e1, t.v0 + t.e2])
        .fold(0.0f32, largest_coordinate);
    if !(largest.is_finite() && largest > 0.0) {
        return 1.0;
    }
    let exponent = (16 - largest.log2().ceil() as i32).clamp(-100, 100);
    2f32.powi(exponent)
}

/// `build_cwbvh` over the triangles scaled by `scale` (a power of two).
fn build_cwbvh_scaled(scene: &Scene, scale: f32) -> CwBvh {
    let tris: Vec<obvhs::triangle::Triangle> = scene
        .triangles
        .iter()
        .map(|t| obvhs::triangle::Triangle {
            v0: (t.v0 * scale).into(),
            v1: ((t.v0 + t.e1) * scale).into(),
            v2: ((t.v0 + t.e2) * scale).into(),
        })
        .collect();
    let mut core = Duration::ZERO;
    obvhs::cwbvh::builder::build_cwbvh_from_tris(&tris, BvhBuildParams::medium_build(), &mut core)
}

/// The obvhs ray for (T_MIN, tmax) along `ray`.
///
/// A −0.0 direction component becomes +0.0 (x + 0.0 does exactly that and changes nothing
/// else): obvhs inverts ±0 to ±1/ε by the sign bit but picks its CWBVH traversal octant by
/// `x < 0.0`, which is false for −0.0, so the two disagreed and such rays missed boxes they
/// lie in (half of the axis-aligned rays in tests/kernels/mesh_bvh.rs). Only the traversal sees
/// this ray; the triangle tests use the caller's.
pub fn obvhs_ray(ray: &Ray, tmax: f32) -> obvhs::ray::Ray {
    obvhs_ray_scaled(ray, tmax, 1.0)
}

/// `obvhs_ray` in coordinates scaled by `scale` (a power of two): the origin and distances
/// scale, the direction does not.
fn obvhs_ray_scaled(ray: &Ray, tmax: f32, scale: f32) -> obvhs::ray::Ray {
    obvhs::ray::Ray::new(
        Vec3A::from(ray.origin * scale),
        Vec3A::from(ray.direction + Vec3::ZERO),
        T_MIN * scale,
        tmax * scale,
    )
}
