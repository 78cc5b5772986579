//! SIMD == scalar twin, lane by lane and bit for bit: the kernels of the wavefront engine, at
//! 8 lanes and (the width-generic ones) at 16, against the scalar kernels of `geometry`,
//! `sampling` and `shading`, on an edge-case table (NaN, infinities, −0.0, grazing and
//! axis-aligned rays, rays starting on a surface, empty scene, one primitive), on random input,
//! and for batch lengths around both lane widths. The 16-lane kernels run as two 256-bit halves
//! on a machine without AVX-512, so these run anywhere.
// `!(x > 0.0)` is on purpose: it is true for NaN, like the kernels' tests.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::common;

use common::strategies::{any_f32, vec3};
use common::{edge_rays, ray, scene_of, triangle};
use glam::Vec3;
use proptest::prelude::*;
use raywave::render::geometry::{
    self, Accel, Ray, intersect_sphere, intersect_triangle, shadow_casters,
};
use raywave::render::sampling::{LightSampler, PointSet, SampleKey, strata_grid, uniform};
use raywave::render::scene::{Light, LightShape, Material, NO_HIT, Scene, Sphere};
use raywave::render::shading::shade;
use raywave::render::spawn::{SurfaceHit, light_end, shadow_ray};
use raywave::render::wavefront::batch::ShadowBlock;
use raywave::render::wavefront::cost::NoCount;
use raywave::render::wavefront::lanes::{Lanes, f32x8, f32x16};
use raywave::render::wavefront::shade::{
    HitLight, MaterialTerms, ShadowLanes, shade_lanes, shade_terms,
};
use raywave::render::wavefront::shadow::key_prefix;
use raywave::render::wavefront::simd::{self, BlockSampler, LightBlock, RayColumns, arrays};

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

/// `check_lanes` at the width of `V` (8 or 16): every run of `V::N` of `rays`, wrapping.
fn check_lanes_n<V: Lanes>(
    rays: &[Ray],
    simd: impl Fn(&[Ray], &[f32]) -> V::Array,
    scalar: impl Fn(&Ray, f32) -> f32,
) {
    for &tmax in &tmaxes() {
        for start in 0..rays.len() {
            let batch: Vec<Ray> = (0..V::N).map(|k| rays[(start + k) % rays.len()]).collect();
            let tm: Vec<f32> = (0..V::N)
                .map(|k| if k % 3 == 0 { tmax } else { INF })
                .collect();
            let got = simd(&batch, &tm);
            for k in 0..V::N {
                let want = scalar(&batch[k], tm[k]);
                assert_eq!(
                    got.as_ref()[k].to_bits(),
                    want.to_bits(),
                    "{} lanes, lane {k}: {:?} tmax {}",
                    V::N,
                    batch[k],
                    tm[k]
                );
            }
        }
    }
}

#[test]
fn sixteen_lane_triangle_and_sphere_kernels_equal_scalar_on_edge_cases() {
    let tris = [
        triangle(Vec3::ZERO, Vec3::X, Vec3::Y),
        triangle(Vec3::ZERO, Vec3::Y, Vec3::X),
        triangle(Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)),
    ];
    for tri in &tris {
        for two_sided in [false, true] {
            check_lanes_n::<f32x16>(
                &edge_rays(),
                |r, tm| arrays::triangle_lanes::<f32x16>(tri, r, tm, two_sided),
                |r, tm| intersect_triangle(tri, r, tm, two_sided),
            );
            // The generic kernel at 8 lanes is the 8-lane one.
            check_lanes_n::<f32x8>(
                &edge_rays(),
                |r, tm| arrays::triangle_lanes::<f32x8>(tri, r, tm, two_sided),
                |r, tm| intersect_triangle(tri, r, tm, two_sided),
            );
        }
    }
    for radius in [1.0, 1e-3, 1e20] {
        let sphere = Sphere {
            center: Vec3::ZERO,
            radius,
            material: 0,
        };
        check_lanes_n::<f32x16>(
            &edge_rays(),
            |r, tm| arrays::sphere_lanes::<f32x16>(&sphere, r, tm),
            |r, tm| intersect_sphere(&sphere, r, tm),
        );
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
                |r, tm| arrays::triangle_lanes::<f32x8>(tri, r, &tm, two_sided),
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
            |r, tm| arrays::sphere_lanes::<f32x8>(&sphere, r, &tm),
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
    assert!(scene.triangles.len() < raywave::render::geometry::BVH_MIN_TRIANGLES);
    let accel = Accel::new(scene);
    let cols = Columns::new(rays);
    let n = rays.len();
    let (mut t, mut prim) = (vec![0.0; n], vec![0; n]);
    let (mut blocked, mut blocked_by_casters) = (vec![false; n], vec![false; n]);
    simd::closest_hits::<f32x8>(
        &scene.triangles,
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut t,
        &mut prim,
    );
    simd::occluded::<f32x8, _>(
        &scene.triangles,
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut blocked,
        &mut NoCount,
    );
    // What the engines run: only the triangles that can shadow a light (all when two-sided).
    let casters = shadow_casters(scene);
    simd::occluded::<f32x8, _>(
        geometry::casters(scene, &casters, two_sided),
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut blocked_by_casters,
        &mut NoCount,
    );
    // The same loops 16 lanes wide give the same answers, entry by entry.
    let (mut t16, mut prim16) = (vec![0.0; n], vec![0; n]);
    let (mut blocked16, mut by_casters16) = (vec![false; n], vec![false; n]);
    simd::closest_hits::<f32x16>(
        &scene.triangles,
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut t16,
        &mut prim16,
    );
    simd::occluded::<f32x16, _>(
        &scene.triangles,
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut blocked16,
        &mut NoCount,
    );
    simd::occluded::<f32x16, _>(
        geometry::casters(scene, &casters, two_sided),
        &scene.spheres,
        &cols.view(),
        two_sided,
        &mut by_casters16,
        &mut NoCount,
    );
    let bits = |t: &[f32]| t.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&t16), bits(&t), "16-lane closest t, {n} rays");
    assert_eq!(prim16, prim, "16-lane closest prim, {n} rays");
    assert_eq!(blocked16, blocked, "16-lane occlusion, {n} rays");
    assert_eq!(
        by_casters16, blocked_by_casters,
        "16-lane casters, {n} rays"
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

/// `block_occluded` (one block of rays from one origin, in registers, as the fused shadow stage
/// tests them) against `occluded` over the same rays in columns: the same answer on every live
/// lane, with all triangles and with the shadow casters, for `n` rays cut into blocks of `V::N`
/// (the last padded with dead lanes: NaN directions, tmax 0).
fn check_blocks<V: Lanes>(scene: &Scene, n: usize, offset: usize, two_sided: bool) {
    let rays = shared_origin_runs(n, offset, V::N);
    // Blocks start where the runs do: from the offset's first whole run.
    let first = (V::N - offset % V::N) % V::N;
    let rays = &rays[first.min(rays.len())..];
    let cols = Columns::new(rays);
    let casters = shadow_casters(scene);
    for triangles in [
        &scene.triangles[..],
        geometry::casters(scene, &casters, two_sided),
    ] {
        let mut want = vec![false; rays.len()];
        simd::occluded::<f32x8, _>(
            triangles,
            &scene.spheres,
            &cols.view(),
            two_sided,
            &mut want,
            &mut NoCount,
        );
        for (b, chunk) in rays.chunks(V::N).enumerate() {
            let mut block = ShadowBlock {
                origin: chunk[0].0.origin,
                l: [V::Array::default(); 3],
                tmax: V::Array::default(),
                n_dot_l: V::Array::default(),
                dist: V::Array::default(),
                live: 0,
            };
            for k in 0..V::N {
                let (d, tmax) = chunk
                    .get(k)
                    .map_or((Vec3::NAN, 0.0), |(r, t)| (r.direction, *t));
                block.l[0].as_mut()[k] = d.x;
                block.l[1].as_mut()[k] = d.y;
                block.l[2].as_mut()[k] = d.z;
                block.tmax.as_mut()[k] = tmax;
                if tmax > 0.0 {
                    block.live |= 1 << k;
                }
            }
            let got = simd::block_occluded::<V, _>(
                triangles,
                &scene.spheres,
                &block,
                two_sided,
                &mut NoCount,
            );
            for (k, (r, tmax)) in chunk.iter().enumerate() {
                if block.live >> k & 1 == 1 {
                    assert_eq!(
                        got >> k & 1 == 1,
                        want[b * V::N + k],
                        "{}-lane block {b}, lane {k}: {r:?} tmax {tmax}",
                        V::N
                    );
                }
            }
        }
    }
}

fn lab_box() -> Scene {
    raywave::render::scene::Scene::builtin_default()
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
    shared_origin_runs(n, offset, 8)
}

/// `shared_origin_rays` with runs of `run` rays from one origin (16: the 16-lane queue's blocks).
fn shared_origin_runs(n: usize, offset: usize, run: usize) -> Vec<(Ray, f32)> {
    let mut rays = box_rays(n + offset);
    for i in 0..rays.len() {
        let leader = i / run * run;
        rays[i].0.origin = rays[leader].0.origin;
    }
    rays.drain(..offset);
    rays
}

#[test]
fn batch_kernels_handle_lengths_around_the_lane_width() {
    let scene = lab_box();
    for n in [0, 1, 7, 8, 9, 15, 16, 17, 31, 33, 8 * 5 + 1, 8 * 64 + 1] {
        for two_sided in [false, true] {
            check_batch(&scene, &box_rays(n), two_sided);
            check_batch(&scene, &shared_origin_rays(n, 0), two_sided);
            check_batch(&scene, &shared_origin_rays(n, 3), two_sided);
            check_batch(&scene, &shared_origin_runs(n, 0, 16), two_sided);
            check_batch(&scene, &shared_origin_runs(n, 5, 16), two_sided);
            check_blocks::<f32x8>(&scene, n, 0, two_sided);
            check_blocks::<f32x16>(&scene, n, 5, two_sided);
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
        let got_t = arrays::triangle_lanes::<f32x8>(&tri, &rays, &tm, two_sided);
        let got_s = arrays::sphere_lanes::<f32x8>(&sphere, &rays, &tm);
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
        check_blocks::<f32x8>(&scene, n, seed as usize % 8, seed % 3 == 0);
        check_blocks::<f32x16>(&scene, n, seed as usize % 16, seed % 5 == 0);
    }

    #[test]
    fn shade_terms_equals_shade(
        kd in vec3(HALF), kr in prop_oneof![Just(Vec3::ZERO), vec3(HALF)], ke in vec3(HALF),
        g in prop_oneof![Just(0.0f32), Just(1.0f32), 0.0f32..1.0, -0.5f32..0.0],
        n in vec3(HALF), e in vec3(HALF), l in vec3(HALF), lc in vec3(HALF),
    ) {
        let m = Material { diffuse: kd.abs(), texture: None, reflective: kr.abs(), emitted: ke.abs(), glossiness: g };
        let terms = MaterialTerms::new(&m, Vec3::splat(raywave::render::shading::AMBIENT));
        let (n, e, l) = (n.normalize_or(Vec3::Z), e.normalize_or(Vec3::Z), l.normalize_or(Vec3::Z));
        let ndl = n.dot(l);
        prop_assume!(ndl > 0.0);
        let want = shade(&m, n, e, l, ndl, lc.abs());
        let got = shade_terms(&terms, n, e, l, ndl, lc.abs());
        prop_assert_eq!(got.to_array().map(f32::to_bits), want.to_array().map(f32::to_bits),
            "{:?} vs {:?}", got, want);
    }

    #[test]
    fn shade_lanes_equal_shade_terms_lane_by_lane(
        kd in vec3(HALF), kr in prop_oneof![Just(Vec3::ZERO), vec3(HALF)], ke in vec3(HALF),
        g in prop_oneof![Just(0.0f32), Just(1.0f32), 0.0f32..1.0, -0.5f32..0.0],
        n in vec3(HALF), e in vec3(HALF), ls in proptest::collection::vec(vec3(HALF), 16), lc in vec3(HALF),
        weight in prop_oneof![Just(1.0f32), Just(1.0 / 64.0), 0.001f32..1.0],
        blocked_bits in prop_oneof![Just(0u32), any::<u32>()],
        dead_bits in prop_oneof![Just(0u32), any::<u32>()],
        falloffs in prop_oneof![Just(vec![1.0f32; 16]), proptest::collection::vec(0.001f32..100.0, 16)],
    ) {
        let m = Material { diffuse: kd.abs(), texture: None, reflective: kr.abs(), emitted: ke.abs(), glossiness: g };
        let case = ShadeCase { m, n, e, ls, lc, weight, blocked_bits, dead_bits, falloffs };
        // One source at 8 and at 16 lanes.
        check_shade(&case, 8, |at, rays| shade_lanes::<f32x8>(at, rays).map(|c| c.to_vec()))?;
        check_shade(&case, 16, |at, rays| shade_lanes::<f32x16>(at, rays).map(|c| c.to_vec()))?;
    }

    #[test]
    fn simd_light_points_equal_scalar_sampling(
        pixel in any::<u32>(), sample in 0u32..4, bounce in 0u32..6, light in 0u32..3, seed in any::<u32>(),
        count in 1u32..80, which in 0usize..8,
        origin in vec3(HALF), edge_u in vec3(HALF), edge_v in vec3(HALF), point in vec3(HALF), n in vec3(HALF),
        offset in prop_oneof![Just(0.0f32), 0.0f32..0.01],
        end_offset in prop_oneof![Just(0.0f32), 0.0f32..0.01],
    ) {
        let key = SampleKey { pixel, sample, bounce, light, seed };
        // The prefix trick: hash(key, dim) = mix32(prefix ^ dim).
        for dim in [0, 1, 2 * count - 1, 2 * count] {
            let h = raywave::render::sampling::mix32(key_prefix(&key) ^ dim);
            prop_assert_eq!((h >> 8) as f32 * (1.0 / 16_777_216.0), uniform(&key, dim));
        }
        // Every sampler (the lab's strategy only for N > 1: at N = 1 it is the scalar path's).
        let sampler = LightSampler::ALL[which];
        let count = if sampler == LightSampler::Lab { count.max(2) } else { count };
        let case = LightCase { key, sampler, count, origin, edge_u, edge_v, point, n: n.normalize_or(Vec3::Z), offset, end_offset };
        check_light_points::<f32x8>(&case, |b| simd::light_points::<f32x8>(b).map(|c| c.to_vec()), |hit, pts, end, lanes| {
            let p: [[f32; 8]; 3] = std::array::from_fn(|a| pts[a].clone().try_into().expect("8 lanes"));
            let b = simd::shadow_rays::<f32x8>(hit, &p, end, lanes);
            BlockOut { origin: b.origin, l: b.l.map(|c| c.to_vec()), tmax: b.tmax.to_vec(), n_dot_l: b.n_dot_l.to_vec(), dist: b.dist.to_vec(), live: b.live }
        })?;
        check_light_points::<f32x16>(&case, |b| simd::light_points::<f32x16>(b).map(|c| c.to_vec()), |hit, pts, end, lanes| {
            let p: [[f32; 16]; 3] = std::array::from_fn(|a| pts[a].clone().try_into().expect("16 lanes"));
            let b = simd::shadow_rays::<f32x16>(hit, &p, end, lanes);
            BlockOut { origin: b.origin, l: b.l.map(|c| c.to_vec()), tmax: b.tmax.to_vec(), n_dot_l: b.n_dot_l.to_vec(), dist: b.dist.to_vec(), live: b.live }
        })?;
    }
}

/// One shading case of the proptest: 16 rays' worth of inputs (8-lane kernels use the first 8).
struct ShadeCase {
    m: Material,
    n: Vec3,
    e: Vec3,
    ls: Vec<Vec3>,
    lc: Vec3,
    weight: f32,
    blocked_bits: u32,
    dead_bits: u32,
    falloffs: Vec<f32>,
}

/// A shading kernel `width` lanes wide against `shade_terms`, lane by lane.
fn check_shade(
    case: &ShadeCase,
    width: usize,
    kernel: impl Fn(&HitLight, &ShadowLanes) -> [Vec<f32>; 3],
) -> Result<(), TestCaseError> {
    let terms = MaterialTerms::new(&case.m, Vec3::splat(raywave::render::shading::AMBIENT));
    let (n, e) = (case.n.normalize_or(Vec3::Z), case.e.normalize_or(Vec3::Z));
    let ls: Vec<Vec3> = case.ls[..width]
        .iter()
        .map(|l| l.normalize_or(Vec3::Z))
        .collect();
    let col = |f: fn(Vec3) -> f32| ls.iter().map(|&l| f(l)).collect::<Vec<f32>>();
    let (lx, ly, lz) = (col(|l| l.x), col(|l| l.y), col(|l| l.z));
    let blocked: Vec<bool> = (0..width)
        .map(|k| case.blocked_bits & (1 << k) != 0)
        .collect();
    let falloff = &case.falloffs[..width];
    let lab = falloff.iter().all(|&f| f == 1.0);
    // Dead lanes carry n·l = 0.
    let ndl: Vec<f32> = (0..width)
        .map(|k| {
            if case.dead_bits & (1 << k) != 0 {
                0.0
            } else {
                n.dot(ls[k])
            }
        })
        .collect();
    let lc = case.lc.abs();
    let got = kernel(
        &HitLight {
            material: &terms,
            normal: n,
            to_eye: e,
            light_color: lc,
            weight: case.weight,
        },
        &ShadowLanes {
            l: [&lx, &ly, &lz],
            n_dot_l: &ndl,
            blocked: &blocked,
            falloff: (!lab).then_some(falloff),
        },
    );
    for k in 0..width {
        let lane = [got[0][k], got[1][k], got[2][k]].map(f32::to_bits);
        if !(ndl[k] > 0.0) || blocked[k] {
            // Adds nothing: exactly −0.0, the identity of addition.
            prop_assert_eq!(
                lane,
                [(-0.0f32).to_bits(); 3],
                "{} lanes, lane {}",
                width,
                k
            );
            continue;
        }
        let want = shade_terms(&terms, n, e, ls[k], ndl[k], lc * falloff[k]) * case.weight;
        prop_assert_eq!(
            lane,
            want.to_array().map(f32::to_bits),
            "{} lanes, lane {}",
            width,
            k
        );
    }
    Ok(())
}

/// One light-sampling case of the proptest.
struct LightCase {
    key: SampleKey,
    sampler: LightSampler,
    count: u32,
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    point: Vec3,
    n: Vec3,
    offset: f32,
    end_offset: f32,
}

/// A shadow block as vectors, whatever its width.
struct BlockOut {
    origin: Vec3,
    l: [Vec<f32>; 3],
    tmax: Vec<f32>,
    n_dot_l: Vec<f32>,
    dist: Vec<f32>,
    live: u32,
}

/// The light-point and shadow-ray kernels at the width of `V` against `PointSet::point`,
/// `Light::point` and `spawn::shadow_ray`, block by block of `V::N` points (on a 640×480
/// image, for the samplers that read the pixel's place).
fn check_light_points<V: Lanes>(
    case: &LightCase,
    points: impl Fn(&LightBlock) -> [Vec<f32>; 3],
    rays: impl Fn(&SurfaceHit, &[Vec<f32>; 3], &raywave::render::spawn::LightEnd, usize) -> BlockOut,
) -> Result<(), TestCaseError> {
    let LightCase {
        key,
        sampler,
        count,
        origin,
        edge_u,
        edge_v,
        point,
        n,
        offset,
        end_offset,
    } = *case;
    let (nx, ny) = strata_grid(count);
    let padded = count.div_ceil(16) * 16;
    let cell_x: Vec<f32> = (0..padded).map(|j| (j % nx) as f32).collect();
    let cell_y: Vec<f32> = (0..padded).map(|j| (j / nx) as f32).collect();
    let lamp = Light {
        face: 0,
        shape: LightShape::Parallelogram {
            origin,
            edge_u,
            edge_v,
        },
        centroid: origin,
        area: 1.0,
        normal: Vec3::Z,
        color: Vec3::ONE,
    };
    let width = V::N as u32;
    let set = PointSet::with(sampler, count, (640, 480), 1);
    for j0 in (0..count).step_by(V::N) {
        let block = LightBlock {
            prefix: key_prefix(&key),
            j0,
            sampler: match sampler {
                LightSampler::Stratified => BlockSampler::Stratified {
                    cell_x: &cell_x,
                    cell_y: &cell_y,
                    nx: nx as f32,
                    ny: ny as f32,
                },
                LightSampler::Sobol => BlockSampler::Sobol {
                    scramble: raywave::render::sampling::hash(
                        &key,
                        raywave::render::sampling::SOBOL_SEED_DIM,
                    ),
                },
                LightSampler::Random | LightSampler::Lab => BlockSampler::Random,
                LightSampler::Halton
                | LightSampler::Pmj02
                | LightSampler::Zsobol
                | LightSampler::Bluenoise => BlockSampler::Stream {
                    stream: set.stream(&key).expect("a table sampler"),
                    count,
                },
            },
            origin,
            edge_u,
            edge_v,
        };
        let pts = points(&block);
        let lanes = (count - j0).min(width) as usize;
        let hit = SurfaceHit {
            point,
            normal: n,
            offset,
        };
        let end = light_end(&lamp, end_offset, &hit);
        let block = rays(&hit, &pts, &end, lanes);
        let (l, live) = (&block.l, block.live);
        for k in 0..lanes {
            let (u, v) = set.point(&key, j0 + k as u32);
            let target = lamp.point(u, v);
            prop_assert_eq!(
                [pts[0][k], pts[1][k], pts[2][k]].map(f32::to_bits),
                target.to_array().map(f32::to_bits),
                "{} lanes, point {}",
                width,
                j0 + k as u32
            );
            let want = shadow_ray(&hit, target, &end);
            prop_assert_eq!(live & (1 << k) != 0, want.is_some());
            if let Some(want) = want {
                prop_assert_eq!(
                    block.origin.to_array().map(f32::to_bits),
                    want.ray.origin.to_array().map(f32::to_bits)
                );
                prop_assert_eq!(
                    [l[0][k], l[1][k], l[2][k]].map(f32::to_bits),
                    want.ray.direction.to_array().map(f32::to_bits)
                );
                prop_assert_eq!(block.tmax[k].to_bits(), want.tmax.to_bits());
                prop_assert_eq!(block.n_dot_l[k].to_bits(), want.n_dot_l.to_bits());
                prop_assert_eq!(block.dist[k].to_bits(), want.dist.to_bits());
            } else {
                prop_assert_eq!((block.tmax[k], block.n_dot_l[k]), (0.0, 0.0));
            }
        }
        for k in lanes..V::N {
            prop_assert_eq!(live & (1 << k), 0, "lane past the last point is live");
        }
    }
    Ok(())
}

#[test]
fn miss_sentinels_are_the_scalar_ones() {
    let scene = scene_of(vec![], vec![]);
    let cols = Columns::new(&[(ray([0.0; 3], [0.0, 0.0, 1.0]), INF)]);
    let (mut t, mut prim) = (vec![0.0], vec![0]);
    simd::closest_hits::<f32x8>(
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
        let scramble =
            raywave::render::sampling::hash(&key, raywave::render::sampling::SOBOL_SEED_DIM);
        for j0 in (0..count).step_by(8 * 61).chain([count - 16, count - 8]) {
            // The 16-lane kernel from the same index gives the same first 8 points and the
            // twins' next 8 (checked below for the 8-lane kernel from j0 + 8).
            let wide = simd::light_points::<f32x16>(&LightBlock {
                prefix: key_prefix(&key),
                j0,
                sampler: BlockSampler::Sobol { scramble },
                origin,
                edge_u,
                edge_v,
            });
            for k in 0..16u32 {
                let Some(j) = j0.checked_add(k).filter(|&j| j < count) else {
                    continue;
                };
                let (u, v) = PointSet::of(LightSampler::Sobol, count).point(&key, j);
                let want = lamp.point(u, v);
                let k = k as usize;
                assert_eq!(
                    [wide[0][k], wide[1][k], wide[2][k]].map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "16 lanes, seed {seed}, sample {j}"
                );
            }
            let pts = simd::light_points::<f32x8>(&LightBlock {
                prefix: key_prefix(&key),
                j0,
                sampler: BlockSampler::Sobol { scramble },
                origin,
                edge_u,
                edge_v,
            });
            for (k, ((x, y), z)) in pts[0].iter().zip(&pts[1]).zip(&pts[2]).enumerate() {
                let (u, v) = PointSet::of(LightSampler::Sobol, count).point(&key, j0 + k as u32);
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
