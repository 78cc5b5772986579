//! The mesh BVH's leaf kernels (`wavefront::bvh::arrays`) against the scalar
//! `intersect_triangle`, lane by lane and bit for bit: on an edge-case table of rays and
//! triangles for every leaf length up to the lane width, and on random input.

use crate::common;

use common::strategies::{any_f32, vec3};
use common::{edge_rays, ray, triangle};
use glam::Vec3;
use proptest::prelude::*;
use raywave::render::geometry::{Ray, intersect_triangle};
use raywave::render::scene::Triangle;
use raywave::render::wavefront::bvh::arrays;

const NAN: f32 = f32::NAN;
const INF: f32 = f32::INFINITY;
/// Random coordinates lie in [−HALF, HALF): the generated meshes' scale.
const HALF: f32 = 10.0;

fn edge_triangles() -> Vec<Triangle> {
    vec![
        triangle(Vec3::ZERO, Vec3::X, Vec3::Y),
        triangle(Vec3::ZERO, Vec3::Y, Vec3::X), // facing −z
        triangle(Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)), // degenerate
        triangle(Vec3::X, Vec3::Y, Vec3::Z),
        triangle(Vec3::ZERO, Vec3::ZERO, Vec3::ZERO), // a point
        triangle(
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(1.0, 0.0, 0.5),
            Vec3::new(0.0, 1.0, 0.5),
        ),
        triangle(
            Vec3::splat(-1e20),
            Vec3::splat(1e20),
            Vec3::new(1e20, -1e20, 0.0),
        ),
        triangle(
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::ZERO,
        ),
    ]
}

/// Lane k of the leaf kernels equals the scalar kernel for `tris[k]`; lanes past the end miss.
fn check_leaf(tris: &[Triangle], r: &Ray, tmax: f32, two_sided: bool) {
    let got = arrays::triangles(tris, r, tmax, two_sided);
    let mut any = false;
    for (k, got) in got.iter().enumerate() {
        let want = tris
            .get(k)
            .map_or(INF, |t| intersect_triangle(t, r, tmax, two_sided));
        any |= want < tmax;
        assert_eq!(
            got.to_bits(),
            want.to_bits(),
            "lane {k}: {r:?} tmax {tmax} two-sided {two_sided}: leaf {got} scalar {want}"
        );
    }
    assert_eq!(
        arrays::blocks(tris, r, tmax, two_sided),
        any,
        "{r:?} tmax {tmax}"
    );
}

#[test]
fn leaf_kernels_equal_scalar_on_edge_cases() {
    let tris = edge_triangles();
    for len in [0, 1, 3, 7, 8] {
        for start in 0..tris.len() {
            let set: Vec<Triangle> = (0..len).map(|k| tris[(start + k) % tris.len()]).collect();
            for r in &edge_rays() {
                for tmax in [INF, 1.0, 0.5, 0.0, -1.0, NAN] {
                    for two_sided in [false, true] {
                        check_leaf(&set, r, tmax, two_sided);
                    }
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn leaf_kernels_equal_scalar_on_random_input(
        verts in prop::collection::vec((vec3(HALF), vec3(HALF), vec3(HALF)), 0..=8),
        o in (any_f32(HALF), any_f32(HALF), any_f32(HALF)),
        d in (any_f32(HALF), any_f32(HALF), any_f32(HALF)),
        tmax in prop_oneof![3 => 0.0f32..30.0, 1 => Just(INF), 1 => any_f32(HALF)],
        two_sided: bool,
    ) {
        let tris: Vec<Triangle> = verts.iter().map(|&(a, b, c)| triangle(a, b, c)).collect();
        let r = ray([o.0, o.1, o.2], [d.0, d.1, d.2]);
        check_leaf(&tris, &r, tmax, two_sided);
    }

    #[test]
    fn leaf_kernels_equal_scalar_on_rays_that_hit(
        verts in prop::collection::vec((vec3(HALF), vec3(HALF), vec3(HALF)), 1..=8),
        o in vec3(HALF),
        (a, b) in (0.0f32..1.0, 0.0f32..1.0),
        tmax in prop_oneof![Just(INF), 0.0f32..30.0],
        two_sided: bool,
    ) {
        // Aim at a point of the first triangle, so that lanes hit often.
        let tris: Vec<Triangle> = verts.iter().map(|&(a, b, c)| triangle(a, b, c)).collect();
        let target = tris[0].v0 + a * (1.0 - b) * tris[0].e1 + a * b * tris[0].e2;
        let r = Ray { origin: o, direction: (target - o).normalize_or_zero() };
        check_leaf(&tris, &r, tmax, two_sided);
    }
}
