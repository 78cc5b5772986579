//! The oracle's textures, by its own code: a PPM reader, sRGB to linear, a hit's (s, t) from its
//! barycentrics with the ambiguity rule's wrap case, and RPI's wrapped bilinear lookup, all in
//! f64. Written from the lookup's description (docs/SHADING.md, and the module doc of
//! `raywave::render::scene::texture`), not from the engines' code:
//!
//! ```text
//! x = (s − ⌊s⌋)·W    i1 = ⌊x⌋ (W → 0)    dx = x − ⌊x⌋    i2 = min(i1 + 1, W − 1)    (t: rows)
//! kd = c(i1,j1)(1−dx)(1−dy) + c(i1,j2)(1−dx)dy + c(i2,j1)dx(1−dy) + c(i2,j2)dx·dy
//! ```
//!
//! with c the texel's sRGB value over maxval, made linear, and row 0 the file's last row (t = 0
//! is the image's bottom edge).

use super::{Check, DECISION_MARGIN, Oracle, TEXTURE_WRAP};
use glam::DVec3;
use std::path::Path;

/// A texture: linear texels, row 0 at the bottom of the image.
#[derive(Clone, Debug)]
pub struct Image {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// `width × height` linear colours, row `j` from the bottom at `j·width`.
    texels: Vec<DVec3>,
}

/// sRGB-encoded [0, 1] to linear (IEC 61966-2-1).
pub fn srgb_to_linear(x: f64) -> f64 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// Reads whitespace-separated header and P3 tokens, skipping `#` comments to the end of a line.
struct Tokens<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Tokens<'_> {
    /// The next token as an integer, `what` naming it in the error.
    fn number(&mut self, what: &str) -> Result<u32, String> {
        loop {
            match self.bytes.get(self.at) {
                Some(b'#') => {
                    while self.bytes.get(self.at).is_some_and(|&b| b != b'\n') {
                        self.at += 1;
                    }
                }
                Some(b) if b.is_ascii_whitespace() => self.at += 1,
                _ => break,
            }
        }
        let start = self.at;
        while self.bytes.get(self.at).is_some_and(u8::is_ascii_digit) {
            self.at += 1;
        }
        std::str::from_utf8(&self.bytes[start..self.at])
            .unwrap()
            .parse()
            .map_err(|_| format!("expected {what} at byte {start}"))
    }
}

impl Image {
    /// Reads a P3 or P6 file with any maxval from 1 to 65535 (two bytes, most significant
    /// first, per P6 sample above 255).
    pub fn read(path: &Path) -> Result<Image, String> {
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let binary = match bytes.get(..2) {
            Some(b"P3") => false,
            Some(b"P6") => true,
            _ => return Err(format!("{}: not a P3 or P6 file", path.display())),
        };
        let mut tokens = Tokens {
            bytes: &bytes,
            at: 2,
        };
        let width = tokens.number("the width")? as usize;
        let height = tokens.number("the height")? as usize;
        let maxval = tokens.number("maxval")?;
        if width == 0 || height == 0 || !(1..=65535).contains(&maxval) {
            return Err(format!(
                "{}: {width}×{height}, maxval {maxval}",
                path.display()
            ));
        }
        let count = 3 * width * height;
        let samples: Vec<u32> = if binary {
            // Exactly one whitespace byte separates maxval from the raster.
            let raster = bytes.get(tokens.at + 1..).unwrap_or_default();
            let size = if maxval < 256 { 1 } else { 2 };
            if raster.len() < count * size {
                return Err(format!("{}: short raster", path.display()));
            }
            raster
                .chunks_exact(size)
                .take(count)
                .map(|c| c.iter().fold(0u32, |v, &b| (v << 8) | b as u32))
                .collect()
        } else {
            (0..count)
                .map(|_| tokens.number("a sample"))
                .collect::<Result<_, _>>()?
        };
        if samples.iter().any(|&v| v > maxval) {
            return Err(format!("{}: a sample above maxval", path.display()));
        }
        let linear = |k: usize| srgb_to_linear(samples[k] as f64 / maxval as f64);
        // Row j from the bottom is the file's row height − 1 − j.
        let texels = (0..height)
            .flat_map(|j| (0..width).map(move |i| 3 * ((height - 1 - j) * width + i)))
            .map(|k| DVec3::new(linear(k), linear(k + 1), linear(k + 2)))
            .collect();
        Ok(Image {
            width,
            height,
            texels,
        })
    }

    /// The texel in column `i`, row `j` from the bottom.
    pub fn texel(&self, i: usize, j: usize) -> DVec3 {
        self.texels[j * self.width + i]
    }

    /// The bilinear lookup at (s, t), both wrapped into [0, 1).
    pub fn lookup(&self, s: f64, t: f64) -> DVec3 {
        let (i1, i2, dx) = axis(s, self.width);
        let (j1, j2, dy) = axis(t, self.height);
        self.texel(i1, j1) * (1.0 - dx) * (1.0 - dy)
            + self.texel(i1, j2) * (1.0 - dx) * dy
            + self.texel(i2, j1) * dx * (1.0 - dy)
            + self.texel(i2, j2) * dx * dy
    }
}

/// The two texels along an axis of `n` and the second one's weight at coordinate `s`.
fn axis(s: f64, n: usize) -> (usize, usize, f64) {
    let x = (s - s.floor()) * n as f64;
    let i = x.floor();
    // x = n only when s − ⌊s⌋ rounds to 1, which is s's next whole number: texel 0.
    let first = if i >= n as f64 { 0 } else { i as usize };
    (first, (first + 1).min(n - 1), x - i)
}

/// Whether coordinate `value`, interpolated from a triangle's `corners`, is close to a whole
/// number, where the lookup jumps from texel n − 1 to texel 0 (along an axis of `n` > 1
/// texels). Close is within `margin` of the largest corner (at least 1): an f32 engine's
/// b0·s0 + b1·s1 + b2·s2 is off by a few ulps of its largest term, whatever the texture's
/// width, so the margin is in coordinate units, not texels (1e-5 texel of a 256-wide texture is
/// 4e-8 in s, less than f32's ulp at s = 1). A coordinate that is 0 at all three corners is
/// exactly 0 in any arithmetic: no decision.
pub fn near_wrap(value: f64, corners: [f64; 3], n: usize, margin: f64) -> bool {
    if n <= 1 || corners == [0.0; 3] {
        return false;
    }
    let size = corners.iter().fold(1.0f64, |m, c| m.max(c.abs()));
    !((value - value.round()).abs() >= margin * size)
}

impl Oracle<'_> {
    /// (s, t) at the point `x` of primitive `prim`, whose material has texture `k`:
    /// interpolated with the barycentrics of `x` (the hit point, moved if `with_rounding` moved
    /// it) on a triangle with coordinates, (0, 0) anywhere else. Flags a coordinate close to a
    /// whole number, where the lookup jumps ([`near_wrap`]).
    pub(super) fn texture_coords(
        &self,
        prim: usize,
        x: DVec3,
        k: usize,
        check: &mut Check,
    ) -> [f64; 2] {
        let Some(corners) = self.texcoords.get(prim) else {
            return [0.0, 0.0];
        };
        let (b1, b2) = self.triangles[prim].barycentric(x);
        let b0 = 1.0 - b1 - b2;
        let sizes = [self.textures[k].width, self.textures[k].height];
        [0, 1].map(|a| {
            let c = corners.map(|st| st[a]);
            let value = b0 * c[0] + b1 * c[1] + b2 * c[2];
            if near_wrap(value, c, sizes[a], DECISION_MARGIN) {
                check.flag(TEXTURE_WRAP);
            }
            value
        })
    }
}
