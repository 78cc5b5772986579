//! Loading an image to compare: PNG, PPM (8 or 16 bits per channel), PFM and EXR (floats), as
//! three channels of `f32`. 8- and 16-bit values are divided by 255 or 65535 and not decoded
//! further (no sRGB curve): raywave's own PNGs hold the clamped linear values, the lab's look.
//! Grey images are spread over R, G and B; alpha is dropped.

use super::{Encoding, Image};
use crate::render::film::Film;
use anyhow::{Context, Result, bail};
use glam::Vec3;
use image::{ColorType, ImageFormat, ImageReader};
use std::io::Read;
use std::path::Path;

/// Reads `path` as an image; every error names the file and what was expected.
pub fn read_image(path: &Path) -> Result<Image> {
    let meta =
        std::fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?;
    let kind = meta.file_type();
    if kind.is_dir() {
        bail!(
            "cannot read {}: it is a directory, expected an image file",
            path.display()
        );
    }
    if !kind.is_file() {
        bail!(
            "cannot read {}: expected a regular image file (PNG, PPM, PFM or EXR), found a device, FIFO or socket",
            path.display()
        );
    }
    let mut magic = [0u8; 3];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut magic))
        .with_context(|| format!("cannot read {}", path.display()))?;
    if n >= 3 && magic[0] == b'P' && magic[1] == b'F' && magic[2].is_ascii_whitespace() {
        let film = Film::read_pfm(path)?;
        return Ok(Image::from_film(film, "PFM"));
    }
    let reader = ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .with_context(|| format!("cannot read {}", path.display()))?;
    let name = match reader.format() {
        Some(ImageFormat::Png) => "PNG",
        Some(ImageFormat::Pnm) => "PPM",
        Some(ImageFormat::OpenExr) => "EXR",
        Some(other) => bail!(
            "{}: a {other:?} image, which raywave does not read: expected PNG, PPM, PFM or EXR",
            path.display()
        ),
        None => bail!(
            "{}: not an image raywave reads: expected PNG, PPM, PFM or EXR",
            path.display()
        ),
    };
    let decoded = reader
        .decode()
        .with_context(|| format!("{}: not a readable {name} image", path.display()))?;
    let encoding = match decoded.color() {
        ColorType::L8 | ColorType::La8 | ColorType::Rgb8 | ColorType::Rgba8 => Encoding::Bits8,
        ColorType::L16 | ColorType::La16 | ColorType::Rgb16 | ColorType::Rgba16 => Encoding::Bits16,
        _ => Encoding::Float,
    };
    let (width, height) = (decoded.width(), decoded.height());
    if width == 0 || height == 0 {
        bail!("{}: an empty image ({width}×{height})", path.display());
    }
    let rgb = decoded.into_rgb32f();
    let pixels = rgb
        .as_raw()
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    Ok(Image {
        film: Film {
            width,
            height,
            pixels,
        },
        encoding,
        format: name,
    })
}

impl Image {
    /// A render's linear floats, as a float image named `format`.
    pub fn from_film(film: Film, format: &'static str) -> Image {
        Image {
            film,
            encoding: Encoding::Float,
            format,
        }
    }

    /// An 8-bit image's values divided by 255, as reading its PNG gives them.
    pub fn from_rgb8(img: &image::RgbImage, format: &'static str) -> Image {
        Image {
            film: Film {
                width: img.width(),
                height: img.height(),
                pixels: img
                    .pixels()
                    .map(|p| Vec3::from_array(p.0.map(|v| v as f32 / 255.0)))
                    .collect(),
            },
            encoding: Encoding::Bits8,
            format,
        }
    }
}
