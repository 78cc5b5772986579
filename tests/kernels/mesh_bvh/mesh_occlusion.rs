//! Shadow rays through the mesh BVH (`MeshBvh::occluded`, the shadow stage's entry point) get
//! brute force's blocked or unblocked answer on the rays where an any-hit traversal could go
//! wrong: soft-shadow fans from one point, hard-shadow rays from neighbouring points to one,
//! grazing rays, rays through shared edges and vertices, blockers at the very end of the
//! segment, rays that part at the first node, and dead lanes.

use crate::common::{Draw, seeded};
use glam::Vec3;
use raywave::render::geometry::{Ray, T_MIN, intersect_triangle};
use raywave::render::scene::meshgen::cornell_box_mesh_spheres;
use raywave::render::scene::{Scene, parse_scene_str};
use raywave::render::wavefront::bvh::MeshBvh;
use raywave::render::wavefront::cost::NoCount;
use raywave::render::wavefront::simd::RayColumns;

/// A ray with its tmax.
type Segment = (Ray, f32);

/// True when a triangle blocks the ray in (T_MIN, tmax): every triangle in turn.
fn brute_force(scene: &Scene, r: &Ray, tmax: f32, two_sided: bool) -> bool {
    tmax > T_MIN
        && scene
            .triangles
            .iter()
            .any(|tri| intersect_triangle(tri, r, tmax, two_sided) < tmax)
}

/// The first hit's t of a ray (∞ for none), over every triangle.
fn first_hit(scene: &Scene, r: &Ray, two_sided: bool) -> f32 {
    scene
        .triangles
        .iter()
        .map(|tri| intersect_triangle(tri, r, f32::INFINITY, two_sided))
        .fold(f32::INFINITY, f32::min)
}

/// Every answer of the batch entry point equals brute force's, for one- and two-sided faces;
/// returns how many rays were blocked (so that a caller can check the set is not trivial).
fn check(scene: &Scene, bvh: &MeshBvh, segments: &[Segment], what: &str) -> usize {
    let col = |f: &dyn Fn(&Segment) -> f32| segments.iter().map(f).collect::<Vec<f32>>();
    let c = [
        col(&|s| s.0.origin.x),
        col(&|s| s.0.origin.y),
        col(&|s| s.0.origin.z),
        col(&|s| s.0.direction.x),
        col(&|s| s.0.direction.y),
        col(&|s| s.0.direction.z),
        col(&|s| s.1),
    ];
    let rays = RayColumns {
        origin: [&c[0], &c[1], &c[2]],
        direction: [&c[3], &c[4], &c[5]],
        tmax: &c[6],
    };
    let mut blocked_count = 0;
    for two_sided in [false, true] {
        let n = segments.len();
        let mut got = vec![false; n];
        bvh.occluded(scene, &rays, two_sided, &mut got, &mut NoCount);
        for (i, (r, tmax)) in segments.iter().enumerate() {
            let want = brute_force(scene, r, *tmax, two_sided);
            assert_eq!(
                got[i], want,
                "{what}: ray {i} {r:?} tmax {tmax} two-sided {two_sided}: brute force {want}"
            );
            blocked_count += usize::from(want);
        }
    }
    blocked_count
}

fn mesh_scene(bands: u32) -> Scene {
    parse_scene_str(&cornell_box_mesh_spheres(bands), "meshgen").expect("meshgen parses")
}

/// A point on a triangle, as a hit point: barycentrics (u, v).
fn on(scene: &Scene, k: usize, u: f32, v: f32) -> Vec3 {
    let t = &scene.triangles[k % scene.triangles.len()];
    t.v0 + u * t.e1 + v * t.e2
}

/// The segment from `from` to `to`, ending `short` before it (as a shadow ray ends before its
/// light point).
fn segment(from: Vec3, to: Vec3, short: f32) -> Segment {
    let d = to - from;
    let len = d.length();
    (
        Ray {
            origin: from,
            direction: d / len,
        },
        len - short,
    )
}

#[test]
fn soft_shadow_fans_from_one_point_equal_brute_force() {
    let scene = mesh_scene(10);
    let bvh = MeshBvh::new(&scene);
    let light = &scene.lights[0];
    let mut rng = seeded(5);
    let mut segments = Vec::new();
    for h in 0..300 {
        let from = on(&scene, h * 37, 0.3, 0.3)
            + 1e-4 * scene.triangles[h * 37 % scene.triangles.len()].normal;
        for _ in 0..8 {
            segments.push(segment(from, light.point(rng.unit(), rng.unit()), 1e-4));
        }
    }
    let blocked = check(&scene, &bvh, &segments, "fans");
    assert!(blocked > segments.len() / 10 && blocked < 2 * segments.len() * 9 / 10);
}

#[test]
fn hard_shadow_rays_from_neighbouring_points_equal_brute_force() {
    let scene = mesh_scene(10);
    let bvh = MeshBvh::new(&scene);
    let centroid = scene.lights[0].centroid;
    let camera = raywave::render::camera::CameraRays::new(&scene.camera, 64, 48);
    let mut segments = Vec::new();
    for pixel in 0..64 * 48 {
        let (x, y) = camera.screen(pixel, 0.5, 0.5);
        let r = camera.ray(x, y);
        let t = first_hit(&scene, &r, false);
        if t.is_finite() {
            segments.push(segment(r.origin + 0.9999 * t * r.direction, centroid, 1e-4));
        }
    }
    assert!(segments.len() > 1000);
    check(&scene, &bvh, &segments, "hard");
}

/// Targets exactly on vertices and edges shared by two triangles (the ray passes through the
/// edge on its way), grazing rays along a face, and rays whose segment ends exactly at, just
/// before and just after the first blocker.
#[test]
fn edges_vertices_grazing_rays_and_blockers_at_the_segment_end() {
    let scene = mesh_scene(8);
    let bvh = MeshBvh::new(&scene);
    let mut rng = seeded(17);
    let mut segments = Vec::new();
    let n = scene.triangles.len();
    for h in 0..200 {
        let from = on(&scene, h * 13, 0.2, 0.5);
        let tri = &scene.triangles[(h * 101) % n];
        // Through a vertex, the middle of an edge and a far corner, from one point.
        let targets = [
            tri.v0,
            tri.v0 + tri.e1,
            tri.v0 + tri.e2,
            tri.v0 + 0.5 * tri.e1,
            tri.v0 + 0.5 * (tri.e1 + tri.e2),
            tri.v0 + 0.5 * tri.e2,
            tri.v0 + 2.0 * tri.e1,
            tri.v0 + 2.0 * (tri.e1 + tri.e2),
        ];
        for target in targets {
            let (r, _) = segment(from, target, 0.0);
            segments.push((r, f32::INFINITY));
        }
        // Grazing: along the triangle's plane, from a point just above it.
        for k in 0..8 {
            let along = (tri.e1 * (1.0 - k as f32 / 8.0) + tri.e2 * (k as f32 / 8.0)).normalize();
            let lift = tri.normal * (1e-7 * (k as f32 - 4.0));
            let start = tri.v0 - along * 0.01 + lift;
            segments.push((
                Ray {
                    origin: start,
                    direction: (along + tri.normal * 1e-6 * rng.unit()).normalize(),
                },
                1.0,
            ));
        }
        // Blockers at the segment's end: tmax at the first hit (not blocked, t < tmax fails),
        // one ulp past it (blocked) and one ulp short of it.
        let r = Ray {
            origin: from,
            direction: rng.direction(),
        };
        let t = first_hit(&scene, &r, false);
        if t.is_finite() && t > 4.0 * T_MIN {
            for tmax in [t, t.next_up(), t.next_down(), t.next_up().next_up()] {
                segments.push((r, tmax));
            }
            for tmax in [t, t.next_up(), t.next_down(), 0.5 * t] {
                segments.push((r, tmax));
            }
        }
    }
    let blocked = check(&scene, &bvh, &segments, "edges");
    assert!(blocked > 0);
}

/// Groups of 8 rays that leave one point in 8 random directions (they part at the root), mixed
/// with dead lanes (tmax 0, NaN, T_MIN), in batches around the lane width.
#[test]
fn rays_that_part_at_once_and_dead_lanes() {
    let scene = mesh_scene(6);
    let bvh = MeshBvh::new(&scene);
    let mut rng = seeded(23);
    let mut segments: Vec<Segment> = Vec::new();
    for h in 0..150 {
        let from = on(&scene, h * 7, 0.25, 0.25);
        for k in 0..8 {
            let tmax = match (h + k) % 11 {
                0 => 0.0,
                1 => f32::NAN,
                2 => T_MIN,
                _ => 3.0 * rng.unit(),
            };
            segments.push((
                Ray {
                    origin: from,
                    direction: rng.direction(),
                },
                tmax,
            ));
        }
    }
    for n in [0, 1, 3, 4, 7, 8, 9, 17, segments.len()] {
        check(&scene, &bvh, &segments[..n], "parting");
    }
}
