//! Shadow-caster culling (`geometry::shadow_casters`): a one-sided face with every light on its
//! front side (or on its plane) can never block a shadow ray, so the engines skip it. These
//! tests check the rule by hand on the lab's box and on two facing blockers, and check on random
//! scenes that culling never changes whether a shadow ray is blocked.

use crate::common;

use common::{Draw, TestRng, seeded};
use glam::Vec3;
use raywave::render::geometry::{Accel, Ray, intersect_sphere, intersect_triangle, shadow_casters};
use raywave::render::scene::{Scene, parse_scene_str};
use raywave::render::spawn::{SurfaceHit, light_end, light_offset, shadow_ray};
use std::fmt::Write;
use std::path::Path;

fn scene(name: &str) -> Scene {
    Scene::load(&Path::new(env!("RAYWAVE_REPO")).join("scenes").join(name)).unwrap()
}

/// Blocked with every triangle tested: what the engines did before culling.
fn blocked_unculled(scene: &Scene, ray: &Ray, tmax: f32) -> bool {
    scene
        .spheres
        .iter()
        .any(|s| intersect_sphere(s, ray, tmax) < tmax)
        || scene
            .triangles
            .iter()
            .any(|t| intersect_triangle(t, ray, tmax, false) < tmax)
}

#[test]
fn the_lab_box_walls_never_shadow_its_light() {
    // The light is the box's front wall: every wall, and the light itself, has it on or in front
    // of its plane, so only the spheres can cast shadows.
    for name in [
        "cornell_box.obj",
        "cornell_box_diffuse_sphere.obj",
        "cornell_box_reflective_spheres.obj",
    ] {
        let s = scene(name);
        assert_eq!(s.triangles.len(), 12, "{name}");
        assert_eq!(shadow_casters(&s).len(), 0, "{name}");
    }
}

/// A light square at y = 2 facing down, and a blocker square at y = 1 over x, z in [−1, 1],
/// wound to face `blocker_faces` (−1: down, towards the floor; +1: up, towards the light).
fn blocker_scene(blocker_faces: f32) -> Scene {
    let blocker = if blocker_faces > 0.0 {
        "f 5 6 7 8"
    } else {
        "f 8 7 6 5"
    };
    let text = format!(
        "material\ndiffuse 1 1 1\nemitted 1 1 1\nmaterial\ndiffuse 1 1 1\n\
         v -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n\
         v -1 1 -1\nv -1 1 1\nv 1 1 1\nv 1 1 -1\n\
         m 0\nf 1 2 3 4\nm 1\n{blocker}\n"
    );
    parse_scene_str(&text, "blocker.obj").unwrap()
}

#[test]
fn a_face_is_kept_exactly_when_it_can_block() {
    let down = blocker_scene(-1.0);
    let up = blocker_scene(1.0);
    assert_eq!(down.triangles[2].normal, Vec3::NEG_Y);
    assert_eq!(up.triangles[2].normal, Vec3::Y);
    // Facing the floor, the blocker has the light behind it: kept. The light faces down too,
    // and lies in its own plane: culled. Facing up, the blocker has the light in front: culled.
    assert_eq!(shadow_casters(&down).len(), 2);
    assert_eq!(shadow_casters(&down)[0].normal, Vec3::NEG_Y);
    assert_eq!(shadow_casters(&up).len(), 0);
    // A floor point under the blocker, towards the light's centre: blocked by the face that
    // faces it, not by its back.
    let from = Vec3::new(0.1, 0.0, 0.2);
    let to = Vec3::new(0.0, 2.0, 0.0);
    let (ray, tmax) = segment(&down, from, to);
    assert!(Accel::new(&down).occluded(&down, &ray, tmax, false));
    assert!(!Accel::new(&up).occluded(&up, &ray, tmax, false));
    // Two-sided, both block.
    assert!(Accel::new(&up).occluded(&up, &ray, tmax, true));
}

/// The renderers' shadow ray from `from` to `to` on the scene's first light (`spawn`): it
/// ends off the light's plane, on `from`'s side. (`from` is no surface point here: the normal
/// is taken along the ray, with no offset at the start.)
fn segment(scene: &Scene, from: Vec3, to: Vec3) -> (Ray, f32) {
    let light = &scene.lights[0];
    let start = SurfaceHit {
        point: from,
        normal: (to - from).normalize(),
        offset: 0.0,
    };
    let end_offset = light_offset(light);
    let end = light_end(light, end_offset, &start);
    let s = shadow_ray(&start, to, &end).expect("a segment to the light");
    (s.ray, s.tmax)
}

/// Random triangles in a cube of half-size 2, a random parallelogram light and a sphere.
fn random_scene(rng: &mut TestRng, triangles: usize) -> Scene {
    let mut text =
        String::from("material\ndiffuse 1 1 1\nemitted 1 1 1\nmaterial\ndiffuse 1 1 1\n");
    let light = rng.point(2.0);
    let (eu, ev) = (rng.point(0.7), rng.point(0.7));
    for p in [light, light + eu, light + eu + ev, light + ev] {
        writeln!(text, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    text.push_str("m 0\nf 1 2 3 4\nm 1\n");
    for k in 0..triangles {
        let a = rng.point(2.0);
        let (b, c) = (a + rng.point(1.0), a + rng.point(1.0));
        for p in [a, b, c] {
            writeln!(text, "v {} {} {}", p.x, p.y, p.z).unwrap();
        }
        let i = 5 + 3 * k;
        writeln!(text, "f {} {} {}", i, i + 1, i + 2).unwrap();
    }
    let c = rng.point(1.5);
    writeln!(text, "s {} {} {} 0.3", c.x, c.y, c.z).unwrap();
    parse_scene_str(&text, "random.obj").unwrap()
}

#[test]
fn culling_changes_only_rounding_hits_on_the_light_points_plane() {
    let mut rng = seeded(0x5eed_2026);
    let (mut rays, mut blocked, mut culled, mut total, mut grazing) = (0, 0, 0, 0, 0);
    for _ in 0..200 {
        let scene = random_scene(&mut rng, 24);
        // Every triangle is tested by the reference's brute force below 64 triangles.
        let accel = Accel::new(&scene);
        assert!(!accel.uses_bvh());
        total += scene.triangles.len();
        culled += scene.triangles.len() - shadow_casters(&scene).len();
        let light = &scene.lights[0];
        for _ in 0..500 {
            let from = rng.point(2.5);
            let to = light.point(rng.unit(), rng.unit());
            let (ray, tmax) = segment(&scene, from, to);
            let dist = tmax;
            let expected = blocked_unculled(&scene, &ray, tmax);
            let culled_blocked = accel.occluded(&scene, &ray, tmax, false);
            if culled_blocked != expected {
                // Culling only removes faces, so it can only unblock a ray, and only where the
                // brute force's hit is rounding: within 1e-5 of the light point, measured along
                // the face's normal. (Rays end before the light's moved plane, so none is seen
                // now; rays that ended at p were, 34 in 100,000.)
                assert!(expected && !culled_blocked);
                let rounding_only = scene.triangles.iter().all(|t| {
                    let th = intersect_triangle(t, &ray, tmax, false);
                    th >= tmax || (dist - th) * t.normal.dot(ray.direction).abs() < 1e-5
                });
                assert!(rounding_only, "from {from} to {to}");
                grazing += 1;
            }
            rays += 1;
            blocked += expected as u32;
        }
    }
    // Not vacuous: a good share of triangles were culled and of rays blocked.
    assert!(culled * 5 > total, "culled {culled} of {total} triangles");
    assert!(blocked * 20 > rays, "blocked {blocked} of {rays} rays");
    // And the rounding cases are rare: about one ray in ten thousand.
    assert!(
        grazing * 1000 < rays,
        "{grazing} of {rays} rays differ by rounding"
    );
    eprintln!(
        "{culled} of {total} triangles culled; {rays} rays, {blocked} blocked, {grazing} unblocked by culling (rounding)"
    );
}

/// A face near the light keeps its shadow in a scene with far-away geometry: the tolerance is
/// the face's and light corner's own, not the scene's size. (With a tolerance of 1e-6 of the
/// largest coordinate, a ±1e6 floor widened it to 1 unit and culled the four sides of this
/// box, whose light corners lie 0.3–0.9 behind their planes: the box's shadow was cut off at
/// its footprint.)
#[test]
fn far_geometry_does_not_cull_a_box_beside_the_light() {
    // Light at y = 3 facing down; a one-sided closed box with x, z in [−0.6, 0.6] and y in
    // [1, 2.5] (faces outwards); a huge floor at y = 0 facing up.
    let text = "material\ndiffuse 1 1 1\nemitted 1 1 1\nmaterial\ndiffuse 1 1 1\n\
        v -0.3 3 -0.3\nv 0.3 3 -0.3\nv 0.3 3 0.3\nv -0.3 3 0.3\n\
        v -1e6 0 -1e6\nv 1e6 0 -1e6\nv 1e6 0 1e6\nv -1e6 0 1e6\n\
        v -0.6 1 -0.6\nv 0.6 1 -0.6\nv 0.6 1 0.6\nv -0.6 1 0.6\n\
        v -0.6 2.5 -0.6\nv 0.6 2.5 -0.6\nv 0.6 2.5 0.6\nv -0.6 2.5 0.6\n\
        m 0\nf 1 2 3 4\nm 1\nf 8 7 6 5\n\
        f 9 10 11 12\nf 16 15 14 13\n\
        f 9 13 14 10\nf 10 14 15 11\nf 11 15 16 12\nf 12 16 13 9\n";
    let scene = parse_scene_str(text, "far.obj").unwrap();
    assert_eq!(
        scene.triangles[0].normal,
        Vec3::NEG_Y,
        "the light faces down"
    );
    assert_eq!(scene.triangles[2].normal, Vec3::Y, "the floor faces up");
    assert_eq!(
        scene.triangles[6].normal,
        Vec3::Y,
        "the box's top faces out"
    );
    assert_eq!(
        scene.triangles[8].normal,
        Vec3::NEG_Z,
        "the box's sides face out"
    );
    // Kept: the bottom (light behind it) and the four sides (every light corner behind each
    // side's plane, 0.3–0.9 away); culled: the light, the floor and the box's top.
    let casters = shadow_casters(&scene);
    assert_eq!(casters.len(), 10, "{casters:#?}");
    // A floor point beside the box, in its shadow: the rays go in through a side face (the
    // ones that used to be culled) and out through the top.
    let accel = Accel::new(&scene);
    let from = Vec3::new(1.0, 0.0, 0.0);
    let light = &scene.lights[0];
    let mut blocked = 0;
    for (u, v) in [(0.1, 0.5), (0.5, 0.5), (0.9, 0.5), (0.5, 0.1), (0.5, 0.9)] {
        let to = light.point(u, v);
        let (ray, tmax) = segment(&scene, from, to);
        let expected = blocked_unculled(&scene, &ray, tmax);
        assert_eq!(accel.occluded(&scene, &ray, tmax, false), expected);
        blocked += expected as u32;
    }
    assert!(
        blocked >= 3,
        "the box should shadow this floor point ({blocked} of 5 blocked)"
    );
}
