//! The texel stage (`wavefront::texels`, 8 hits at a time) against its scalar twin
//! `Scene::diffuse_at`, bit for bit: batch sizes 0, 1, 7, 8, 9 and more, hits mixed with misses,
//! untextured materials and spheres, coordinates that wrap, sit on texel edges or are not finite,
//! and random points on every textured triangle.

use crate::common::random::{Draw, seeded};
use glam::Vec3;
use rand::RngExt;
use raywave::render::scene::{NO_HIT, Scene, parse_scene_in};
use raywave::render::settings::RenderSettings;
use raywave::render::wavefront::batch::HitBatch;
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::texels::{diffuse8, fill};
use std::path::Path;

/// Two textured quads (one wrapping twice, one with a corner without `vt`), an untextured
/// quad, a textured sphere and a plain one, over a 5 × 3 texture and a 1 × 1 one.
fn scene(dir: &Path) -> Scene {
    let mut body = String::from("P3\n5 3\n255\n");
    for k in 0..15 {
        body += &format!("{} {} {}\n", 17 * k, 255 - 13 * k, (101 * k) % 256);
    }
    std::fs::write(dir.join("five.ppm"), body).unwrap();
    std::fs::write(dir.join("one.ppm"), b"P6\n1 1\n255\n\x40\x80\xc0").unwrap();
    let text = "\
material\ntexture_file five.ppm\n\
material\ndiffuse 0.3 0.6 0.9\n\
material\ntexture_file one.ppm\n\
v 0 0 0\nvt 0 0\nv 2 0 0\nvt 2 0\nv 2 1 0\nvt 2 1\nv 0 1 0\nvt 0 1\n\
v 0 0 1\nvt -0.3 0.25\nv 1 0 1\nvt 0.999999 1e6\nv 1 1 1\nv 0 1 1\nvt 0.5 0.5\n\
v 0 0 2\nv 1 0 2\nv 1 1 2\n\
m 0\nf 1 2 3 4\nf 5 6 7 8\nm 1\nf 9 10 11\nm 0\ns 0 0 5 1\nm 1\ns 0 0 8 1\nm 2\ns 0 0 11 1\n";
    parse_scene_in(text, "texels.obj", &Default::default(), Some(dir)).unwrap()
}

/// A point on primitive `prim`: on a triangle at barycentrics (b1, b2), on a sphere anywhere.
fn point_on(scene: &Scene, prim: u32, b1: f32, b2: f32) -> Vec3 {
    match scene.triangles.get(prim as usize) {
        Some(t) => t.v0 + b1 * t.e1 + b2 * t.e2,
        None => scene.spheres[prim as usize - scene.triangles.len()].center + Vec3::X,
    }
}

/// Runs the stage on `hits` (prim, point) and checks every textured hit against the scalar twin.
fn check(scene: &Scene, hits_in: &[(u32, Vec3)]) {
    let settings = RenderSettings::default();
    let ctx = Context::new(scene, &settings);
    let mut hits = HitBatch::default();
    let n = hits_in.len();
    hits.resize(n);
    hits.terms = ctx.materials.clone();
    for (i, &(prim, p)) in hits_in.iter().enumerate() {
        hits.prim[i] = prim;
        hits.point.set(i, p);
        if prim != NO_HIT {
            let (_, m) = ctx.surface(prim, p);
            hits.material[i] = m;
        }
    }
    fill(&ctx, &mut hits, n);
    for (i, &(prim, p)) in hits_in.iter().enumerate() {
        if prim == NO_HIT || scene.material_of(prim).texture.is_none() {
            continue;
        }
        let lanes = hits.terms[hits.material[i] as usize].diffuse;
        let scalar = scene.diffuse_at(prim, p);
        assert_eq!(
            lanes.to_array().map(f32::to_bits),
            scalar.to_array().map(f32::to_bits),
            "hit {i} of {n} (prim {prim}, point {p}): lanes {lanes} scalar {scalar}"
        );
    }
}

#[test]
fn batches_of_every_size_equal_the_scalar_lookup() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path());
    let prims = scene.primitive_count() as u32;
    let mut rng = seeded(11);
    for n in [0, 1, 7, 8, 9, 16, 17, 100] {
        let hits: Vec<(u32, Vec3)> = (0..n)
            .map(|k| {
                // Every tenth a miss; the rest spread over every primitive.
                if k % 10 == 9 {
                    return (NO_HIT, Vec3::ZERO);
                }
                let prim = rng.random_range(0..prims);
                let (b1, b2) = (rng.unit(), rng.unit());
                let (b1, b2) = if b1 + b2 > 1.0 {
                    (1.0 - b1, 1.0 - b2)
                } else {
                    (b1, b2)
                };
                (prim, point_on(&scene, prim, b1, b2))
            })
            .collect();
        check(&scene, &hits);
    }
}

#[test]
fn edges_seams_and_corners_equal_the_scalar_lookup() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path());
    let mut hits = Vec::new();
    // On the wrapping quad's triangles: corners, the seam s = 1 (b1 = 0.5 of the 0..2 edge),
    // texel edges (multiples of 1/5 and 1/3), and points just inside them.
    for prim in 0..4u32 {
        for b1 in [0.0, 0.1, 0.2, 0.5, 1.0 / 3.0, 0.4999999, 0.5000001, 1.0] {
            for b2 in [0.0, 1.0 / 3.0, 2.0 / 3.0, 1e-7] {
                if b1 + b2 <= 1.0 {
                    hits.push((prim, point_on(&scene, prim, b1, b2)));
                }
            }
        }
    }
    // Spheres (textured: (0, 0)), and points off the plane or far away.
    for prim in 5..8 {
        hits.push((prim, point_on(&scene, prim, 0.0, 0.0)));
    }
    hits.push((0, Vec3::new(1e30, -1e30, 7.0)));
    hits.push((1, Vec3::new(0.5, 0.5, 3.0)));
    check(&scene, &hits);
}

#[test]
fn points_that_are_not_finite_take_texel_zero_in_both() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path());
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let p = Vec3::new(bad, 0.5, 0.0);
        let lanes = diffuse8(&scene, &[0; 8], &[[p.x; 8], [p.y; 8], [p.z; 8]], 0xff);
        let scalar = scene.diffuse_at(0, p);
        assert_eq!(scalar, scene.textures[0].texel(0, 0), "{bad}");
        for (k, ((r, g), b)) in lanes[0].iter().zip(&lanes[1]).zip(&lanes[2]).enumerate() {
            assert_eq!([*r, *g, *b], scalar.to_array(), "{bad}: lane {k}");
        }
    }
}
