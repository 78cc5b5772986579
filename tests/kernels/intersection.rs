//! Edge cases of the scalar kernels: one-sided quads (front, back, two-sided), the a–c
//! diagonal, grazing rays, spheres from outside, inside and behind, NaN and infinite input,
//! and the t > 1e-4 rule. Expected distances are worked out by hand in each test.

use crate::common;

use common::{TestRng, seeded};
use glam::Vec3;
use rand::RngExt;
use raywave::render::geometry::{Accel, Ray, T_MIN, intersect_sphere, intersect_triangle};
use raywave::render::scene::{NO_HIT, Scene, Sphere, parse_scene_str};

/// The unit square z = 0, x and y in [0, 2], wound counter-clockwise seen from +z: its front
/// faces +z. Quad a b c d = (0,0) (2,0) (2,2) (0,2), split along a–c.
fn square() -> Scene {
    parse_scene_str(
        "material\ndiffuse 1 1 1\nm 0\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4\n",
        "square.obj",
    )
    .unwrap()
}

fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
    Ray {
        origin: Vec3::from_array(o),
        direction: Vec3::from_array(d),
    }
}

/// Closest t over the scene's triangles with the plain kernel.
fn quad_t(scene: &Scene, r: &Ray, two_sided: bool) -> f32 {
    scene
        .triangles
        .iter()
        .map(|t| intersect_triangle(t, r, f32::INFINITY, two_sided))
        .fold(f32::INFINITY, f32::min)
}

#[test]
fn quad_is_hit_from_the_front_only() {
    let s = square();
    assert_eq!(s.triangles.len(), 2);
    let front = ray([0.5, 1.5, 3.0], [0.0, 0.0, -1.0]);
    assert_eq!(quad_t(&s, &front, false), 3.0);
    let back = ray([0.5, 1.5, -3.0], [0.0, 0.0, 1.0]);
    assert_eq!(quad_t(&s, &back, false), f32::INFINITY);
    assert_eq!(quad_t(&s, &back, true), 3.0);
    assert_eq!(quad_t(&s, &front, true), 3.0);
    // An oblique ray from the front: from (1, 1, 2) towards (1.5, 0.5, 0): t = |(0.5,-0.5,-2)|.
    let d = Vec3::new(0.5, -0.5, -2.0);
    let oblique = Ray {
        origin: Vec3::new(1.0, 1.0, 2.0),
        direction: d.normalize(),
    };
    assert!((quad_t(&s, &oblique, false) - d.length()).abs() < 1e-5);
    // Outside the square: miss from either side.
    let outside = ray([2.5, 1.0, 3.0], [0.0, 0.0, -1.0]);
    assert_eq!(quad_t(&s, &outside, true), f32::INFINITY);
    let outside = ray([-0.001, 1.0, 3.0], [0.0, 0.0, -1.0]);
    assert_eq!(quad_t(&s, &outside, true), f32::INFINITY);
}

#[test]
fn accel_reports_the_face_and_respects_two_sided() {
    let s = square();
    let accel = Accel::new(&s);
    let front = ray([1.5, 0.5, 1.0], [0.0, 0.0, -1.0]);
    let hit = accel.closest(&s, &front, f32::INFINITY, false);
    assert_eq!(hit.t, 1.0);
    assert_eq!(hit.prim, 0, "(1.5, 0.5) is in triangle a b c");
    let hit = accel.closest(
        &s,
        &ray([0.5, 1.5, 1.0], [0.0, 0.0, -1.0]),
        f32::INFINITY,
        false,
    );
    assert_eq!(hit.prim, 1, "(0.5, 1.5) is in triangle a c d");
    let back = ray([1.5, 0.5, -1.0], [0.0, 0.0, 1.0]);
    let miss = accel.closest(&s, &back, f32::INFINITY, false);
    assert_eq!((miss.t, miss.prim), (f32::INFINITY, NO_HIT));
    assert!(!accel.occluded(&s, &back, 10.0, false));
    assert!(accel.occluded(&s, &back, 10.0, true));
    // tmax shorter than the distance: no hit, not occluded.
    assert!(!accel.occluded(&s, &front, 0.999, false));
    assert!(!accel.closest(&s, &front, 0.999, false).is_hit());
}

#[test]
fn rays_through_the_a_c_diagonal_hit() {
    // Points exactly on the diagonal x = y strictly between a and c, from many directions;
    // none may fall in a crack between the two triangles. (The corners a and c are on the
    // quad's outer boundary, where a miss by rounding is a silhouette, not a crack.)
    let s = square();
    let mut misses = Vec::new();
    let n = 256;
    for k in 1..n {
        let along = 2.0 * k as f32 / n as f32;
        let target = Vec3::new(along, along, 0.0);
        for (dx, dy) in [
            (0.0, 0.0),
            (0.3, -0.7),
            (-0.61, 0.2),
            (0.123, 0.456),
            (-0.9, -0.35),
            (1e-3, -1e-3),
        ] {
            let origin = target + Vec3::new(dx, dy, 1.7);
            let r = Ray {
                origin,
                direction: (target - origin).normalize(),
            };
            for two_sided in [false, true] {
                if quad_t(&s, &r, two_sided) == f32::INFINITY {
                    misses.push((target, dx, dy, two_sided));
                }
            }
        }
    }
    assert!(
        misses.is_empty(),
        "rays through the diagonal missed: {misses:?}"
    );
}

#[test]
fn grazing_rays_in_the_plane_miss() {
    let s = square();
    for (o, d) in [
        ([-1.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
        ([1.0, -1.0, 0.0], [0.0, 1.0, 0.0]),
        ([-1.0, -1.0, 0.0], [1.0, 1.0, 0.0]), // along the diagonal itself
        ([1.0, 1.0, 0.0], [0.6, 0.8, 0.0]),   // starting inside the face
    ] {
        let r = ray(o, d);
        assert_eq!(quad_t(&s, &r, false), f32::INFINITY, "{r:?}");
        assert_eq!(quad_t(&s, &r, true), f32::INFINITY, "{r:?} two-sided");
    }
}

#[test]
fn t_must_exceed_zero() {
    let s = square();
    assert_eq!(T_MIN, 0.0);
    // Starting on the face: t = 0 is not a hit.
    let on = ray([1.0, 0.5, 0.0], [0.0, 0.0, -1.0]);
    assert_eq!(quad_t(&s, &on, true), f32::INFINITY);
    let on = ray([1.0, 0.5, 0.0], [0.0, 0.0, 1.0]);
    assert_eq!(quad_t(&s, &on, true), f32::INFINITY);
    // Any positive distance is: there is no absolute epsilon, which would be wrong at some
    // scale (secondary rays start off their surface instead: tests/kernels/spawn.rs).
    let near = ray([1.0, 0.5, 1e-6], [0.0, 0.0, -1.0]);
    assert!((quad_t(&s, &near, false) - 1e-6).abs() < 1e-12);
    // A sphere: a ray from just outside the surface, going out, does not hit it; going in, it
    // meets the far side at t ≈ 2.
    let sphere = Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
        material: 0,
    };
    let leaving = ray([1.0 + 1e-5, 0.0, 0.0], [1.0, 0.0, 0.0]);
    assert_eq!(
        intersect_sphere(&sphere, &leaving, f32::INFINITY),
        f32::INFINITY
    );
    let inwards = ray([1.0 + 1e-5, 0.0, 0.0], [-1.0, 0.0, 0.0]);
    assert!((intersect_sphere(&sphere, &inwards, f32::INFINITY) - 1e-5).abs() < 1e-6);
    let inside = ray([1.0 - 1e-5, 0.0, 0.0], [-1.0, 0.0, 0.0]);
    assert!((intersect_sphere(&sphere, &inside, f32::INFINITY) - 2.0).abs() < 1e-4);
}

#[test]
fn sphere_from_outside_inside_and_behind() {
    let sphere = Sphere {
        center: Vec3::new(1.0, 2.0, 3.0),
        radius: 0.5,
        material: 0,
    };
    // Outside, towards the centre from 4 units away: t = 3.5.
    let outside = ray([1.0, 2.0, 7.0], [0.0, 0.0, -1.0]);
    assert!((intersect_sphere(&sphere, &outside, f32::INFINITY) - 3.5).abs() < 1e-6);
    // From the centre: the far root, t = r.
    let inside = ray([1.0, 2.0, 3.0], [0.6, 0.0, 0.8]);
    assert!((intersect_sphere(&sphere, &inside, f32::INFINITY) - 0.5).abs() < 1e-6);
    // From inside, off centre: origin (1, 2, 3.3), going +z: exits at z = 3.5, t = 0.2.
    let off = ray([1.0, 2.0, 3.3], [0.0, 0.0, 1.0]);
    assert!((intersect_sphere(&sphere, &off, f32::INFINITY) - 0.2).abs() < 1e-6);
    // Going -z from there: exits at z = 2.5, t = 0.8.
    let off = ray([1.0, 2.0, 3.3], [0.0, 0.0, -1.0]);
    assert!((intersect_sphere(&sphere, &off, f32::INFINITY) - 0.8).abs() < 1e-6);
    // Behind the ray: the sphere is at negative t only.
    let behind = ray([1.0, 2.0, 7.0], [0.0, 0.0, 1.0]);
    assert_eq!(
        intersect_sphere(&sphere, &behind, f32::INFINITY),
        f32::INFINITY
    );
    // Passing beside it.
    let beside = ray([1.6, 2.0, 7.0], [0.0, 0.0, -1.0]);
    assert_eq!(
        intersect_sphere(&sphere, &beside, f32::INFINITY),
        f32::INFINITY
    );
    // Non-unit direction: t scales inversely (direction of length 2 -> t = 1.75).
    let long = ray([1.0, 2.0, 7.0], [0.0, 0.0, -2.0]);
    assert!((intersect_sphere(&sphere, &long, f32::INFINITY) - 1.75).abs() < 1e-6);
    // tmax before the hit.
    assert_eq!(intersect_sphere(&sphere, &outside, 3.4), f32::INFINITY);
}

#[test]
fn sphere_normal_is_outward_even_from_inside() {
    let s = parse_scene_str("material\ndiffuse 1 1 1\nm 0\ns 0 0 0 2\n", "s.obj").unwrap();
    let accel = Accel::new(&s);
    let r = ray([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let hit = accel.closest(&s, &r, f32::INFINITY, false);
    assert_eq!(hit.prim, 0);
    assert!((hit.t - 2.0).abs() < 1e-6);
    let n = raywave::render::spawn::surface_hit(&s, hit.prim, &r, hit.t, false).normal;
    assert!(n.distance(Vec3::Y) < 1e-6, "{n}");
}

#[test]
fn nan_and_infinite_input_miss() {
    let s = square();
    let sphere = Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
        material: 0,
    };
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    let bad = [
        ([nan, 1.0, 1.0], [0.0, 0.0, -1.0]),
        ([1.0, 1.0, 1.0], [0.0, 0.0, nan]),
        ([1.0, 1.0, 1.0], [nan, nan, nan]),
        ([inf, 1.0, 1.0], [0.0, 0.0, -1.0]),
        ([1.0, 1.0, inf], [0.0, 0.0, -1.0]),
        ([1.0, 1.0, -inf], [0.0, 0.0, 1.0]),
        ([1.0, 1.0, 1.0], [0.0, 0.0, -inf]),
        ([1.0, 1.0, 1.0], [inf, 0.0, -1.0]),
        ([0.0, 0.0, 0.0], [0.0, inf, 0.0]),
        ([0.0, 0.0, 5.0], [0.0, 0.0, -inf]),
        ([-inf, -inf, -inf], [1.0, 1.0, 1.0]),
    ];
    let accel = Accel::new(&s);
    for (o, d) in bad {
        let r = ray(o, d);
        for two_sided in [false, true] {
            for tri in &s.triangles {
                let t = intersect_triangle(tri, &r, inf, two_sided);
                assert_eq!(t, inf, "triangle, {r:?}, two_sided {two_sided}");
            }
            let hit = accel.closest(&s, &r, inf, two_sided);
            assert_eq!((hit.t, hit.prim), (inf, NO_HIT), "{r:?}");
        }
        let t = intersect_sphere(&sphere, &r, inf);
        assert_eq!(t, inf, "sphere, {r:?}");
    }
    // A NaN tmax never admits a hit either.
    let good = ray([1.0, 1.0, 1.0], [0.0, 0.0, -1.0]);
    assert_eq!(intersect_triangle(&s.triangles[0], &good, nan, false), inf);
    assert_eq!(
        intersect_sphere(&sphere, &ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]), nan),
        inf
    );
}

#[test]
fn zero_direction_misses() {
    let s = square();
    let sphere = Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
        material: 0,
    };
    let r = ray([1.0, 1.0, 1.0], [0.0, 0.0, 0.0]);
    assert_eq!(quad_t(&s, &r, true), f32::INFINITY);
    assert_eq!(intersect_sphere(&sphere, &r, f32::INFINITY), f32::INFINITY);
    let inside = ray([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]);
    assert_eq!(
        intersect_sphere(&sphere, &inside, f32::INFINITY),
        f32::INFINITY
    );
}

#[test]
fn bvh_and_brute_force_agree_on_a_mesh() {
    // 12 × 12 grid of quads (288 triangles, above the BVH threshold) facing +z, plus a sphere;
    // every ray's closest hit must match a brute-force loop over the kernels.
    let mut text = String::from("material\ndiffuse 1 1 1\nm 0\n");
    let n = 12;
    for j in 0..=n {
        for i in 0..=n {
            // A gently curved surface so the triangles are not coplanar.
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            text += &format!("v {x} {y} {}\n", 0.1 * (x * 3.0).sin() * (y * 2.0).cos());
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            text += &format!("f {} {} {} {}\n", a, a + 1, a + n + 2, a + n + 1);
        }
    }
    text += "s 0.5 0.5 0.3 0.1\n";
    let s = parse_scene_str(&text, "grid.obj").unwrap();
    let accel = Accel::new(&s);
    assert!(accel.uses_bvh());
    let mut state = 12345u32;
    let mut rnd = || {
        state = raywave::render::sampling::mix32(state.wrapping_add(0x9e37_79b9));
        (state >> 8) as f32 / 16_777_216.0
    };
    let mut hits = 0;
    for _ in 0..2000 {
        let origin = Vec3::new(rnd() * 1.4 - 0.2, rnd() * 1.4 - 0.2, 1.0);
        let target = Vec3::new(rnd(), rnd(), 0.0);
        let r = Ray {
            origin,
            direction: (target - origin).normalize(),
        };
        for two_sided in [false, true] {
            let mut best = (f32::INFINITY, NO_HIT);
            for (i, t) in s.triangles.iter().enumerate() {
                let d = intersect_triangle(t, &r, f32::INFINITY, two_sided);
                if d < best.0 {
                    best = (d, i as u32);
                }
            }
            let ds = intersect_sphere(&s.spheres[0], &r, f32::INFINITY);
            if ds < best.0 {
                best = (ds, s.triangles.len() as u32);
            }
            let hit = accel.closest(&s, &r, f32::INFINITY, two_sided);
            assert!(
                (hit.t - best.0).abs() <= 1e-5 * best.0.max(1.0) || hit.t == best.0,
                "{r:?}: bvh {hit:?}, brute {best:?}"
            );
            if best.0.is_finite() {
                assert_eq!(hit.prim, best.1, "{r:?}: bvh {hit:?}, brute {best:?}");
                hits += 1;
                assert!(accel.occluded(&s, &r, best.0 + 1e-3, two_sided));
            }
            assert!(!accel.occluded(&s, &r, best.0 * 0.999, two_sided));
        }
    }
    assert!(hits > 1000, "{hits}");
}

/// A point in the cube [−scale, scale]³.
fn vec(rng: &mut TestRng, scale: f64) -> glam::DVec3 {
    glam::DVec3::from_array(std::array::from_fn(|_| rng.random_range(-scale..scale)))
}

#[test]
fn triangle_kernel_matches_an_independent_f64_plane_test() {
    // Intersect the plane in f64, then barycentric coordinates by areas; only cases that are
    // clearly inside or clearly outside (margin 1e-3) are checked.
    let mut rng = seeded(99);
    let (mut hits, mut misses, mut backs) = (0, 0, 0);
    for _ in 0..20000 {
        // Every input is rounded to f32 first, so the f64 answer is for the kernel's inputs.
        let f = |v: glam::DVec3| v.as_vec3().as_dvec3();
        let a = f(vec(&mut rng, 2.0));
        let e1 = f(vec(&mut rng, 2.0) - a);
        let e2 = f(vec(&mut rng, 2.0) - a);
        let (b, c) = (a + e1, a + e2);
        let n = e1.cross(e2);
        if n.length() < 0.1 {
            continue;
        }
        let origin = f(vec(&mut rng, 4.0));
        let target = a + rng.random::<f64>() * 1.4 * e1 + rng.random::<f64>() * 1.4 * e2 - 0.2 * e1;
        let d = f((target - origin).normalize());
        let denom = n.dot(d);
        // Near-grazing rays amplify the rounding inside the kernel: skip them.
        if denom.abs() < 0.05 * n.length() {
            continue;
        }
        let t = n.dot(a - origin) / denom;
        let p = origin + t * d;
        let area = n.length();
        let w = [
            (c - b).cross(p - b).dot(n) / (area * area),
            (a - c).cross(p - c).dot(n) / (area * area),
            (b - a).cross(p - a).dot(n) / (area * area),
        ];
        let min_w = w.iter().cloned().fold(f64::INFINITY, f64::min);
        let clearly_in = min_w > 1e-3 && t > 1e-2;
        let clearly_out = min_w < -1e-3 || t < -1e-2;
        if !(clearly_in || clearly_out) {
            continue;
        }
        let tri = raywave::render::scene::Triangle {
            v0: a.as_vec3(),
            e1: e1.as_vec3(),
            e2: e2.as_vec3(),
            normal: n.normalize().as_vec3(),
            material: 0,
            face: 0,
        };
        let r = Ray {
            origin: origin.as_vec3(),
            direction: d.as_vec3(),
        };
        let front = denom < 0.0;
        let one = intersect_triangle(&tri, &r, f32::INFINITY, false);
        let two = intersect_triangle(&tri, &r, f32::INFINITY, true);
        if clearly_in {
            assert!(
                (two as f64 - t).abs() < 1e-4 * t.max(1.0),
                "{r:?} {tri:?}: {two} vs {t}"
            );
            if front {
                assert_eq!(one, two);
                hits += 1;
            } else {
                assert_eq!(one, f32::INFINITY, "back face hit: {r:?} {tri:?}");
                backs += 1;
            }
            // tmax just below t: no hit.
            assert_eq!(
                intersect_triangle(&tri, &r, (t * 0.999) as f32, true),
                f32::INFINITY
            );
        } else {
            assert_eq!(
                two,
                f32::INFINITY,
                "{r:?} {tri:?}: hit at {two}, expected a miss"
            );
            misses += 1;
        }
    }
    assert!(
        hits > 1000 && misses > 1000 && backs > 1000,
        "{hits} {misses} {backs}"
    );
}

#[test]
fn sphere_kernel_matches_an_independent_f64_root() {
    let mut rng = seeded(7);
    let (mut hits, mut misses, mut inside) = (0, 0, 0);
    for _ in 0..20000 {
        let f = |v: glam::DVec3| v.as_vec3().as_dvec3();
        let center = f(vec(&mut rng, 2.0));
        let radius = (0.1 + rng.random::<f64>() * 1.5) as f32 as f64;
        let origin = f(vec(&mut rng, 4.0));
        let d = f((center + vec(&mut rng, 2.0) - origin).normalize());
        // |o + t d − c|² = r²  ->  t² + 2 b t + c0 = 0 with b = (o − c)·d.
        let oc = origin - center;
        let b = oc.dot(d);
        let c0 = oc.length_squared() - radius * radius;
        let disc = b * b - c0;
        let roots = if disc > 0.0 {
            let s = disc.sqrt();
            vec![-b - s, -b + s]
        } else {
            vec![]
        };
        let expected = roots.iter().cloned().find(|&t| t > 1e-2);
        let ambiguous = disc.abs() < 1e-3 || roots.iter().any(|&t| t.abs() <= 1e-2);
        if ambiguous {
            continue;
        }
        let s = Sphere {
            center: center.as_vec3(),
            radius: radius as f32,
            material: 0,
        };
        let r = Ray {
            origin: origin.as_vec3(),
            direction: d.as_vec3(),
        };
        let got = intersect_sphere(&s, &r, f32::INFINITY);
        match expected {
            Some(t) => {
                assert!(
                    (got as f64 - t).abs() < 1e-4 * t.max(1.0),
                    "{r:?} {s:?}: {got} vs {t}"
                );
                if c0 < 0.0 {
                    inside += 1;
                } else {
                    hits += 1;
                }
            }
            None => {
                assert_eq!(got, f32::INFINITY, "{r:?} {s:?}");
                misses += 1;
            }
        }
    }
    assert!(
        hits > 1000 && misses > 1000 && inside > 100,
        "{hits} {misses} {inside}"
    );
}

/// The occlusion test `sphere_blocks` answers as `intersect_sphere(..) < tmax` does, and as an
/// f64 root would, on random segments (roots or tmax within 1e-3 of each other or of 0 are the
/// ambiguous cases left out: there the product and the quotient may round apart).
#[test]
fn sphere_blocks_agrees_with_the_closest_hit_and_an_f64_root() {
    use raywave::render::geometry::sphere_blocks;
    let mut rng = seeded(11);
    let (mut blocked, mut clear) = (0, 0);
    for _ in 0..20000 {
        let f = |v: glam::DVec3| v.as_vec3().as_dvec3();
        let center = f(vec(&mut rng, 2.0));
        let radius = (0.1 + rng.random::<f64>() * 1.5) as f32 as f64;
        let origin = f(vec(&mut rng, 4.0));
        let d = f((center + vec(&mut rng, 2.0) - origin).normalize());
        let tmax = (rng.random::<f64>() * 8.0) as f32 as f64;
        let oc = origin - center;
        let b = oc.dot(d);
        let disc = b * b - (oc.length_squared() - radius * radius);
        let roots = if disc > 0.0 {
            vec![-b - disc.sqrt(), -b + disc.sqrt()]
        } else {
            vec![]
        };
        let near = |x: f64, y: f64| (x - y).abs() <= 1e-3;
        if disc.abs() < 1e-3 || roots.iter().any(|&t| near(t, 0.0) || near(t, tmax)) {
            continue;
        }
        let expected = roots.iter().any(|&t| t > 0.0 && t < tmax);
        let s = Sphere {
            center: center.as_vec3(),
            radius: radius as f32,
            material: 0,
        };
        let r = Ray {
            origin: origin.as_vec3(),
            direction: d.as_vec3(),
        };
        let got = sphere_blocks(&s, &r, tmax as f32);
        assert_eq!(got, expected, "{r:?} {s:?} tmax {tmax}: roots {roots:?}");
        assert_eq!(got, intersect_sphere(&s, &r, tmax as f32) < tmax as f32);
        if got {
            blocked += 1;
        } else {
            clear += 1;
        }
    }
    assert!(
        blocked > 2000 && clear > 2000,
        "{blocked} blocked, {clear} clear"
    );
}
