//! A film's files: PNG and PPM after tone mapping, PFM and EXR linear, the one table of image
//! formats by extension, and the atomic writer every command's files go through
//! (`output::write`: each file whole or not at all).

use crate::output::{OutputPlan, Target, target, write_output};
use crate::render::film::{Film, ToneMap};
use anyhow::{Context, Result, bail};
use glam::Vec3;
use std::io::Write;
use std::path::Path;

impl Film {
    /// 8-bit RGB after tone mapping.
    pub fn to_rgb8(&self, tone: ToneMap) -> image::RgbImage {
        let mut img = image::RgbImage::new(self.width, self.height);
        for (px, c) in img.pixels_mut().zip(&self.pixels) {
            let c = match tone {
                ToneMap::Clamp => *c,
                ToneMap::Exp => Vec3::ONE - (-3.0 * *c).exp(),
            };
            *px = image::Rgb(c.to_array().map(to_byte));
        }
        img
    }

    /// Reads a colour PFM as written by `write_hdr` (little-endian, rows bottom to top).
    pub fn read_pfm(path: &Path) -> Result<Film> {
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        let bad = || anyhow::anyhow!("{}: not a little-endian colour PFM", path.display());
        // Header: "PF", width height, scale; each ends at a newline. Then the floats.
        let mut parts = bytes.splitn(4, |&b| b == b'\n');
        let mut field = || -> Result<&str> {
            let part = parts.next().ok_or_else(bad)?;
            Ok(std::str::from_utf8(part).map_err(|_| bad())?.trim())
        };
        let (magic, dims, scale) = (field()?, field()?, field()?);
        let dims: Vec<u32> = dims
            .split_whitespace()
            .filter_map(|t| t.parse().ok())
            .collect();
        let scale: f32 = scale.parse().map_err(|_| bad())?;
        let floats = parts.next().ok_or_else(bad)?;
        if magic != "PF" || dims.len() != 2 || scale >= 0.0 {
            return Err(bad());
        }
        let (width, height) = (dims[0], dims[1]);
        // A zero dimension would make the row split below panic ("chunk size must be
        // non-zero"); an empty image is not a PFM this program writes.
        let expected = (width as u64) * (height as u64) * 12;
        if width == 0 || height == 0 || floats.len() as u64 != expected {
            return Err(bad());
        }
        // Rows were stored bottom to top.
        let pixels = (floats.chunks_exact(12 * width as usize).rev())
            .flat_map(|row| row.chunks_exact(12))
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
                Vec3::new(f(0), f(4), f(8))
            })
            .collect();
        Ok(Film {
            width,
            height,
            pixels,
        })
    }

    /// Writes linear floats: `.pfm` (portable float map) or `.exr`; PFM to standard output
    /// (`-`), a device or a FIFO whose name has neither extension.
    pub fn write_hdr(&self, path: &Path) -> Result<()> {
        match hdr_format(path)? {
            HdrFormat::Pfm => write_output(path, |w| {
                write!(w, "PF\n{} {}\n-1.0\n", self.width, self.height)?;
                // PFM stores rows bottom to top, little-endian (the negative scale says so).
                let rows = self.pixels.chunks(self.width as usize).rev();
                for x in rows.flatten().flat_map(|c| c.to_array()) {
                    w.write_all(&x.to_le_bytes())?;
                }
                Ok(())
            }),
            HdrFormat::Exr => {
                if target(path).is_stream() {
                    // EXR seeks back to its offset table: a pipe needs the file in memory.
                    let mut bytes = std::io::Cursor::new(Vec::new());
                    self.write_exr(&mut bytes)?;
                    write_output(path, |w| Ok(w.write_all(bytes.get_ref())?))
                } else {
                    write_output(path, |w| self.write_exr(w))
                }
            }
        }
    }

    /// Encodes EXR block by block from the film itself: no copy of the image. (The `image`
    /// crate's encoder reads from its own buffer, which cost two full copies here.)
    fn write_exr(&self, w: &mut (impl Write + std::io::Seek)) -> Result<()> {
        use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
        let (width, height) = (self.width as usize, self.height as usize);
        Image::from_channels(
            (width, height),
            SpecificChannels::rgb(|pixel: Vec2<usize>| {
                let c = self.pixels[pixel.flat_index_for_size(Vec2(width, height))];
                (c.x, c.y, c.z)
            }),
        )
        .write()
        .to_buffered(w)
        .map_err(|e| anyhow::anyhow!("{e}"))
    }
}

/// The 8-bit value a channel is shown as: clamped to [0, 1], ×255, rounded (raywave's clamp
/// tone map; an 8-bit file's own bytes come back unchanged).
pub fn to_byte(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// An 8-bit image format raywave writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LdrFormat {
    /// PNG, through the `image` crate.
    Png,
    /// Binary PPM (`P6`). Written here rather than by the `image` crate, whose PNM encoder
    /// wrote a `P7` PAM header, which PPM readers reject.
    Ppm,
}

/// A linear float format raywave writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HdrFormat {
    /// Portable float map, written here.
    Pfm,
    /// OpenEXR, through the `exr` crate.
    Exr,
}

/// An image format raywave writes, and what `-o FILE` makes of it: an 8-bit image, or (for
/// `.pfm` and `.exr`) only the linear floats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// A tone-mapped 8-bit image.
    Ldr(LdrFormat),
    /// Linear floats, and no 8-bit image beside them.
    Linear(HdrFormat),
}

/// Every image format raywave writes, by its file extension (lower case): the one table that
/// `-o`, `--hdr` and every figure consult.
const FORMATS: [(&str, OutputFormat); 4] = [
    ("png", OutputFormat::Ldr(LdrFormat::Png)),
    ("ppm", OutputFormat::Ldr(LdrFormat::Ppm)),
    ("pfm", OutputFormat::Linear(HdrFormat::Pfm)),
    ("exr", OutputFormat::Linear(HdrFormat::Exr)),
];

/// What `pick` makes of the format `path`'s extension names; for a path without one to go by
/// (standard output, an existing device or FIFO), `stream`, a format that streams; else an
/// error saying what was `expected`.
fn format_for<T>(
    path: &Path,
    pick: impl Fn(OutputFormat) -> Option<T>,
    stream: T,
    expected: &str,
) -> Result<T> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let format = FORMATS.iter().find(|(e, _)| Some(*e) == ext.as_deref());
    match format.and_then(|&(_, f)| pick(f)) {
        Some(f) => Ok(f),
        None if !matches!(target(path), Target::Regular(_)) => Ok(stream),
        None => bail!("cannot write {}: expected {expected}", path.display()),
    }
}

/// The 8-bit format for an output path, or an error naming what is accepted.
pub fn ldr_format(path: &Path) -> Result<LdrFormat> {
    let pick = |f| match f {
        OutputFormat::Ldr(f) => Some(f),
        OutputFormat::Linear(_) => None,
    };
    let expected = "an output file ending in .png or .ppm (use --hdr for .pfm or .exr)";
    format_for(path, pick, LdrFormat::Png, expected)
}

/// The format of an `-o` path, or an error naming the extensions accepted.
pub fn output_format(path: &Path) -> Result<OutputFormat> {
    let expected =
        "an output file ending in .png or .ppm (8-bit), or .pfm or .exr (linear floats only)";
    format_for(path, Some, OutputFormat::Ldr(LdrFormat::Png), expected)
}

/// Encodes an 8-bit image as PNG into `w`: the one PNG encoder of every output (files, figures
/// and the viewer's levels), streaming, so a large image is not held twice.
pub fn write_png(img: &image::RgbImage, w: &mut (impl Write + std::io::Seek)) -> Result<()> {
    img.write_to(w, image::ImageFormat::Png)?;
    Ok(())
}

/// An 8-bit image as PNG bytes (`write_png` into memory), for the viewer's replies.
pub fn png_bytes(img: &image::RgbImage) -> Result<Vec<u8>> {
    let mut out = std::io::Cursor::new(Vec::new());
    write_png(img, &mut out)?;
    Ok(out.into_inner())
}

/// Writes an 8-bit image whole or not at all; the format follows the extension (png, ppm).
pub fn write_rgb8(img: &image::RgbImage, path: &Path) -> Result<()> {
    match ldr_format(path)? {
        LdrFormat::Png => write_output(path, |w| write_png(img, w)),
        LdrFormat::Ppm => write_output(path, |w| {
            // Netpbm's binary pixmap: magic, width, height, maxval, one whitespace byte, then
            // the RGB bytes row by row from the top.
            write!(w, "P6\n{} {}\n255\n", img.width(), img.height())?;
            w.write_all(img.as_raw())?;
            Ok(())
        }),
    }
}

/// The float format for an `--hdr` path, or an error naming the extensions accepted.
pub fn hdr_format(path: &Path) -> Result<HdrFormat> {
    let pick = |f| match f {
        OutputFormat::Linear(f) => Some(f),
        OutputFormat::Ldr(_) => None,
    };
    let expected = "an --hdr file ending in .pfm or .exr";
    format_for(path, pick, HdrFormat::Pfm, expected)
}

/// Checks, before a long render, that `path` can be written (as [`OutputPlan::check`] checks
/// an output): a directory named like an image is otherwise found out only by the final
/// rename, after the whole render.
pub fn check_output_dir(path: &Path) -> Result<()> {
    OutputPlan::new().output("", path).check()
}

/// Writes `value` as pretty JSON with a final newline, through [`write_output`].
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    write_output(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        Ok(writeln!(w)?)
    })
}
