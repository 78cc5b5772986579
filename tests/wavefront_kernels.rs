//! SIMD == scalar twin, lane by lane and bit for bit: the 8-wide kernels of the wavefront engine
//! against the scalar kernels of `geometry`, `sampling` and `shading`, on an edge-case table
//! (NaN, infinities, −0.0, grazing and axis-aligned rays, rays starting on a surface, empty
//! scene, one primitive), on random input, and for batch lengths around the lane width.
// `!(x > 0.0)` is on purpose: it is true for NaN, like the kernels' tests.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod common;

use common::strategies::{any_f32, vec3};
use common::{edge_rays, ray, scene_of, triangle};
use glam::Vec3;
use proptest::prelude::*;
use raywave::geometry::{self, Accel, Ray, intersect_sphere, intersect_triangle, shadow_casters};
use raywave::sampling::{LightSampler, SampleKey, square_sample, strata_grid, uniform};
use raywave::scene::{Light, LightShape, Material, NO_HIT, Scene, Sphere};
use raywave::shading::shade;
use raywave::spawn::{SurfaceHit, light_end, shadow_ray};
use raywave::wavefront::shade::{HitLight, MaterialTerms, ShadowLanes, shade_terms, shade8};
use raywave::wavefront::shadow::key_prefix;
use raywave::wavefront::simd::{self, BlockSampler, LightBlock, RayColumns, arrays};

const NAN: f32 = f32::NAN;
const INF: f32 = f32::INFINITY;
/// Random coordinates lie in [−HALF, HALF): around the unit triangle and sphere.
const HALF: f32 = 2.0;

fn tmaxes() -> [f32; 6] {
    [INF, 1.0, 0.5, 0.0, -1.0, NAN]
}

/// Runs the 8-wide kernel on every run of 8 of `rays` (wrapping around) and each `tmax`.
fn check_lanes(
    rays: &[Ray],
    simd: impl Fn(&[Ray; 8], [f32; 8]) -> [f32; 8],
    scalar: impl Fn(&Ray, f32) -> f32,
) {
    for &tmax in &tmaxes() {
        for start in 0..rays.len() {
            let batch: [Ray; 8] = std::array::from_fn(|k| rays[(start + k) % rays.len()]);
            // Vary tmax across lanes too.
            let tm: [f32; 8] = std::array::from_fn(|k| if k % 3 == 0 { tmax } else { INF });
            let got = simd(&batch, tm);
            for k in 0..8 {
                let want = scalar(&batch[k], tm[k]);
                assert_eq!(
                    got[k].to_bits(),
                    want.to_bits(),
                    "lane {k}: {:?} tmax {}: simd {} scalar {want}",
                    batch[k],
                    tm[k],
                    got[k]
                );
            }
        }
    }
}

#[test]
fn triangle_kernel_equals_scalar_on_edge_cases() {
    let tris = [
        triangle(Vec3::ZERO, Vec3::X, Vec3::Y),
        triangle(Vec3::ZERO, Vec3::Y, Vec3::X), // facing −z
        triangle(Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)), // degenerate
    ];
    for tri in &tris {
        for two_sided in [false, true] {
            check_lanes(
                &edge_rays(),
                |r, tm| arrays::triangle(tri, r, tm, two_sided),
                |r, tm| intersect_triangle(tri, r, tm, two_sided),
            );
        }
    }
}

#[test]
fn sphere_kernel_equals_scalar_on_edge_cases() {
    for radius in [1.0, 1e-3, 1e20] {
        let sphere = Sphere {
            center: Vec3::ZERO,
            radius,
            material: 0,
        };
        check_lanes(
            &edge_rays(),
            |r, tm| arrays::sphere(&sphere, r, tm),
            |r, tm| intersect_sphere(&sphere, r, tm),
        );
    }
}

struct Columns {
    ox: Vec<f32>,
    oy: Vec<f32>,
    oz: Vec<f32>,
    dx: Vec<f32>,
    dy: Vec<f32>,
    dz: Vec<f32>,
    tmax: Vec<f32>,
}

impl Columns {
    fn new(rays: &[(Ray, f32)]) -> Columns {
        let col = |f: &dyn Fn(&(Ray, f32)) -> f32| rays.iter().map(f).collect::<Vec<f32>>();
        Columns {
            ox: col(&|r| r.0.origin.x),
            oy: col(&|r| r.0.origin.y),
            oz: col(&|r| r.0.origin.z),
            dx: col(&|r| r.0.direction.x),
            dy: col(&|r| r.0.direction.y),
            dz: col(&|r| r.0.direction.z),
            tmax: col(&|r| r.1),
        }
    }
    fn view(&self) -> RayColumns<'_> {
        RayColumns {
            origin: [&self.ox, &self.oy, &self.oz],
            direction: [&self.dx, &self.dy, &self.dz],
            tmax: &self.tmax,
        }
    }
}

/// `closest_hits` and `occluded` over a whole batch against `Accel` without a BVH.
fn check_batch(scene: &Scene, rays: &[(Ray, f32)], two_sided: bool) {
    assert!(scene.triangles.len() < raywave::geometry::BVH_MIN_TRIANGLES);
    let accel = Accel::new(scene);
    let cols = Columns::new(rays);
    let n = rays.len();
    let (mut t, mut prim) = (vec![0.0; n], vec![0; n]);
    let (mut blocked, mut blocked_by_casters) = (vec![false; n], vec![false; n]);
    simd::closest_hits(
        &scene.triangles,
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut t,
        &mut prim,
    );
    simd::occluded(
        &scene.triangles,
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut blocked,
    );
    // What the engines run: only the triangles that can shadow a light (all when two-sided).
    let casters = shadow_casters(scene);
    simd::occluded(
        geometry::casters(scene, &casters, two_sided),
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut blocked_by_casters,
    );
    for (i, (r, tmax)) in rays.iter().enumerate() {
        let want = accel.closest(scene, r, *tmax, two_sided);
        assert_eq!(
            (t[i].to_bits(), prim[i]),
            (want.t.to_bits(), want.prim),
            "ray {i}: {r:?}"
        );
        let every_primitive = scene
            .spheres
            .iter()
            .any(|s| intersect_sphere(s, r, *tmax) < *tmax)
            || scene
                .triangles
                .iter()
                .any(|tri| intersect_triangle(tri, r, *tmax, two_sided) < *tmax);
        assert_eq!(blocked[i], every_primitive, "ray {i}: {r:?} tmax {tmax}");
        assert_eq!(
            blocked_by_casters[i],
            accel.occluded(scene, r, *tmax, two_sided),
            "ray {i}: {r:?} tmax {tmax}"
        );
    }
}

fn lab_box() -> Scene {
    raywave::scene::Scene::builtin_default()
}

/// Deterministic rays through the lab box, some with finite tmax.
fn box_rays(n: usize) -> Vec<(Ray, f32)> {
    (0..n)
        .map(|i| {
            let key = SampleKey {
                pixel: i as u32,
                sample: 0,
                bounce: 0,
                light: 0,
                seed: 11,
            };
            let u = |d| uniform(&key, d) * 2.0 - 1.0;
            let o = Vec3::new(u(0) * 0.9, u(1) * 0.9, u(2) * 0.9);
            let d = Vec3::new(u(3), u(4), u(5)).normalize();
            let tmax = if i % 2 == 0 { INF } else { 0.5 + u(6).abs() };
            (
                Ray {
                    origin: o,
                    direction: d,
                },
                tmax,
            )
        })
        .collect()
}

/// Like `box_rays`, but rays come in runs of 8 from one origin, as soft-shadow rays do (the
/// occlusion kernel then computes the origin terms once); `offset` misaligns the runs with the
/// 8-lane chunks.
fn shared_origin_rays(n: usize, offset: usize) -> Vec<(Ray, f32)> {
    let mut rays = box_rays(n + offset);
    for i in 0..rays.len() {
        let leader = i / 8 * 8;
        rays[i].0.origin = rays[leader].0.origin;
    }
    rays.drain(..offset);
    rays
}

#[test]
fn batch_kernels_handle_lengths_around_the_lane_width() {
    let scene = lab_box();
    for n in [0, 1, 7, 8, 9, 8 * 5 + 1, 8 * 64 + 1] {
        for two_sided in [false, true] {
            check_batch(&scene, &box_rays(n), two_sided);
            check_batch(&scene, &shared_origin_rays(n, 0), two_sided);
            check_batch(&scene, &shared_origin_rays(n, 3), two_sided);
        }
    }
}

#[test]
fn batch_kernels_on_empty_and_one_primitive_scenes() {
    let rays: Vec<(Ray, f32)> = edge_rays()
        .into_iter()
        .flat_map(|r| tmaxes().map(|t| (r, t)))
        .collect();
    let tri = triangle(Vec3::ZERO, Vec3::X, Vec3::Y);
    let sphere = Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
        material: 0,
    };
    for scene in [
        scene_of(vec![], vec![]),
        scene_of(vec![tri], vec![]),
        scene_of(vec![], vec![sphere]),
        scene_of(vec![tri], vec![sphere]),
    ] {
        check_batch(&scene, &rays, false);
        check_batch(&scene, &rays, true);
    }
    // Ties: two identical triangles; the first one wins, as in the reference.
    let twin = scene_of(vec![tri, tri], vec![]);
    check_batch(&twin, &rays, false);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn kernels_equal_scalar_on_random_input(
        v in [vec3(HALF), vec3(HALF), vec3(HALF)],
        center in vec3(HALF),
        radius in 0.01f32..2.0,
        origins in proptest::collection::vec([any_f32(HALF), any_f32(HALF), any_f32(HALF)], 8),
        dirs in proptest::collection::vec(vec3(HALF), 8),
        tmax in proptest::collection::vec(prop_oneof![Just(INF), 0.0f32..4.0], 8),
        two_sided in any::<bool>(),
    ) {
        let tri = triangle(v[0], v[1], v[2]);
        let sphere = Sphere { center, radius, material: 0 };
        let rays: [Ray; 8] = std::array::from_fn(|k| Ray {
            origin: Vec3::from_array(origins[k]),
            direction: dirs[k].normalize_or_zero(),
        });
        let tm: [f32; 8] = std::array::from_fn(|k| tmax[k]);
        let got_t = arrays::triangle(&tri, &rays, tm, two_sided);
        let got_s = arrays::sphere(&sphere, &rays, tm);
        for k in 0..8 {
            prop_assert_eq!(got_t[k].to_bits(), intersect_triangle(&tri, &rays[k], tm[k], two_sided).to_bits());
            prop_assert_eq!(got_s[k].to_bits(), intersect_sphere(&sphere, &rays[k], tm[k]).to_bits());
        }
    }

    #[test]
    fn batches_equal_scalar_on_random_scenes(
        tris in proptest::collection::vec([vec3(HALF), vec3(HALF), vec3(HALF)], 0..6),
        spheres in proptest::collection::vec((vec3(HALF), 0.05f32..0.8), 0..4),
        n in 0usize..40,
        seed in any::<u32>(),
    ) {
        let scene = scene_of(
            tris.iter().map(|v| triangle(v[0], v[1], v[2])).collect(),
            spheres.iter().map(|&(center, radius)| Sphere { center, radius, material: 0 }).collect(),
        );
        let rays: Vec<(Ray, f32)> = box_rays(n + 8).into_iter().skip(8).map(|(r, t)| {
            (Ray { origin: r.origin * 2.0 + Vec3::splat(seed as f32 * 1e-10), ..r }, t)
        }).collect();
        check_batch(&scene, &rays, seed % 2 == 0);
        check_batch(&scene, &shared_origin_rays(n, seed as usize % 8), seed % 3 == 0);
    }

    #[test]
    fn shade_terms_equals_shade(
        kd in vec3(HALF), kr in prop_oneof![Just(Vec3::ZERO), vec3(HALF)], ke in vec3(HALF),
        g in prop_oneof![Just(0.0f32), Just(1.0f32), 0.0f32..1.0, -0.5f32..0.0],
        n in vec3(HALF), e in vec3(HALF), l in vec3(HALF), lc in vec3(HALF),
    ) {
        let m = Material { diffuse: kd.abs(), reflective: kr.abs(), emitted: ke.abs(), glossiness: g };
        let terms = MaterialTerms::new(&m, Vec3::splat(raywave::shading::AMBIENT));
        let (n, e, l) = (n.normalize_or(Vec3::Z), e.normalize_or(Vec3::Z), l.normalize_or(Vec3::Z));
        let ndl = n.dot(l);
        prop_assume!(ndl > 0.0);
        let want = shade(&m, n, e, l, ndl, lc.abs());
        let got = shade_terms(&terms, n, e, l, ndl, lc.abs());
        prop_assert_eq!(got.to_array().map(f32::to_bits), want.to_array().map(f32::to_bits),
            "{:?} vs {:?}", got, want);
    }

    #[test]
    fn shade8_equals_shade_terms_lane_by_lane(
        kd in vec3(HALF), kr in prop_oneof![Just(Vec3::ZERO), vec3(HALF)], ke in vec3(HALF),
        g in prop_oneof![Just(0.0f32), Just(1.0f32), 0.0f32..1.0, -0.5f32..0.0],
        n in vec3(HALF), e in vec3(HALF), ls in proptest::collection::vec(vec3(HALF), 8), lc in vec3(HALF),
        weight in prop_oneof![Just(1.0f32), Just(1.0 / 64.0), 0.001f32..1.0],
        blocked_bits in prop_oneof![Just(0u32), any::<u32>()],
        dead_bits in prop_oneof![Just(0u32), any::<u32>()],
        falloffs in prop_oneof![Just(vec![1.0f32; 8]), proptest::collection::vec(0.001f32..100.0, 8)],
    ) {
        let m = Material { diffuse: kd.abs(), reflective: kr.abs(), emitted: ke.abs(), glossiness: g };
        let terms = MaterialTerms::new(&m, Vec3::splat(raywave::shading::AMBIENT));
        let (n, e) = (n.normalize_or(Vec3::Z), e.normalize_or(Vec3::Z));
        let ls: Vec<Vec3> = ls.iter().map(|l| l.normalize_or(Vec3::Z)).collect();
        let col = |f: fn(Vec3) -> f32| ls.iter().map(|&l| f(l)).collect::<Vec<f32>>();
        let (lx, ly, lz) = (col(|l| l.x), col(|l| l.y), col(|l| l.z));
        let ndl: Vec<f32> = ls.iter().map(|&l| n.dot(l)).collect();
        let blocked: Vec<bool> = (0..8).map(|k| blocked_bits & (1 << k) != 0).collect();
        let falloff: [f32; 8] = std::array::from_fn(|k| falloffs[k]);
        let lab = falloffs.iter().all(|&f| f == 1.0);
        // Dead lanes carry n·l = 0.
        let ndl: Vec<f32> = (0..8).map(|k| if dead_bits & (1 << k) != 0 { 0.0 } else { ndl[k] }).collect();
        let got = shade8(
            &HitLight { material: &terms, normal: n, to_eye: e, light_color: lc.abs(), weight },
            &ShadowLanes { l: [&lx, &ly, &lz], n_dot_l: &ndl, blocked: &blocked,
                falloff: (!lab).then_some(&falloff) });
        for k in 0..8 {
            if !(ndl[k] > 0.0) || blocked[k] {
                // Adds nothing: exactly −0.0, the identity of addition.
                prop_assert_eq!([got[0][k], got[1][k], got[2][k]].map(f32::to_bits),
                    [(-0.0f32).to_bits(); 3]);
                continue;
            }
            let want = shade_terms(&terms, n, e, ls[k], ndl[k], lc.abs() * falloff[k]) * weight;
            prop_assert_eq!([got[0][k], got[1][k], got[2][k]].map(f32::to_bits),
                want.to_array().map(f32::to_bits), "lane {}", k);
        }
    }

    #[test]
    fn simd_light_points_equal_scalar_sampling(
        pixel in any::<u32>(), sample in 0u32..4, bounce in 0u32..6, light in 0u32..3, seed in any::<u32>(),
        count in 1u32..80, which in 0usize..4,
        origin in vec3(HALF), edge_u in vec3(HALF), edge_v in vec3(HALF), point in vec3(HALF), n in vec3(HALF),
        offset in prop_oneof![Just(0.0f32), 0.0f32..0.01],
        end_offset in prop_oneof![Just(0.0f32), 0.0f32..0.01],
    ) {
        let key = SampleKey { pixel, sample, bounce, light, seed };
        // The prefix trick: hash(key, dim) = mix32(prefix ^ dim).
        for dim in [0, 1, 2 * count - 1, 2 * count] {
            let h = raywave::sampling::mix32(key_prefix(&key) ^ dim);
            prop_assert_eq!((h >> 8) as f32 * (1.0 / 16_777_216.0), uniform(&key, dim));
        }
        // Every sampler with an 8-wide twin (the lab's strategy only for N > 1).
        let sampler = [LightSampler::Random, LightSampler::Stratified, LightSampler::Sobol, LightSampler::Lab][which];
        let count = if sampler == LightSampler::Lab { count.max(2) } else { count };
        let (nx, ny) = strata_grid(count);
        let padded = count.div_ceil(8) * 8;
        let cell_x: Vec<f32> = (0..padded).map(|j| (j % nx) as f32).collect();
        let cell_y: Vec<f32> = (0..padded).map(|j| (j / nx) as f32).collect();
        let lamp = Light {
            face: 0,
            shape: LightShape::Parallelogram { origin, edge_u, edge_v },
            centroid: origin,
            area: 1.0,
            normal: Vec3::Z,
            color: Vec3::ONE,
        };
        let n = n.normalize_or(Vec3::Z);
        for j0 in (0..count).step_by(8) {
            let block = LightBlock {
                prefix: key_prefix(&key),
                j0,
                sampler: match sampler {
                    LightSampler::Stratified => BlockSampler::Stratified {
                        cell_x: &cell_x, cell_y: &cell_y, nx: nx as f32, ny: ny as f32,
                    },
                    LightSampler::Sobol => BlockSampler::Sobol {
                        scramble: raywave::sampling::hash(&key, raywave::sampling::SOBOL_SEED_DIM),
                    },
                    LightSampler::Random | LightSampler::Lab => BlockSampler::Random,
                },
                origin, edge_u, edge_v,
            };
            let pts = simd::light_points8(&block);
            let lanes = ((count - j0) as usize).min(8);
            let hit = SurfaceHit { point, normal: n, offset };
            let end = light_end(&lamp, end_offset, &hit);
            let block = simd::shadow_rays8(&hit, &pts, &end, lanes);
            let (l, live) = (block.l, block.live);
            for k in 0..lanes {
                let (u, v) = square_sample(sampler, &key, j0 + k as u32, count);
                let target = lamp.point(u, v);
                prop_assert_eq!([pts[0][k], pts[1][k], pts[2][k]].map(f32::to_bits),
                    target.to_array().map(f32::to_bits));
                let want = shadow_ray(&hit, target, &end);
                prop_assert_eq!(live & (1 << k) != 0, want.is_some());
                if let Some(want) = want {
                    prop_assert_eq!(block.origin.to_array().map(f32::to_bits),
                        want.ray.origin.to_array().map(f32::to_bits));
                    prop_assert_eq!([l[0][k], l[1][k], l[2][k]].map(f32::to_bits),
                        want.ray.direction.to_array().map(f32::to_bits));
                    prop_assert_eq!(block.tmax[k].to_bits(), want.tmax.to_bits());
                    prop_assert_eq!(block.n_dot_l[k].to_bits(), want.n_dot_l.to_bits());
                    prop_assert_eq!(block.dist[k].to_bits(), want.dist.to_bits());
                } else {
                    prop_assert_eq!((block.tmax[k], block.n_dot_l[k]), (0.0, 0.0));
                }
            }
            for k in lanes..8 {
                prop_assert_eq!(live & (1 << k), 0, "lane past the last point is live");
            }
        }
    }
}

#[test]
fn miss_sentinels_are_the_scalar_ones() {
    let scene = scene_of(vec![], vec![]);
    let cols = Columns::new(&[(ray([0.0; 3], [0.0, 0.0, 1.0]), INF)]);
    let (mut t, mut prim) = (vec![0.0], vec![0]);
    simd::closest_hits(
        &scene.triangles,
        &scene.spheres,
        &cols.view(),
        false,
        &mut t,
        &mut prim,
    );
    assert_eq!((t[0], prim[0]), (INF, NO_HIT));
}

/// The 8-wide Sobol points over the whole index range N allows (the proptest covers N < 80).
#[test]
fn simd_sobol_points_equal_scalar_up_to_the_largest_index() {
    let (origin, edge_u, edge_v) = (Vec3::new(-1.0, 2.0, 0.5), Vec3::X * 2.0, Vec3::Z * 0.5);
    let lamp = Light {
        face: 0,
        shape: LightShape::Parallelogram {
            origin,
            edge_u,
            edge_v,
        },
        centroid: origin,
        area: 1.0,
        normal: Vec3::Y,
        color: Vec3::ONE,
    };
    let count = 1 << 16;
    for seed in [0, 7, u32::MAX] {
        let key = SampleKey {
            pixel: 12_345,
            sample: 1,
            bounce: 2,
            light: 0,
            seed,
        };
        let scramble = raywave::sampling::hash(&key, raywave::sampling::SOBOL_SEED_DIM);
        for j0 in (0..count).step_by(8 * 61).chain([count - 8]) {
            let pts = simd::light_points8(&LightBlock {
                prefix: key_prefix(&key),
                j0,
                sampler: BlockSampler::Sobol { scramble },
                origin,
                edge_u,
                edge_v,
            });
            for (k, ((x, y), z)) in pts[0].iter().zip(&pts[1]).zip(&pts[2]).enumerate() {
                let (u, v) = square_sample(LightSampler::Sobol, &key, j0 + k as u32, count);
                let want = lamp.point(u, v);
                assert_eq!(
                    [*x, *y, *z].map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "seed {seed}, sample {}",
                    j0 + k as u32
                );
            }
        }
    }
}
