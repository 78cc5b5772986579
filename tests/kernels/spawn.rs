//! Secondary rays never meet the surface they leave, at every scale: the property behind the
//! speckle-free spheres, tested on the spawn functions both engines call (`raywave::render::spawn`)
//! with the intersection kernels both use. The images themselves are held to an independent
//! f64 oracle in tests/images/oracle_agreement.rs.

use crate::common;

use common::{Draw, TestRng, seeded, triangle};
use glam::Vec3;
use raywave::render::geometry::{Accel, Ray, intersect_sphere};
use raywave::render::scene::{Scene, Sphere};
use raywave::render::spawn::{
    LightEnd, SurfaceHit, light_end, light_offset, mirror_ray, shadow_ray, sphere_offset,
    surface_hit,
};

const SCALES: [f32; 5] = [1e-3, 1e-1, 1.0, 10.0, 1e3];
const RAYS: usize = 20_000;

/// A sphere of the lab's size and place (radius 0.25 to 0.45, centre within the unit box),
/// scaled by `s`, and an eye 8·s away, as the lab's camera is.
fn sphere_and_eye(rng: &mut TestRng, s: f32) -> (Sphere, Vec3) {
    let sphere = Sphere {
        center: rng.point(0.6) * s,
        radius: (0.25 + 0.2 * rng.unit()) * s,
        material: 0,
    };
    let eye = rng.direction() * (8.0 * s);
    (sphere, eye)
}

/// A camera ray from `eye` towards a random point of the sphere's disc, and where it hits.
fn camera_hit(rng: &mut TestRng, sphere: &Sphere, eye: Vec3) -> Option<(Ray, f32)> {
    let aim = sphere.center + rng.point(sphere.radius * 0.999);
    let ray = Ray {
        origin: eye,
        direction: (aim - eye).normalize(),
    };
    let t = intersect_sphere(sphere, &ray, f32::INFINITY);
    t.is_finite().then_some((ray, t))
}

/// The end of a shadow ray to `target` as if it were a small light facing the hit (its plane
/// through `target`, perpendicular to the ray), as `spawn::light_end` computes it.
fn towards(hit: &SurfaceHit, target: Vec3) -> LightEnd {
    let normal = (hit.point - target).normalize();
    let origin = hit.point + hit.offset * hit.normal;
    let height = normal.dot(origin - target) - hit.offset;
    LightEnd {
        ratio: height / normal.dot(hit.point - target),
        margin: hit.offset,
    }
}

fn sphere_scene(sphere: Sphere) -> Scene {
    Scene {
        spheres: vec![sphere],
        ..Scene::default()
    }
}

#[test]
fn mirror_and_shadow_rays_leave_a_sphere_at_every_scale() {
    for s in SCALES {
        let mut rng = seeded(0x5eed ^ s.to_bits() as u64);
        let (mut mirror_rehits, mut shadow_rehits, mut hits) = (0, 0, 0);
        for _ in 0..RAYS {
            let (sphere, eye) = sphere_and_eye(&mut rng, s);
            let Some((ray, t)) = camera_hit(&mut rng, &sphere, eye) else {
                continue;
            };
            hits += 1;
            let scene = sphere_scene(sphere);
            let hit = surface_hit(&scene, 0, &ray, t, false);
            // Hit from outside, so the mirror ray goes out and can never meet the sphere again.
            let mirror = mirror_ray(&hit, ray.direction);
            if intersect_sphere(&sphere, &mirror, f32::INFINITY).is_finite() {
                mirror_rehits += 1;
            }
            // A light point anywhere above the tangent plane, near or far, grazing or not.
            let target = hit.point + rng.direction() * (s * 4.0 * rng.unit());
            if let Some(shadow) = shadow_ray(&hit, target, &towards(&hit, target))
                && intersect_sphere(&sphere, &shadow.ray, shadow.tmax) < shadow.tmax
            {
                shadow_rehits += 1;
            }
        }
        assert!(hits > RAYS / 2, "scale {s}: only {hits} camera hits");
        assert_eq!(
            (mirror_rehits, shadow_rehits),
            (0, 0),
            "scale {s}: rays that met the sphere they left, of {hits}"
        );
    }
}

#[test]
fn hit_points_are_put_back_on_the_sphere() {
    // The camera ray's raw hit point was 4e-5 inside a lab sphere 8 units away; put back on
    // the surface it is within a few ulps of it, far closer than the offset.
    for s in SCALES {
        let mut rng = seeded(0xb0b ^ s.to_bits() as u64);
        let mut worst = 0.0f64;
        for _ in 0..RAYS {
            let (sphere, eye) = sphere_and_eye(&mut rng, s);
            let Some((ray, t)) = camera_hit(&mut rng, &sphere, eye) else {
                continue;
            };
            let hit = surface_hit(&sphere_scene(sphere), 0, &ray, t, false);
            let off = (hit.point.as_dvec3() - sphere.center.as_dvec3()).length()
                - f64::from(sphere.radius);
            worst = worst.max(off.abs() / f64::from(sphere_offset(&sphere)));
        }
        assert!(
            worst < 0.1,
            "scale {s}: a point off the sphere by {worst} offsets"
        );
    }
}

#[test]
fn a_mirror_ray_inside_a_sphere_meets_its_far_side() {
    for s in SCALES {
        let mut rng = seeded(0x1ed ^ s.to_bits() as u64);
        for _ in 0..2_000 {
            let sphere = Sphere {
                center: rng.point(0.6) * s,
                radius: 0.4 * s,
                material: 0,
            };
            // From inside, towards the surface.
            let ray = Ray {
                origin: sphere.center + rng.point(0.2 * s),
                direction: rng.direction(),
            };
            let t = intersect_sphere(&sphere, &ray, f32::INFINITY);
            assert!(t.is_finite());
            let hit = surface_hit(&sphere_scene(sphere), 0, &ray, t, false);
            let mirror = mirror_ray(&hit, ray.direction);
            let t2 = intersect_sphere(&sphere, &mirror, f32::INFINITY);
            // The chord from a point on the sphere along d has length 2r·|n·d| (in f64).
            let n = hit.normal.as_dvec3();
            let chord = 2.0 * f64::from(sphere.radius) * n.dot(mirror.direction.as_dvec3()).abs();
            assert!(
                (f64::from(t2) - chord).abs() < 1e-4 * f64::from(sphere.radius),
                "scale {s}: inside mirror ray met the far side at {t2}, chord {chord}"
            );
        }
    }
}

/// A light made of `k`² small quads (2k² triangles, above the BVH threshold) in the plane
/// z = `height`, facing down, spanning [−s, s]².
fn tessellated_light(s: f32, height: f32, k: usize) -> Scene {
    let mut text = String::from("material\ndiffuse 0 0 0\nemitted 1 1 1\nm 0\n");
    let step = 2.0 * s / k as f32;
    for i in 0..=k {
        for j in 0..=k {
            let (x, y) = (-s + i as f32 * step, -s + j as f32 * step);
            text.push_str(&format!("v {x} {y} {height}\n"));
        }
    }
    let id = |i: usize, j: usize| i * (k + 1) + j + 1;
    for i in 0..k {
        for j in 0..k {
            // Counter-clockwise seen from below: the front faces −z.
            text.push_str(&format!(
                "f {} {} {} {}\n",
                id(i, j),
                id(i, j + 1),
                id(i + 1, j + 1),
                id(i + 1, j)
            ));
        }
    }
    raywave::render::scene::parse_scene_str(&text, "light.obj").expect("the light parses")
}

#[test]
fn shadow_rays_end_before_the_light_even_at_grazing_angles() {
    for s in SCALES {
        let scene = tessellated_light(s, 0.7 * s, 8);
        let accel = Accel::new(&scene);
        assert!(
            accel.uses_bvh(),
            "every triangle is tested, the light's own included"
        );
        let mut rng = seeded(0x119 ^ s.to_bits() as u64);
        let mut blocked = 0;
        for _ in 0..RAYS {
            // A floor point, some far off to the side so that rays reach the light grazing.
            let spread = if rng.unit() < 0.5 { 1.0 } else { 40.0 };
            let p = rng.point(spread * s);
            let floor = SurfaceHit {
                point: Vec3::new(p.x, p.y, -s),
                normal: Vec3::Z,
                offset: raywave::render::spawn::OFFSET_SCALE * s * spread,
            };
            let count = scene.lights.len();
            let light = &scene.lights[((rng.unit() * count as f32) as usize).min(count - 1)];
            let (u, v) = (rng.unit(), rng.unit());
            let end_offset = light_offset(light);
            let end = light_end(light, end_offset, &floor);
            let Some(shadow) = shadow_ray(&floor, light.point(u, v), &end) else {
                continue;
            };
            if accel.occluded(&scene, &shadow.ray, shadow.tmax, false) {
                blocked += 1;
            }
        }
        assert_eq!(
            blocked, 0,
            "scale {s}: shadow rays blocked by the light they go to"
        );
    }
}

#[test]
fn two_sided_faces_do_not_shadow_themselves_or_their_other_half() {
    for s in SCALES {
        // One quad, two triangles sharing the a–c diagonal, seen from both sides.
        let (a, b, c, d) = (
            Vec3::new(-1.0, -1.0, 0.3) * s,
            Vec3::new(1.0, -1.0, 0.3) * s,
            Vec3::new(1.0, 1.0, 0.3) * s,
            Vec3::new(-1.0, 1.0, 0.3) * s,
        );
        let scene = Scene {
            triangles: vec![triangle(a, b, c), triangle(a, c, d)],
            ..Scene::default()
        };
        let accel = Accel::new(&scene);
        let mut rng = seeded(0x25 ^ s.to_bits() as u64);
        let mut self_hits = 0;
        for _ in 0..RAYS {
            let eye = rng.direction() * (8.0 * s);
            let aim = Vec3::new(rng.unit() * 2.0 - 1.0, rng.unit() * 2.0 - 1.0, 0.3) * s;
            let ray = Ray {
                origin: eye,
                direction: (aim - eye).normalize(),
            };
            let hit = accel.closest(&scene, &ray, f32::INFINITY, true);
            if !hit.is_hit() {
                continue;
            }
            let surface = surface_hit(&scene, hit.prim, &ray, hit.t, true);
            let mirror = mirror_ray(&surface, ray.direction);
            if accel.closest(&scene, &mirror, f32::INFINITY, true).is_hit() {
                self_hits += 1;
            }
            let target = surface.point + rng.direction() * (3.0 * s);
            if let Some(shadow) = shadow_ray(&surface, target, &towards(&surface, target))
                && accel.occluded(&scene, &shadow.ray, shadow.tmax, true)
            {
                self_hits += 1;
            }
        }
        assert_eq!(self_hits, 0, "scale {s}: rays met the quad they left");
    }
}

#[test]
fn offsets_scale_with_the_scene() {
    let sphere = Sphere {
        center: Vec3::new(0.3, -0.6, 0.1),
        radius: 0.3,
        material: 0,
    };
    for s in SCALES {
        let scaled = Sphere {
            center: sphere.center * s,
            radius: sphere.radius * s,
            material: 0,
        };
        let ratio = f64::from(sphere_offset(&scaled)) / f64::from(sphere_offset(&sphere));
        assert!(
            (ratio / f64::from(s) - 1.0).abs() < 1e-6,
            "scale {s}: ratio {ratio}"
        );
        // And small against the sphere: well under a millionth of a box.
        assert!(f64::from(sphere_offset(&scaled)) < 1e-5 * f64::from(s));
    }
}
