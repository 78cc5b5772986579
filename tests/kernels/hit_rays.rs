//! `simd::hit_shadow_rays` (one shadow ray per hit, N hits at a time: the hard-shadow spawn)
//! == the scalar spawn both engines call, `spawn::light_end` then `spawn::shadow_ray`, lane by
//! lane and bit for bit, at 8 and 16 lanes: on an edge-case table (hits on the light's plane
//! at ±0, behind it, grazing the tangent plane, at the light point itself, NaN and infinite
//! coordinates, zero offsets) and on random hits at every scale, for groups that end
//! mid-vector. And `simd::hit_rays_occluded` (the blockers of those rays, in registers) ==
//! `simd::occluded` on the same rays in columns; on a mesh, `MeshBvh::hit_rays_occluded` (the
//! hard-shadow stage's walk from registers) == `MeshBvh::occluded` on them in columns, answers
//! and per-ray traversal counts, lanes with a NaN, zero, negative or T_MIN tmax included.

use crate::common;

use common::{Draw, TestRng, seeded};
use glam::Vec3;
use raywave::render::geometry::{self, T_MIN, shadow_casters};
use raywave::render::scene::{Light, Scene};
use raywave::render::spawn::{SurfaceHit, light_end, light_offset, shadow_ray};
use raywave::render::wavefront::batch::{HitBatch, HitRays};
use raywave::render::wavefront::bvh::MeshBvh;
use raywave::render::wavefront::cost::{Cost, NoCount, PerRay};
use raywave::render::wavefront::lanes::{Lanes, f32x8, f32x16};
use raywave::render::wavefront::simd::{
    self, HitLanes, RayColumns, hit_rays_occluded, hit_shadow_rays,
};

const NAN: f32 = f32::NAN;
const INF: f32 = f32::INFINITY;

/// A batch holding `hits`.
fn batch(hits: &[SurfaceHit]) -> HitBatch {
    let mut b = HitBatch::default();
    b.resize(hits.len());
    for (i, h) in hits.iter().enumerate() {
        b.point.set(i, h.point);
        b.normal.set(i, h.normal);
        b.offset[i] = h.offset;
    }
    b
}

/// Every group of `V::N` hits of `hits` (the last one short) against the scalar spawn.
fn check<V: Lanes>(hits: &[SurfaceHit], light: &Light, target: Vec3) {
    let b = batch(hits);
    let end_offset = light_offset(light);
    for i0 in (0..hits.len()).step_by(V::N) {
        let got = hit_shadow_rays(&HitLanes::<V>::load(&b, i0), light, end_offset, target);
        for (k, hit) in hits[i0..].iter().take(V::N).enumerate() {
            let want = shadow_ray(hit, target, &light_end(light, end_offset, hit));
            let live = got.live >> k & 1 == 1;
            let what = format!("{}-lane group at {i0}, lane {k}: {hit:?} to {target}", V::N);
            let Some(want) = want else {
                assert!(!live, "{what}: live where the scalar spawn casts no ray");
                continue;
            };
            assert!(live, "{what}: dead where the scalar spawn casts {want:?}");
            let lane = |c: &V::Array| c.as_ref()[k].to_bits();
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            let origin = [
                lane(&got.origin[0]),
                lane(&got.origin[1]),
                lane(&got.origin[2]),
            ];
            let l = [lane(&got.l[0]), lane(&got.l[1]), lane(&got.l[2])];
            assert_eq!(origin, bits(want.ray.origin), "{what}: origin");
            assert_eq!(l, bits(want.ray.direction), "{what}: l");
            assert_eq!(lane(&got.tmax), want.tmax.to_bits(), "{what}: tmax");
            assert_eq!(lane(&got.n_dot_l), want.n_dot_l.to_bits(), "{what}: n·l");
            assert_eq!(lane(&got.dist), want.dist.to_bits(), "{what}: dist");
        }
    }
}

fn both_widths(hits: &[SurfaceHit], light: &Light, target: Vec3) {
    check::<f32x8>(hits, light, target);
    check::<f32x16>(hits, light, target);
}

fn lab_light() -> Light {
    Scene::builtin_default().lights[0].clone()
}

fn hit(point: Vec3, normal: Vec3, offset: f32) -> SurfaceHit {
    SurfaceHit {
        point,
        normal,
        offset,
    }
}

#[test]
fn edge_cases_equal_the_scalar_spawn() {
    let light = lab_light();
    let (c, n) = (light.centroid, light.normal);
    // Two directions in the light's plane.
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let hits = [
        // On the light's plane, at +0 and −0 height, and at the centroid itself.
        hit(c + u * 0.3, -n, 1e-4),
        hit(c - v * 0.3, n, 1e-4),
        hit(c, n, 1e-4),
        // Behind the light, facing it and facing away.
        hit(c + n * 0.5, -n, 1e-4),
        hit(c + n * 0.5, n, 1e-4),
        // In front, facing the light, away from it, and grazing: the tangent plane through
        // the centroid, and just above and below it by about the margin.
        hit(c - n * 0.7, n, 1e-4),
        hit(c - n * 0.7, -n, 1e-4),
        hit(c - n * 0.7 + u * 0.2, u, 1e-4),
        hit(c - n * 0.7 + u * 0.2, (u + n * 3e-4).normalize(), 1e-4),
        hit(c - n * 0.7 + u * 0.2, (u - n * 3e-4).normalize(), 1e-4),
        // No offset, a huge offset, and an offset that is NaN.
        hit(c - n * 0.7, n, 0.0),
        hit(c - n * 0.7, n, 10.0),
        hit(c - n * 0.7, n, NAN),
        // NaN and infinite points and normals, a zero normal.
        hit(Vec3::new(NAN, 0.0, 0.0), n, 1e-4),
        hit(Vec3::new(0.0, INF, 0.0), -n, 1e-4),
        hit(c - n * 0.7, Vec3::new(NAN, NAN, NAN), 1e-4),
        hit(c - n * 0.7, Vec3::ZERO, 1e-4),
        // Far away and very close, in both directions along the plane.
        hit(c - n * 1e6 + u * 1e6, -n, 1e2),
        hit(c - n * 1e-6, -n, 1e-7),
    ];
    for len in [0, 1, 7, 8, 9, 16, 17, hits.len()] {
        let hits = &hits[..len.min(hits.len())];
        both_widths(hits, &light, c);
        // A target off the centroid (the kernel takes any point of the light).
        both_widths(hits, &light, c + u * 0.1 - v * 0.05);
    }
}

#[test]
fn random_hits_at_every_scale_equal_the_scalar_spawn() {
    let mut rng: TestRng = seeded(0x4a7d);
    for scale in [1e-3f32, 1e-1, 1.0, 10.0, 1e3] {
        let base = lab_light();
        let light = Light {
            centroid: base.centroid * scale,
            ..base
        };
        for len in [1, 7, 8, 9, 31, 33, 200] {
            let hits: Vec<SurfaceHit> = (0..len)
                .map(|_| {
                    let normal = rng.direction().normalize();
                    hit(rng.point(scale), normal, 1e-4 * scale * rng.unit())
                })
                .collect();
            let target = light.centroid + rng.point(0.1 * scale);
            both_widths(&hits, &light, target);
        }
    }
}

/// The first `lanes` rays of a group as the queue holds them: the `live` ones, and dead ones
/// with tmax 0 (the queue holds no dead rays; a tmax of 0 cannot be blocked).
struct Queued {
    origin: [Vec<f32>; 3],
    direction: [Vec<f32>; 3],
    tmax: Vec<f32>,
}

impl Queued {
    fn of<V: Lanes>(rays: &HitRays<V::Array>, live: u32, lanes: usize) -> Queued {
        let col = |c: &V::Array| -> Vec<f32> { c.as_ref()[..lanes].to_vec() };
        let tmax = (0..lanes)
            .map(|k| {
                if live >> k & 1 == 1 {
                    rays.tmax.as_ref()[k]
                } else {
                    0.0
                }
            })
            .collect();
        Queued {
            origin: rays.origin.each_ref().map(col),
            direction: rays.l.each_ref().map(col),
            tmax,
        }
    }

    fn columns(&self) -> RayColumns<'_> {
        RayColumns {
            origin: self.origin.each_ref().map(Vec::as_slice),
            direction: self.direction.each_ref().map(Vec::as_slice),
            tmax: &self.tmax,
        }
    }
}

/// The rays `hit_shadow_rays` makes from random hits inside the lab box (its three spheres and,
/// two-sided, its walls block some of them), tested in registers and in columns.
fn check_occlusion<V: Lanes>(rng: &mut TestRng, len: usize, two_sided: bool) {
    let scene = Scene::builtin_default();
    let light = &scene.lights[0];
    let casters = shadow_casters(&scene);
    let triangles = geometry::casters(&scene, &casters, two_sided);
    let hits: Vec<SurfaceHit> = (0..len)
        .map(|_| hit(rng.point(0.95), rng.direction().normalize(), 1e-4))
        .collect();
    let b = batch(&hits);
    let mut some_blocked = false;
    for i0 in (0..len).step_by(V::N) {
        let rays = hit_shadow_rays(
            &HitLanes::<V>::load(&b, i0),
            light,
            light_offset(light),
            light.centroid,
        );
        let lanes = (len - i0).min(V::N);
        let live = rays.live & ((1u32 << lanes) - 1);
        let got = hit_rays_occluded::<V, _>(
            triangles,
            &scene.spheres,
            &rays,
            live,
            two_sided,
            &mut NoCount,
        );
        let queued = Queued::of::<V>(&rays, live, lanes);
        let cols = queued.columns();
        let mut want = vec![false; lanes];
        simd::occluded::<f32x8, _>(
            triangles,
            &scene.spheres,
            &cols,
            two_sided,
            &mut want,
            &mut NoCount,
        );
        for k in (0..lanes).filter(|k| live >> k & 1 == 1) {
            assert_eq!(
                got >> k & 1 == 1,
                want[k],
                "{}-lane group at {i0}, lane {k}",
                V::N
            );
            some_blocked |= want[k];
        }
    }
    assert!(
        len < 64 || some_blocked,
        "no ray was blocked: the test has no power"
    );
}

#[test]
fn occlusion_in_registers_equals_occlusion_in_columns() {
    let mut rng: TestRng = seeded(0x0cc1);
    for len in [0, 1, 7, 8, 9, 17, 300] {
        for two_sided in [false, true] {
            check_occlusion::<f32x8>(&mut rng, len, two_sided);
            check_occlusion::<f32x16>(&mut rng, len, two_sided);
        }
    }
}

/// The rays `hit_shadow_rays` makes from random hits inside the mesh box (its tessellated
/// spheres block some), through the BVH from registers and from columns. Every other group has
/// its first lanes' tmax set to NaN, −1, 0, T_MIN and just above it: the walk skips the same
/// lanes the queue's does, and charges each traced lane what the queue charges its ray.
fn check_mesh_occlusion<V: Lanes>(rng: &mut TestRng, scene: &Scene, len: usize, two_sided: bool) {
    let bvh = MeshBvh::new(scene);
    let light = &scene.lights[0];
    let hits: Vec<SurfaceHit> = (0..len)
        .map(|_| hit(rng.point(0.95), rng.direction().normalize(), 1e-4))
        .collect();
    let b = batch(&hits);
    let mut stack = bvh.stack();
    let mut some_blocked = false;
    for i0 in (0..len).step_by(V::N) {
        let mut rays = hit_shadow_rays(
            &HitLanes::<V>::load(&b, i0),
            light,
            light_offset(light),
            light.centroid,
        );
        let lanes = (len - i0).min(V::N);
        if (i0 / V::N) % 2 == 1 {
            let edges = [f32::NAN, -1.0, 0.0, T_MIN, T_MIN.next_up()];
            for (t, edge) in rays.tmax.as_mut().iter_mut().zip(edges) {
                *t = edge;
            }
        }
        let live = rays.live & (((1u64 << lanes) - 1) as u32);
        let mut got_costs = vec![Cost::default(); lanes];
        let got = bvh.hit_rays_occluded(
            scene,
            &rays,
            live,
            two_sided,
            &mut stack,
            0,
            &mut PerRay(&mut got_costs),
        );
        let queued = Queued::of::<V>(&rays, live, lanes);
        let cols = queued.columns();
        let (mut want, mut want_costs) = (vec![false; lanes], vec![Cost::default(); lanes]);
        bvh.occluded(
            scene,
            &cols,
            two_sided,
            &mut want,
            &mut PerRay(&mut want_costs),
        );
        for k in (0..lanes).filter(|k| live >> k & 1 == 1) {
            assert_eq!(
                got >> k & 1 == 1,
                want[k],
                "{}-lane group at {i0}, lane {k}, tmax {}",
                V::N,
                queued.tmax[k]
            );
            some_blocked |= want[k];
        }
        assert_eq!(got_costs, want_costs, "{}-lane group at {i0}", V::N);
    }
    assert!(
        len < 64 || some_blocked,
        "no ray was blocked: the test has no power"
    );
}

#[test]
fn mesh_occlusion_in_registers_equals_the_queue_s() {
    let path = concat!(env!("RAYWAVE_REPO"), "/scenes/mesh_spheres_small.obj");
    let scene = Scene::load(std::path::Path::new(path)).expect("scenes/mesh_spheres_small.obj");
    let mut rng: TestRng = seeded(0x3e5b);
    for len in [0, 1, 7, 8, 9, 17, 300] {
        for two_sided in [false, true] {
            check_mesh_occlusion::<f32x8>(&mut rng, &scene, len, two_sided);
            check_mesh_occlusion::<f32x16>(&mut rng, &scene, len, two_sided);
        }
    }
}
