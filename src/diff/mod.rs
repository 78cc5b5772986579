//! Comparing two images (`raywave diff A B`, `raywave render --mse-reference REF`): error
//! figures per channel and overall, over the whole image or a mask, and a false-colour map of
//! the error per pixel. A is the image checked, B the reference.
//!
//! ```text
//! for each pixel p in the region (the mask, or every pixel), both finite, each channel c:
//!     d = a[p][c] − b[p][c]
//!     MSE     = mean of d²
//!     relMSE  = mean of d² / (b + 0.01)²      pbrt-v4's MRSE (Image::MRSE)
//!     max     = max |d|, and the first (x, y) where it occurs (row-major)
//!     PSNR    = 10·log10(1 / MSE) dB          peak 1: 8- and 16-bit data read as [0, 1]
//! "all" pools the three channels: its MSE and relMSE are the means of the channels'.
//! FLIP (feature `flip`): NVIDIA's LDR-FLIP of the 8-bit images, mean and max over the region.
//! ```
//!
//! The figures are exact functions of the two files (sums in f64 over every pixel compared),
//! not estimates: they carry no sampling error. The images themselves may be Monte Carlo
//! renders, so an error against a noisy reference includes the reference's own noise.

pub(crate) mod read;
pub mod text;

#[cfg(feature = "flip")]
mod flip;

pub use crate::output::image_file::to_byte;
pub use read::read_image;

use crate::output::false_colour::{self, Scale};
use crate::render::film::Film;
use anyhow::{Result, bail};
use glam::Vec3;
use serde::Serialize;

/// relMSE's denominator is (b + RELATIVE_EPSILON)², as in pbrt-v4.
const RELATIVE_EPSILON: f64 = 0.01;

/// The peak value PSNR is taken against: 8- and 16-bit images are read as [0, 1].
pub const PSNR_PEAK: f64 = 1.0;

/// The exit code when the chosen figure is past `--fail-above` (as `bench --compare`'s).
pub const EXIT_FAILED: u8 = 3;

/// How an image's values were stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Encoding {
    /// 8 bits per channel, read as v / 255.
    #[serde(rename = "8-bit")]
    Bits8,
    /// 16 bits per channel, read as v / 65535.
    #[serde(rename = "16-bit")]
    Bits16,
    /// Floats, read as they are.
    #[serde(rename = "float")]
    Float,
}

impl Encoding {
    /// "8-bit", "16-bit" or "float".
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Bits8 => "8-bit",
            Encoding::Bits16 => "16-bit",
            Encoding::Float => "float",
        }
    }
}

/// An image to compare: its values as a [`Film`] (the one linear image type, which both engines
/// fill), and how they were stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// The RGB values, row-major from the top-left.
    pub film: Film,
    /// How the values were stored.
    pub encoding: Encoding,
    /// The file format ("PNG", "PPM", "PFM", "EXR").
    pub format: &'static str,
}

/// A compared file, as reports name it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FileInfo {
    /// The path as given.
    pub path: String,
    /// "PNG", "PPM", "PFM", "EXR", or what the values came from.
    pub format: &'static str,
    /// How the values were stored.
    pub encoding: Encoding,
    /// Width and height.
    pub size: [u32; 2],
}

impl FileInfo {
    /// The file at `path`, read as `img`.
    pub fn of(path: &std::path::Path, img: &Image) -> FileInfo {
        FileInfo {
            path: path.display().to_string(),
            format: img.format,
            encoding: img.encoding,
            size: [img.film.width, img.film.height],
        }
    }

    /// "path (PNG, 8-bit, 64×64)".
    pub fn describe(&self) -> String {
        format!(
            "{} ({}, {}, {}×{})",
            self.path,
            self.format,
            self.encoding.name(),
            self.size[0],
            self.size[1]
        )
    }
}

/// The error figure `--metric` chooses (for `--fail-above` and the false-colour map).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// Mean squared error.
    Mse,
    /// pbrt-v4's relative MSE.
    Relmse,
    /// Largest absolute difference.
    Max,
    /// Peak signal-to-noise ratio (fails when it falls *below* the threshold).
    Psnr,
    /// NVIDIA's FLIP, mean over the region.
    Flip,
}

impl Metric {
    /// True when `value` is worse than `threshold`: above it, or for PSNR below it. A NaN
    /// value fails.
    pub fn fails(self, value: f64, threshold: f64) -> bool {
        value.is_nan()
            || match self {
                Metric::Psnr => value < threshold,
                _ => value > threshold,
            }
    }
}

/// Which pixels are compared, and what they are called.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// "whole image", "penumbra", or the mask file's name.
    pub name: String,
    /// One flag per pixel, row-major.
    pub inside: Vec<bool>,
}

impl Region {
    /// Every pixel of a `width × height` image.
    pub fn whole(width: u32, height: u32) -> Region {
        Region {
            name: "whole image".into(),
            inside: vec![true; width as usize * height as usize],
        }
    }

    /// The pixels where a mask image is non-zero in some channel.
    pub fn from_mask_image(mask: &Image, name: String) -> Region {
        Region {
            name,
            inside: mask.film.pixels.iter().map(|&p| p != Vec3::ZERO).collect(),
        }
    }

    /// How many pixels are inside.
    pub fn count(&self) -> u64 {
        self.inside.iter().filter(|&&b| b).count() as u64
    }
}

/// One channel's figures (or all three pooled).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Figures {
    /// Mean of (a − b)².
    pub mse: f64,
    /// Mean of (a − b)² / (b + 0.01)².
    pub relmse: f64,
    /// Largest |a − b|.
    pub max_abs: f64,
    /// Where it first occurs, (x, y) from the top-left.
    pub max_at: [u32; 2],
    /// 10·log10(1 / MSE) in dB; infinite (`null` in JSON) for identical images.
    pub psnr: f64,
}

/// FLIP pooled over the region.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlipFigures {
    /// Mean per-pixel FLIP error, in [0, 1].
    pub mean: f64,
    /// Largest per-pixel FLIP error.
    pub max: f64,
    /// Pixels per degree of visual angle assumed.
    pub pixels_per_degree: f32,
}

/// Everything a comparison measures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The region's name.
    pub region: String,
    /// Pixels in the region.
    pub region_pixels: u64,
    /// Pixels of the region left out because a channel of A or B is not finite.
    pub non_finite_pixels: u64,
    /// Pixels compared: in the region, finite in both.
    pub pixels_compared: u64,
    /// R, G and B.
    pub channels: [Figures; 3],
    /// The three channels pooled.
    pub all: Figures,
    /// The largest finite value in B (PSNR's peak of 1 fits B only when this is ≤ 1).
    pub b_max: f64,
    /// FLIP, when asked for.
    pub flip: Option<FlipFigures>,
}

impl Comparison {
    /// The figure `metric` names (overall).
    pub fn value(&self, metric: Metric) -> Option<f64> {
        match metric {
            Metric::Mse => Some(self.all.mse),
            Metric::Relmse => Some(self.all.relmse),
            Metric::Max => Some(self.all.max_abs),
            Metric::Psnr => Some(self.all.psnr),
            Metric::Flip => self.flip.map(|f| f.mean),
        }
    }
}

/// Refuses two images of different sizes, naming both files.
pub fn check_same_size(a: &Image, a_name: &str, b: &Image, b_name: &str) -> Result<()> {
    let (a, b) = (&a.film, &b.film);
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "{a_name} is {}×{} but {b_name} is {}×{}: expected two images of the same size",
            a.width,
            a.height,
            b.width,
            b.height
        );
    }
    Ok(())
}

/// PSNR in dB of an MSE against [`PSNR_PEAK`]: infinite for 0.
pub fn psnr(mse: f64) -> f64 {
    10.0 * (PSNR_PEAK * PSNR_PEAK / mse).log10()
}

/// Compares A with the reference B over `region`. The images must have the same size and the
/// region must hold one flag per pixel with some pixel compared (errors otherwise).
pub fn compare(a: &Image, b: &Image, region: &Region) -> Result<Comparison> {
    let (a, b) = (&a.film, &b.film);
    let n_pixels = a.pixels.len();
    if b.pixels.len() != n_pixels || region.inside.len() != n_pixels {
        bail!("compare: images and region of different sizes");
    }
    let mut sum_se = [0f64; 3];
    let mut sum_rse = [0f64; 3];
    let mut max = [(-1f64, [0u32; 2]); 3];
    let mut all_max = (-1f64, [0u32; 2]);
    let mut compared = 0u64;
    let mut non_finite = 0u64;
    let mut b_max = f64::NEG_INFINITY;
    for (i, ((pa, pb), &inside)) in a
        .pixels
        .iter()
        .zip(&b.pixels)
        .zip(&region.inside)
        .enumerate()
    {
        if !inside {
            continue;
        }
        if !pa.is_finite() || !pb.is_finite() {
            non_finite += 1;
            continue;
        }
        compared += 1;
        let at = [(i % a.width as usize) as u32, (i / a.width as usize) as u32];
        for c in 0..3 {
            let (va, vb) = (pa[c] as f64, pb[c] as f64);
            let d = va - vb;
            sum_se[c] += d * d;
            sum_rse[c] += d * d / ((vb + RELATIVE_EPSILON) * (vb + RELATIVE_EPSILON));
            if d.abs() > max[c].0 {
                max[c] = (d.abs(), at);
            }
            if d.abs() > all_max.0 {
                all_max = (d.abs(), at);
            }
            b_max = b_max.max(vb);
        }
    }
    if compared == 0 {
        bail!(
            "no pixel to compare: the region ({}) holds {} pixel(s), {non_finite} of them not finite in A or B",
            region.name,
            region.count()
        );
    }
    let n = compared as f64;
    let figures = |se: f64, rse: f64, (max_abs, max_at): (f64, [u32; 2]), k: f64| Figures {
        mse: se / (n * k),
        relmse: rse / (n * k),
        max_abs,
        max_at,
        psnr: psnr(se / (n * k)),
    };
    let channels = [0, 1, 2].map(|c| figures(sum_se[c], sum_rse[c], max[c], 1.0));
    let all = figures(sum_se.iter().sum(), sum_rse.iter().sum(), all_max, 3.0);
    Ok(Comparison {
        width: a.width,
        height: a.height,
        region: region.name.clone(),
        region_pixels: region.count(),
        non_finite_pixels: non_finite,
        pixels_compared: compared,
        channels,
        all,
        b_max,
        flip: None,
    })
}

/// True when raywave was built with FLIP (the `flip` feature).
pub const FLIP_AVAILABLE: bool = cfg!(feature = "flip");

/// Adds FLIP to a comparison; its per-pixel map is returned for the figure. An error when
/// raywave was built without the `flip` feature.
pub fn add_flip(
    comparison: &mut Comparison,
    a: &Image,
    b: &Image,
    region: &Region,
) -> Result<Vec<f32>> {
    #[cfg(feature = "flip")]
    {
        let (figures, map) = flip::flip(a, b, region);
        comparison.flip = Some(figures);
        Ok(map)
    }
    #[cfg(not(feature = "flip"))]
    {
        let _ = (comparison, a, b, region);
        bail!(
            "FLIP needs raywave built with the `flip` feature (on by default; it needs a C++ compiler)"
        )
    }
}

/// The per-pixel error `metric` maps: the mean over channels of (a − b)² (MSE and PSNR) or of
/// the relative squared error, or the largest |a − b| over channels; NaN outside the region
/// and where a value is not finite. FLIP's map comes from [`add_flip`].
pub fn pixel_errors(a: &Image, b: &Image, region: &Region, metric: Metric) -> Vec<f32> {
    a.film
        .pixels
        .iter()
        .zip(&b.film.pixels)
        .zip(&region.inside)
        .map(|((pa, pb), &inside)| {
            if !inside || !pa.is_finite() || !pb.is_finite() {
                return f32::NAN;
            }
            let d = |c: usize| pa[c] as f64 - pb[c] as f64;
            let r = |c: usize| pb[c] as f64 + RELATIVE_EPSILON;
            let v = match metric {
                Metric::Max => (0..3).map(|c| d(c).abs()).fold(0.0, f64::max),
                Metric::Relmse => (0..3).map(|c| d(c) * d(c) / (r(c) * r(c))).sum::<f64>() / 3.0,
                _ => (0..3).map(|c| d(c) * d(c)).sum::<f64>() / 3.0,
            };
            v as f32
        })
        .collect()
}

/// The longest side of an error figure, in pixels.
const MAX_FIGURE_SIDE: u64 = 16384;

/// The false-colour figure of a per-pixel error map: a log scale for the squared errors, a
/// linear one for |a − b| and FLIP; NaN (outside the region) is drawn darkest.
pub fn figure(
    errors: &[f32],
    width: u32,
    height: u32,
    metric: Metric,
    title: &str,
) -> Result<image::RgbImage> {
    // The figure upscales the shorter side to MIN_SIDE: a long thin image would become a huge
    // figure (a 16384×1 one, 4 million pixels wide).
    let factor = false_colour::MIN_SIDE
        .div_ceil(width.min(height).max(1))
        .max(1) as u64;
    if width.max(height) as u64 * factor > MAX_FIGURE_SIDE {
        bail!(
            "a {width}×{height} image is too elongated for an error figure: upscaled to {} pixels on its shorter side, its longer one would pass {MAX_FIGURE_SIDE}",
            false_colour::MIN_SIDE
        );
    }
    let (label, log) = match metric {
        Metric::Mse | Metric::Psnr => ("(a − b)², mean of R G B", true),
        Metric::Relmse => ("(a − b)² / (b + 0.01)², mean of R G B", true),
        Metric::Max => ("|a − b|, largest of R G B", false),
        Metric::Flip => ("FLIP error", false),
    };
    let scale = Scale::from_values(errors, log)
        .or_else(|| Scale::from_values(errors, false))
        .unwrap_or(Scale {
            low: 0.0,
            high: 1.0,
            log: false,
        });
    false_colour::figure(errors, width, height, &scale, title, label)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: Vec<[f32; 3]>, width: u32) -> Image {
        Image {
            film: Film {
                width,
                height: pixels.len() as u32 / width,
                pixels: pixels.into_iter().map(Vec3::from_array).collect(),
            },
            encoding: Encoding::Float,
            format: "PFM",
        }
    }

    #[test]
    fn figures_by_hand() {
        // Two pixels; differences (0.5, 0, 0) and (0, 0, −1); B is 0 except 1 in pixel 1's B.
        let a = image(vec![[0.5, 0.0, 0.0], [0.0, 0.0, 0.0]], 2);
        let b = image(vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], 2);
        let c = compare(&a, &b, &Region::whole(2, 1)).unwrap();
        assert_eq!(c.channels[0].mse, 0.125);
        assert_eq!(c.channels[1].mse, 0.0);
        assert_eq!(c.channels[2].mse, 0.5);
        assert!((c.all.mse - 0.625 / 3.0).abs() < 1e-15);
        let rel_r = 0.25 / (0.01 * 0.01) / 2.0;
        assert!((c.channels[0].relmse - rel_r).abs() < 1e-9 * rel_r);
        assert_eq!(c.all.max_abs, 1.0);
        assert_eq!(c.all.max_at, [1, 0]);
        assert!((c.channels[2].psnr - 10.0 * 2f64.log10()).abs() < 1e-12);
        assert_eq!(c.channels[1].psnr, f64::INFINITY);
    }

    #[test]
    fn non_finite_pixels_are_left_out_and_counted() {
        let a = image(vec![[f32::NAN, 0.0, 0.0], [0.5, 0.5, 0.5]], 2);
        let b = image(vec![[0.0; 3], [0.0; 3]], 2);
        let c = compare(&a, &b, &Region::whole(2, 1)).unwrap();
        assert_eq!((c.pixels_compared, c.non_finite_pixels), (1, 1));
        assert_eq!(c.all.mse, 0.25);
        let only_nan = Region {
            name: "m".into(),
            inside: vec![true, false],
        };
        assert!(compare(&a, &b, &only_nan).is_err());
    }

    #[test]
    fn psnr_fails_below_and_the_others_above() {
        assert!(Metric::Psnr.fails(29.0, 30.0));
        assert!(!Metric::Psnr.fails(f64::INFINITY, 30.0));
        assert!(Metric::Mse.fails(0.2, 0.1));
        assert!(!Metric::Mse.fails(0.1, 0.1));
        assert!(Metric::Mse.fails(f64::NAN, 0.1));
    }

    #[test]
    fn bytes_round_trip() {
        for k in 0..=255u8 {
            assert_eq!(to_byte(k as f32 / 255.0), k);
        }
    }
}
