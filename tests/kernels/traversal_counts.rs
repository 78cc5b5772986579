//! The traversal counters (`wavefront::cost`) against counts worked out by hand: a mesh BVH of
//! one node over two leaves (two clusters of 8 triangles, 10 apart along x and 5 along z), one
//! ray at a time, in packets and for occlusion; brute-force blocks of 8 rays; and a counted
//! render, whose image and ray counts are the uncounted render's.

use crate::common;

use common::{scene_of, triangle};
use glam::Vec3;
use raywave::render::progress::Progress;
use raywave::render::scene::{NO_HIT, Scene, Sphere, Triangle, parse_scene_str};
use raywave::render::settings::{RenderSettings, ShadowMode};
use raywave::render::wavefront::Wavefront;
use raywave::render::wavefront::bvh::MeshBvh;
use raywave::render::wavefront::cost::{Cost, PerRay};
use raywave::render::wavefront::lanes::f32x8;
use raywave::render::wavefront::simd::{self, RayColumns};

const INF: f32 = f32::INFINITY;

/// Triangle k of a cluster at (x0, z): x in x0 + [0.5k, 0.5k + 0.4], y in [0, 1], facing +z.
/// At y = 0.5 it covers x0 + [0.5k, 0.5k + 0.2]: a ray crossing the plane at x0 + 0.5k + 0.1
/// hits triangle k; at x0 + 0.5k + 0.35 it passes between two.
fn cluster(x0: f32, z: f32) -> Vec<Triangle> {
    (0..8)
        .map(|k| {
            let x = x0 + 0.5 * k as f32;
            triangle(
                Vec3::new(x, 0.0, z),
                Vec3::new(x + 0.4, 0.0, z),
                Vec3::new(x, 1.0, z),
            )
        })
        .collect()
}

/// Two clusters (A at x0 = 0, z = 0: triangles 0-7; B at x0 = 10, z = −5: triangles 8-15) and
/// one sphere far away: the tree is one node whose two children are leaves of 8 triangles, A's
/// and B's.
fn two_leaves() -> (Scene, MeshBvh) {
    let mut tris = cluster(0.0, 0.0);
    tris.extend(cluster(10.0, -5.0));
    let sphere = Sphere {
        center: Vec3::new(100.0, 100.0, 100.0),
        radius: 1.0,
        material: 0,
    };
    let scene = scene_of(tris, vec![sphere]);
    let bvh = MeshBvh::new(&scene);
    assert_eq!(bvh.size(), (1, 2), "one node, two blocks");
    assert_eq!(bvh.depth, 1);
    (scene, bvh)
}

/// Rays straight down from z = 10 at (x, 0.5), as batch columns with `tmax`: they meet A's
/// plane at x and never enter B's box.
fn down(xs: &[f32], tmax: f32) -> [Vec<f32>; 7] {
    let n = xs.len();
    [
        xs.to_vec(),
        vec![0.5; n],
        vec![10.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![-1.0; n],
        vec![tmax; n],
    ]
}

/// Rays along (10, 0, −5) that meet A's plane at (x, 0.5) and B's at (x + 10, 0.5): through
/// both leaves' boxes, A's first.
fn slant(xs: &[f32]) -> [Vec<f32>; 7] {
    let n = xs.len();
    let d = Vec3::new(10.0, 0.0, -5.0).normalize();
    [
        xs.iter().map(|x| x - 20.0).collect(),
        vec![0.5; n],
        vec![10.0; n],
        vec![d.x; n],
        vec![d.y; n],
        vec![d.z; n],
        vec![INF; n],
    ]
}

/// Concatenated columns.
fn join(a: [Vec<f32>; 7], b: [Vec<f32>; 7]) -> [Vec<f32>; 7] {
    let mut out = a;
    for (o, b) in out.iter_mut().zip(b) {
        o.extend(b);
    }
    out
}

fn columns(c: &[Vec<f32>; 7]) -> RayColumns<'_> {
    RayColumns {
        origin: [&c[0], &c[1], &c[2]],
        direction: [&c[3], &c[4], &c[5]],
        tmax: &c[6],
    }
}

fn cost(nodes: u32, leaves: u32, tests: u32) -> Cost {
    Cost {
        nodes,
        leaves,
        tests,
    }
}

/// Through triangle 2 of A (and, slanted, of B after it).
const THROUGH: f32 = 1.1;
/// Between triangles 0 and 1 of A (and, slanted, of B).
const GAP: f32 = 0.35;
/// Between the two clusters' boxes (straight down).
const BESIDE: f32 = 6.0;

#[test]
fn one_ray_at_a_time_counts_the_nodes_leaves_and_tests_of_the_walk() {
    let (scene, bvh) = two_leaves();
    let c = join(down(&[THROUGH, GAP, BESIDE], INF), slant(&[THROUGH, GAP]));
    let (mut t, mut prim) = (vec![0.0; 5], vec![0; 5]);
    let mut costs = vec![Cost::default(); 5];
    bvh.closest_hits(
        &scene,
        &columns(&c),
        false,
        &mut t,
        &mut prim,
        &mut PerRay(&mut costs),
    );
    assert_eq!(prim, [2, NO_HIT, NO_HIT, 2, NO_HIT]);
    // Every ray: the root node and the sphere. Down through A: A's leaf (8 triangles). Beside
    // both: no leaf. Slanted: A's leaf, then B's unless A's hit comes before B's box.
    assert_eq!(
        costs,
        [
            cost(1, 1, 9),
            cost(1, 1, 9),
            cost(1, 0, 1),
            cost(1, 1, 9),
            cost(1, 2, 17)
        ]
    );
}

#[test]
fn packets_count_each_lane_at_the_nodes_and_leaves_it_is_active_in() {
    let (scene, bvh) = two_leaves();
    // Eight lanes through triangles 0-7 of the near cluster: the packet stays whole, every
    // lane visits the root and the near leaf.
    let xs: Vec<f32> = (0..8).map(|k| 0.5 * k as f32 + 0.1).collect();
    let c = down(&xs, INF);
    let (mut t, mut prim) = (vec![0.0; 8], vec![0; 8]);
    let mut costs = vec![Cost::default(); 8];
    bvh.closest_hits_coherent(
        &scene,
        &columns(&c),
        false,
        &mut t,
        &mut prim,
        &mut PerRay(&mut costs),
    );
    assert_eq!(prim, [0, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(costs, vec![cost(1, 1, 9); 8]);
    // Five slanted lanes, two of them between triangles: the packet parts at A's leaf (8
    // triangles, 5 lanes) and each lane finishes alone; the two that miss go on to B's leaf.
    let c = slant(&[0.1, GAP + 0.5, 1.1, GAP + 1.5, 2.1]);
    let mut costs = vec![Cost::default(); 5];
    bvh.closest_hits_coherent(
        &scene,
        &columns(&c),
        false,
        &mut t[..5],
        &mut prim[..5],
        &mut PerRay(&mut costs),
    );
    assert_eq!(&prim[..5], [0, NO_HIT, 2, NO_HIT, 4]);
    assert_eq!(
        costs,
        [
            cost(1, 1, 9),
            cost(1, 2, 17),
            cost(1, 1, 9),
            cost(1, 2, 17),
            cost(1, 1, 9)
        ]
    );
}

#[test]
fn occlusion_counts_the_sphere_first_and_stops_at_the_first_blocking_leaf() {
    let (scene, bvh) = two_leaves();
    // Down through a triangle of A, beside both, short of A (tmax 5: no box entered), and
    // slanted between the triangles of both (each leaf tested, nothing blocks) and through
    // a triangle of each (the first leaf the walk takes blocks, whichever it is).
    let mut c = join(
        down(&[THROUGH, BESIDE, THROUGH], INF),
        slant(&[GAP, THROUGH]),
    );
    c[6][2] = 5.0;
    let mut blocked = vec![false; 5];
    let mut costs = vec![Cost::default(); 5];
    bvh.occluded(
        &scene,
        &columns(&c),
        true,
        &mut blocked,
        &mut PerRay(&mut costs),
    );
    assert_eq!(blocked, [true, false, false, false, true]);
    assert_eq!(
        costs,
        [
            cost(1, 1, 9),
            cost(1, 0, 1),
            cost(1, 0, 1),
            cost(1, 2, 17),
            cost(1, 1, 9)
        ]
    );
    // A ray that is not traced (tmax 0, a dead queue entry) costs nothing.
    let mut c = down(&[THROUGH], 0.0);
    c[6][0] = 0.0;
    let mut costs = vec![Cost::default(); 1];
    bvh.occluded(
        &scene,
        &columns(&c),
        true,
        &mut blocked[..1],
        &mut PerRay(&mut costs),
    );
    assert_eq!(costs, [Cost::default()]);
}

#[test]
fn brute_force_blocks_charge_every_live_lane_what_the_block_tested() {
    // Three triangles: the first covers x < 0.4 only, the other two nothing the rays pass.
    let tris = vec![
        triangle(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.4, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ),
        triangle(
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(5.4, 0.0, 0.0),
            Vec3::new(5.0, 1.0, 0.0),
        ),
        triangle(
            Vec3::new(6.0, 0.0, 0.0),
            Vec3::new(6.4, 0.0, 0.0),
            Vec3::new(6.0, 1.0, 0.0),
        ),
    ];
    // First block: all 8 lanes blocked by the first triangle, so the block stops after one
    // test. Second block: 4 lanes blocked, 3 not, one dead (tmax 0): all three are tested,
    // and the dead lane is not a ray.
    let mut xs = vec![0.1; 8];
    xs.extend([0.1, 0.1, 0.1, 0.1, 3.0, 3.0, 3.0, 3.0]);
    let mut c = down(&xs, INF);
    c[6][15] = 0.0;
    let mut blocked = vec![false; 16];
    let mut costs = vec![Cost::default(); 16];
    simd::occluded::<f32x8, _>(
        &tris,
        &[],
        &columns(&c),
        true,
        &mut blocked,
        &mut PerRay(&mut costs),
    );
    let mut want = vec![cost(0, 0, 1); 8];
    want.extend(vec![cost(0, 0, 3); 7]);
    want.push(Cost::default());
    assert_eq!(costs, want);
    assert_eq!(blocked[8..12], [true; 4]);
}

/// A mesh scene with a light: the generated 12k box at its smallest.
fn mesh_scene() -> Scene {
    let text = raywave::render::scene::meshgen::cornell_box_mesh_spheres(4);
    parse_scene_str(&text, "generated").expect("the generated scene parses")
}

#[test]
fn a_counted_render_is_the_render_with_every_kind_counted() {
    let scene = mesh_scene();
    for shadows in [ShadowMode::Hard, ShadowMode::Soft] {
        let settings = RenderSettings {
            width: 24,
            height: 16,
            bounces: 2,
            shadows,
            shadow_samples: 4,
            ..RenderSettings::default()
        };
        let engine = Wavefront::new(&scene, &settings, 64);
        let (film, stats) = engine.render(&Progress::SILENT);
        let (counted, counted_stats, report) = engine.render_counted(&Progress::SILENT, true);
        assert_eq!(film.pixels, counted.pixels, "{shadows:?}: the same image");
        assert_eq!(stats.counts, counted_stats.counts);
        let pixels = report.pixels.expect("per-pixel counts were asked for");
        assert_eq!(pixels.len(), 24 * 16);
        // The frame's sums are the pixels' sums.
        for (kind, total) in report.totals.iter() {
            let nodes: u64 = pixels.iter().map(|p| p[kind].nodes as u64).sum();
            let tests: u64 = pixels.iter().map(|p| p[kind].tests as u64).sum();
            assert_eq!((total.nodes, total.tests), (nodes, tests), "{kind:?}");
            // Every ray of a mesh scene visits the root at least.
            assert!(total.nodes >= stats.counts[kind], "{kind:?}: {total:?}");
        }
        let (_, _, again) = engine.render_counted(&Progress::SILENT, false);
        assert_eq!(again.totals, report.totals);
        assert!(again.pixels.is_none());
    }
}

#[test]
fn small_scenes_charge_every_camera_ray_every_primitive() {
    let scene = Scene::builtin_default();
    let settings = RenderSettings {
        width: 8,
        height: 8,
        bounces: 0,
        shadows: ShadowMode::Off,
        ..RenderSettings::default()
    };
    let engine = Wavefront::new(&scene, &settings, 16);
    let (_, stats, report) = engine.render_counted(&Progress::SILENT, false);
    let every = (scene.triangles.len() + scene.spheres.len()) as u64;
    assert_eq!(report.totals.camera.tests, stats.counts.camera * every);
    assert_eq!(report.totals.camera.nodes, 0);
    assert_eq!(report.totals.shadow.tests, 0);
}
