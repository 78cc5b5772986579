//! Stage 2b, texels: the diffuse colour kd at every hit on a textured material, 8 hits at a
//! time, made into shading terms of the hit's own (`HitBatch::terms`). Runs only when the scene
//! has a textured material, after the intersect stage has put every hit point back on its
//! surface.
//!
//! ```text
//! gather   per lane: the triangle (v0, e1, e2), its corners' (s, t) and the texture's size
//! lanes    barycentrics of the point, (s, t), each wrapped into [0, 1) and cut into texel
//!          column/row and fraction                                    (8 lanes)
//! gather   per lane: the four texels
//! lanes    the bilinear blend                                         (8 lanes)
//! ```
//!
//! [`diffuse8`] is the twin of the scalar `Scene::diffuse_at` (`scene::texture`), which the
//! reference calls per hit: the same operations in the same order, so each lane equals it bit
//! for bit (tests/kernels/texels.rs holds them so). A lane off a triangle with coordinates (a
//! sphere, a face without `vt`) is given a unit triangle and corners at (0, 0), which puts
//! (s, t) at ±0, wrapped to the scalar code's (0, 0).

use super::batch::HitBatch;
use super::context::Context;
use super::lanes::{LANES, Lanes, f32x8};
use crate::render::scene::texture::{Texture, texel_pair};
use crate::render::scene::{NO_HIT, Scene, Triangle};
use glam::Vec3;

/// Gives every hit `0..n` on a textured material terms of its own: kd the texel at the hit,
/// appended to `hits.terms` (which starts as the context's materials) and pointed to by
/// `hits.material`.
pub fn fill(ctx: &Context, hits: &mut HitBatch, n: usize) {
    let mut i0 = 0;
    while i0 < n {
        let lanes = (n - i0).min(LANES);
        let mut mask = 0u32;
        for k in 0..lanes {
            let i = i0 + k;
            if hits.prim[i] != NO_HIT && ctx.materials[hits.material[i] as usize].texture.is_some()
            {
                mask |= 1 << k;
            }
        }
        if mask != 0 {
            let prims = std::array::from_fn(|k| hits.prim[i0 + k.min(lanes - 1)]);
            let point = [&hits.point.x, &hits.point.y, &hits.point.z]
                .map(|c| std::array::from_fn(|k| c[i0 + k.min(lanes - 1)]));
            let kd = diffuse8(ctx.scene, &prims, &point, mask);
            for k in (0..lanes).filter(|&k| mask >> k & 1 == 1) {
                let i = i0 + k;
                let base = &ctx.materials[hits.material[i] as usize];
                let kd = Vec3::new(kd[0][k], kd[1][k], kd[2][k]);
                hits.terms.push(base.with_diffuse(kd, ctx.ambient));
                hits.material[i] = (hits.terms.len() - 1) as u32;
            }
        }
        i0 += LANES;
    }
}

/// The unit triangle a lane without texture coordinates is given: any triangle would do, since
/// its corners' (s, t) are all 0.
const UNIT: Triangle = Triangle {
    v0: Vec3::ZERO,
    e1: Vec3::X,
    e2: Vec3::Y,
    normal: Vec3::Z,
    material: 0,
    face: 0,
};

/// kd at 8 hits (primitive `prims[k]`, point on its surface `point[·][k]`) for the lanes set in
/// `mask`, each on a textured material: lane k equals `scene.diffuse_at(prims[k], p_k)` bit for
/// bit. The other lanes are unspecified.
pub fn diffuse8(
    scene: &Scene,
    prims: &[u32; LANES],
    point: &[[f32; LANES]; 3],
    mask: u32,
) -> [[f32; LANES]; 3] {
    // Gather, lane by lane: the triangle (a unit one off a triangle with coordinates), its
    // corners' (s, t) and the texture's size, as [component][lane] arrays.
    let mut corner = [[[0.0f32; LANES]; 3]; 3]; // v0, e1, e2
    let mut st = [[[0.0f32; LANES]; 2]; 3]; // corner, s|t
    let mut size = [[1.0f32; LANES]; 2]; // width, height
    let mut texture: [Option<&Texture>; LANES] = [None; LANES];
    for k in (0..LANES).filter(|&k| mask >> k & 1 == 1) {
        let p = prims[k] as usize;
        let (tri, uv) = match scene.texcoords.get(p) {
            Some(uv) => (&scene.triangles[p], uv),
            None => (&UNIT, &[[0.0; 2]; 3]),
        };
        for (c, v) in corner.iter_mut().zip([tri.v0, tri.e1, tri.e2]) {
            for a in 0..3 {
                c[a][k] = v[a];
            }
        }
        for (n, uv) in uv.iter().enumerate() {
            st[n][0][k] = uv[0];
            st[n][1][k] = uv[1];
        }
        let tex = scene
            .material_of(prims[k])
            .texture
            .map(|t| &scene.textures[t as usize]);
        if let Some(tex) = tex {
            size[0][k] = tex.width as f32;
            size[1][k] = tex.height as f32;
        }
        texture[k] = tex;
    }
    let [v0, e1, e2] = corner.map(|c| c.map(f32x8::from_array));
    let p = point.map(f32x8::from_array);
    // `texture::barycentrics`, lane by lane.
    let q = [p[0] - v0[0], p[1] - v0[1], p[2] - v0[2]];
    let dot = |a: &[f32x8; 3], b: &[f32x8; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (d00, d01, d11) = (dot(&e1, &e1), dot(&e1, &e2), dot(&e2, &e2));
    let (d20, d21) = (dot(&q, &e1), dot(&q, &e2));
    let denom = d00 * d11 - d01 * d01;
    let b1 = (d11 * d20 - d01 * d21) / denom;
    let b2 = (d00 * d21 - d01 * d20) / denom;
    let b0 = f32x8::ONE - b1 - b2;
    // `texture::interpolate`.
    let [s, t] = [0, 1].map(|c| {
        let at = |n: usize| f32x8::from_array(st[n][c]);
        b0 * at(0) + b1 * at(1) + b2 * at(2)
    });
    let [width, height] = size.map(f32x8::from_array);
    let (x, dx) = footprint8(s, width);
    let (y, dy) = footprint8(t, height);
    // Gather the four texels of each lane (`Texture::lookup`'s c1..c4).
    let (x, y) = (x.to_array(), y.to_array());
    let mut c = [[[0.0f32; LANES]; 3]; 4];
    for k in (0..LANES).filter(|&k| mask >> k & 1 == 1) {
        let Some(tex) = texture[k] else { continue };
        let (i1, i2) = texel_pair(x[k], tex.width);
        let (j1, j2) = texel_pair(y[k], tex.height);
        for (n, (i, j)) in [(i1, j1), (i1, j2), (i2, j1), (i2, j2)]
            .into_iter()
            .enumerate()
        {
            let texel = tex.texel(i, j);
            for a in 0..3 {
                c[n][a][k] = texel[a];
            }
        }
    }
    let one = f32x8::ONE;
    [0, 1, 2].map(|a| {
        let c = |n: usize| f32x8::from_array(c[n][a]);
        (c(0) * (one - dx) * (one - dy)
            + c(1) * (one - dx) * dy
            + c(2) * dx * (one - dy)
            + c(3) * dx * dy)
            .to_array()
    })
}

/// `texture::footprint` on 8 lanes, up to the integer texel: ⌊x⌋ (as a float, for
/// `texture::texel_pair`) and the fraction.
#[inline]
fn footprint8(s: f32x8, n: f32x8) -> (f32x8, f32x8) {
    let s = s.is_finite().select(s, f32x8::ZERO);
    let x = (s - s.floor()) * n;
    let i = x.floor();
    (i, x - i)
}
