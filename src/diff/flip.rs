//! NVIDIA's FLIP (LDR-FLIP, through the `nv-flip` crate), pooled over a region.
//!
//! FLIP compares two 8-bit sRGB images as a viewer sees them at 67 pixels per degree (a 0.7 m
//! wide 4K monitor seen from 0.7 m). Both images are taken as they are displayed: 8-bit files by
//! their bytes, float values clamped to [0, 1] and rounded to 8 bits without a gamma curve (as
//! raywave's clamp tone map writes its PNGs), so a render's PNG and its PFM give the same FLIP.
//! FLIP filters the whole image (its spatial filters see pixels outside the region); the
//! per-pixel errors are then averaged over the region's compared pixels.

use super::{FlipFigures, Image, Region, to_byte};

fn bytes(img: &Image) -> Vec<u8> {
    img.film
        .pixels
        .iter()
        .flat_map(|p| p.to_array().map(to_byte))
        .collect()
}

/// FLIP of A against the reference B: the figures over the region, and the per-pixel map
/// (NaN outside the region and where a value is not finite).
pub(super) fn flip(a: &Image, b: &Image, region: &Region) -> (FlipFigures, Vec<f32>) {
    let (w, h) = (a.film.width, a.film.height);
    let reference = nv_flip::FlipImageRgb8::with_data(w, h, &bytes(b));
    let test = nv_flip::FlipImageRgb8::with_data(w, h, &bytes(a));
    let errors = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec();
    let mut sum = 0f64;
    let mut max = 0f64;
    let mut n = 0u64;
    let map: Vec<f32> = errors
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            let used =
                region.inside[i] && a.film.pixels[i].is_finite() && b.film.pixels[i].is_finite();
            if used {
                sum += e as f64;
                max = max.max(e as f64);
                n += 1;
                e
            } else {
                f32::NAN
            }
        })
        .collect();
    (
        FlipFigures {
            mean: sum / n.max(1) as f64,
            max,
            pixels_per_degree: nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        },
        map,
    )
}
