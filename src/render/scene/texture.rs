//! Textured diffuse colour, as RPI's framework computes it (`Material::getDiffuseColor` in its
//! `material.cpp`): the texture coordinates (s, t) of a hit, interpolated from the corners of its
//! triangle with the hit's barycentrics, pick four texels, blended bilinearly.
//!
//! ```text
//! x = wrap(s) · width             wrap(s) = s − ⌊s⌋: the texture repeats
//! i1 = ⌊x⌋ (width → 0)   dx = x − ⌊x⌋   i2 = min(i1 + 1, width − 1)      (the same for t, rows)
//! kd = c(i1,j1)·(1−dx)·(1−dy) + c(i1,j2)·(1−dx)·dy + c(i2,j1)·dx·(1−dy) + c(i2,j2)·dx·dy
//! ```
//!
//! Texels are linear: each is converted from sRGB when the texture is read, which is what RPI
//! does to each of the four before blending. Row 0 is the bottom row of the file: t = 0 is the
//! image's bottom edge, as RPI's `Image::Load` flips the rows. A point without texture
//! coordinates (a face whose vertices have no `vt`, a sphere, a ring) has (s, t) = (0, 0), RPI's
//! default, and so takes the bottom-left texel. docs/SHADING.md gives the reasons.
//!
//! This is the scalar code both engines' results are defined by: the reference calls it per
//! hit, and the wavefront engine's 8-lane kernel (`wavefront::texels`) is its twin.

use super::{Scene, Triangle};
use glam::{DVec3, Vec3};
use std::path::PathBuf;

/// A texture read from a PPM file: linear texels, rows from the bottom of the image up.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// The name as the scene file gives it.
    pub name: String,
    /// Where it was read from: the name resolved against the scene file's folder.
    pub path: PathBuf,
    /// Width in texels (≥ 1).
    pub width: u32,
    /// Height in texels (≥ 1).
    pub height: u32,
    /// Linear colours, `width × height`, row `j` (from the bottom) at `j·width`.
    pub texels: Vec<Vec3>,
    /// The mean of the linear texels: RPI's `ComputeAverageTextureColor`, the material's diffuse
    /// colour wherever one colour stands for the texture (the viewer's 3D scene, exports).
    pub average: Vec3,
    /// The name leaves the scene file's folder (absolute, or climbing out through `..`):
    /// allowed, and the render's summary shows where it led.
    pub outside_folder: bool,
    /// FNV-1a (64-bit) of the texture's size and samples as read: what caches and records key
    /// on for it (`SceneFile::bytes`). 0 for a texture not read from a file.
    pub digest: u64,
}

/// sRGB-encoded [0, 1] to linear: the IEC 61966-2-1 curve RPI's `srgb_to_linear` uses.
pub fn srgb_to_linear(x: f64) -> f64 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

impl Texture {
    /// A texture from 8- or 16-bit sRGB samples in file order (top row first, `r g b` per
    /// texel), each divided by `max` (255 or 65535). `samples.len()` must be
    /// `3 · width · height` and both sizes ≥ 1 (the reader checks).
    pub fn from_srgb(
        name: String,
        path: PathBuf,
        width: u32,
        height: u32,
        samples: impl Fn(usize) -> u16,
        max: f64,
    ) -> Texture {
        let (w, h) = (width as usize, height as usize);
        let mut texels = Vec::with_capacity(w * h);
        let mut sum = DVec3::ZERO;
        for j in 0..h {
            // Row j from the bottom is file row h − 1 − j.
            let row = (h - 1 - j) * w;
            for i in 0..w {
                let at = 3 * (row + i);
                let c = [0, 1, 2].map(|k| srgb_to_linear(samples(at + k) as f64 / max));
                sum += DVec3::from_array(c);
                texels.push(DVec3::from_array(c).as_vec3());
            }
        }
        let n = (w * h) as f64;
        Texture {
            name,
            path,
            width,
            height,
            texels,
            average: (sum / n).as_vec3(),
            outside_folder: false,
            digest: 0,
        }
    }

    /// The texel in column `i`, row `j` (from the bottom).
    #[inline]
    pub fn texel(&self, i: u32, j: u32) -> Vec3 {
        self.texels[(j * self.width + i) as usize]
    }

    /// The bilinear lookup at (s, t): the module's formula.
    #[inline]
    pub fn lookup(&self, s: f32, t: f32) -> Vec3 {
        let (i1, i2, dx) = footprint(s, self.width);
        let (j1, j2, dy) = footprint(t, self.height);
        let (c1, c2) = (self.texel(i1, j1), self.texel(i1, j2));
        let (c3, c4) = (self.texel(i2, j1), self.texel(i2, j2));
        c1 * (1.0 - dx) * (1.0 - dy) + c2 * (1.0 - dx) * dy + c3 * dx * (1.0 - dy) + c4 * dx * dy
    }
}

/// Where coordinate `s` falls on an axis of `n` texels: the two texels and the weight of the
/// second. s wraps into [0, 1) (a non-finite s counts as 0); the second texel is clamped at the
/// last, not wrapped, as in RPI.
#[inline]
pub fn footprint(s: f32, n: u32) -> (u32, u32, f32) {
    let s = if s.is_finite() { s } else { 0.0 };
    let x = (s - s.floor()) * n as f32;
    let i = x.floor();
    let (i1, i2) = texel_pair(i, n);
    (i1, i2, x - i)
}

/// The two texels from ⌊x⌋ = `i` (0 ≤ i ≤ n) on an axis of `n`: i itself, except that i = n
/// (x reaches n only when s − ⌊s⌋ rounds up to 1: that is s = 1) is texel 0; and the next one,
/// clamped at the last.
#[inline]
pub fn texel_pair(i: f32, n: u32) -> (u32, u32) {
    let i1 = if i >= n as f32 { 0 } else { i as u32 };
    (i1, (i1 + 1).min(n - 1))
}

/// The barycentric coordinates (b1, b2) of `p` in `tri` (p = v0 + b1·e1 + b2·e2 in its plane),
/// from the normal equations of the edges: ratios of lengths, so unchanged when the scene is
/// scaled.
#[inline]
fn barycentrics(tri: &Triangle, p: Vec3) -> (f32, f32) {
    let q = p - tri.v0;
    let (e1, e2) = (tri.e1, tri.e2);
    let d00 = e1.x * e1.x + e1.y * e1.y + e1.z * e1.z;
    let d01 = e1.x * e2.x + e1.y * e2.y + e1.z * e2.z;
    let d11 = e2.x * e2.x + e2.y * e2.y + e2.z * e2.z;
    let d20 = q.x * e1.x + q.y * e1.y + q.z * e1.z;
    let d21 = q.x * e2.x + q.y * e2.y + q.z * e2.z;
    let denom = d00 * d11 - d01 * d01;
    (
        (d11 * d20 - d01 * d21) / denom,
        (d00 * d21 - d01 * d20) / denom,
    )
}

/// (s, t) at `p` on a triangle whose corners (v0, v0 + e1, v0 + e2) have coordinates `st`.
#[inline]
fn interpolate(tri: &Triangle, st: &[[f32; 2]; 3], p: Vec3) -> [f32; 2] {
    let (b1, b2) = barycentrics(tri, p);
    let b0 = 1.0 - b1 - b2;
    [0, 1].map(|k| b0 * st[0][k] + b1 * st[1][k] + b2 * st[2][k])
}

impl Scene {
    /// (s, t) of the point `p` on primitive `prim`: interpolated on a triangle with texture
    /// coordinates, (0, 0) anywhere else.
    #[inline]
    pub fn texture_coords(&self, prim: u32, p: Vec3) -> [f32; 2] {
        match self.texcoords.get(prim as usize) {
            Some(st) => interpolate(&self.triangles[prim as usize], st, p),
            None => [0.0, 0.0],
        }
    }

    /// The diffuse colour kd at point `p` (on its surface) of primitive `prim`: the material's
    /// texture looked up there, or its plain diffuse colour.
    #[inline]
    pub fn diffuse_at(&self, prim: u32, p: Vec3) -> Vec3 {
        let material = self.material_of(prim);
        match material.texture {
            None => material.diffuse,
            Some(k) => {
                let [s, t] = self.texture_coords(prim, p);
                self.textures[k as usize].lookup(s, t)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(width: u32, height: u32, texels: Vec<Vec3>) -> Texture {
        Texture {
            name: "t.ppm".into(),
            path: "t.ppm".into(),
            width,
            height,
            texels,
            average: Vec3::ZERO,
            outside_folder: false,
            digest: 0,
        }
    }

    #[test]
    fn footprint_wraps_and_clamps_like_rpi() {
        assert_eq!(footprint(0.0, 4), (0, 1, 0.0));
        assert_eq!(footprint(0.375, 4), (1, 2, 0.5));
        // The last texel blends with itself: clamped, not wrapped.
        assert_eq!(footprint(0.875, 4), (3, 3, 0.5));
        // s = 1 is texel 0, as RPI's modulo makes it; 1.25 repeats 0.25.
        assert_eq!(footprint(1.0, 4), (0, 1, 0.0));
        assert_eq!(footprint(1.25, 4), footprint(0.25, 4));
        // Negative coordinates repeat too (RPI truncates towards zero there instead).
        assert_eq!(footprint(-0.75, 4), footprint(0.25, 4));
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(footprint(bad, 4), (0, 1, 0.0));
        }
        // A tiny negative s wraps to just below 1, which rounds to 1: texel 0, not 4.
        assert_eq!(footprint(-1e-9, 4).0, 0);
        assert_eq!(footprint(0.5, 1), (0, 0, 0.5));
    }

    #[test]
    fn lookup_is_bilinear_and_t_counts_rows_from_the_bottom() {
        // 2 × 2: bottom row red, green; top row blue, white.
        let (r, g, b, w) = (Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE);
        let tex = texture(2, 2, vec![r, g, b, w]);
        assert_eq!(tex.lookup(0.0, 0.0), r);
        assert_eq!(tex.lookup(0.5, 0.0), g);
        assert_eq!(tex.lookup(0.0, 0.5), b);
        assert_eq!(tex.lookup(0.25, 0.0), 0.5 * r + 0.5 * g);
        assert_eq!(tex.lookup(0.25, 0.25), 0.25 * (r + g + b + w));
    }

    #[test]
    fn from_srgb_flips_rows_and_linearises() {
        // File order: top row first. 1 × 2: top 255 (white), bottom 0 (black).
        let samples = [255u16, 255, 255, 0, 0, 0];
        let tex = Texture::from_srgb("x".into(), "x".into(), 1, 2, |k| samples[k], 255.0);
        assert_eq!(tex.texel(0, 0), Vec3::ZERO);
        assert_eq!(tex.texel(0, 1), Vec3::ONE);
        assert_eq!(tex.average, Vec3::splat(0.5));
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-6);
        assert_eq!(srgb_to_linear(0.04), 0.04 / 12.92);
    }

    #[test]
    fn barycentrics_do_not_change_with_scale() {
        let tri = |s: f32| Triangle {
            v0: Vec3::new(1.0, 2.0, 3.0) * s,
            e1: Vec3::new(2.0, 0.5, 0.0) * s,
            e2: Vec3::new(0.25, 3.0, 1.0) * s,
            normal: Vec3::Z,
            material: 0,
            face: 0,
        };
        let p = |s: f32| {
            (Vec3::new(1.0, 2.0, 3.0)
                + 0.3 * Vec3::new(2.0, 0.5, 0.0)
                + 0.2 * Vec3::new(0.25, 3.0, 1.0))
                * s
        };
        for s in [1e-4, 1.0, 1e4] {
            let (b1, b2) = barycentrics(&tri(s), p(s));
            assert!(
                (b1 - 0.3).abs() < 1e-5 && (b2 - 0.2).abs() < 1e-5,
                "{s}: {b1} {b2}"
            );
        }
    }
}
