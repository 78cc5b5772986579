//! The contact sheet: one render of every sampler at every budget on one labelled PNG, so the
//! noise of each (sampler, N) is seen side by side.
//!
//! ```text
//! title
//!             N = 1     N = 4     N = 16
//! random     [image]   [image]   [image]
//! stratified [image]   [image]   [image]
//! ```
//!
//! Images smaller than [`MIN_TILE`] on their shorter side are enlarged by a whole factor
//! (nearest neighbour: every pixel stays a visible square).

use crate::output::false_colour::register_font;
use crate::output::image_file::write_rgb8;
use crate::render::sampling::LightSampler;
use crate::variance::StudyResult;
use anyhow::{Result, anyhow};
use image::RgbImage;
use plotters::prelude::*;
use std::path::Path;

/// Tiles are enlarged by a whole factor until their shorter side reaches this many pixels.
pub const MIN_TILE: u32 = 128;
/// Width of the row labels on the left.
const LABEL_WIDTH: u32 = 110;
/// Height of the title.
pub const TITLE_HEIGHT: u32 = 34;
/// Height of the column headers.
const HEADER_HEIGHT: u32 = 24;
/// Space between and around tiles.
pub(crate) const GAP: u32 = 8;

/// The sheet of `images[row][col]` (all of one size), `rows` and `cols` labelling them.
pub fn contact_sheet(
    title: &str,
    rows: &[String],
    cols: &[String],
    images: &[Vec<&RgbImage>],
) -> Result<RgbImage> {
    let first = images
        .first()
        .and_then(|r| r.first())
        .ok_or_else(|| anyhow!("contact sheet: no images"))?;
    let (w, h) = first.dimensions();
    if images.len() != rows.len()
        || images
            .iter()
            .any(|r| r.len() != cols.len() || r.iter().any(|i| i.dimensions() != (w, h)))
        || w == 0
        || h == 0
    {
        return Err(anyhow!(
            "contact sheet: expected {} rows of {} images of {w}×{h}",
            rows.len(),
            cols.len()
        ));
    }
    register_font();
    let factor = MIN_TILE.div_ceil(w.min(h)).max(1);
    let (tw, th) = (w * factor, h * factor);
    // The left edge of column `c` and the top of row `r`; one past the last, the sheet's size.
    let col_x = |c: usize| LABEL_WIDTH + c as u32 * (tw + GAP) + GAP;
    let row_y = |r: usize| TITLE_HEIGHT + HEADER_HEIGHT + r as u32 * (th + GAP) + GAP;
    let (sw, sh) = (col_x(cols.len()), row_y(rows.len()));
    let mut buffer = vec![255u8; (sw as usize) * (sh as usize) * 3];
    for (r, row) in images.iter().enumerate() {
        for (c, img) in row.iter().enumerate() {
            let (x0, y0) = (col_x(c), row_y(r));
            for y in 0..th {
                for x in 0..tw {
                    let px = img.get_pixel(x / factor, y / factor).0;
                    let i = (((y0 + y) * sw + x0 + x) * 3) as usize;
                    buffer[i..i + 3].copy_from_slice(&px);
                }
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (sw, sh)).into_drawing_area();
        let err = |e| anyhow!("contact sheet: {e}");
        let title_style = ("sans-serif", 18).into_font().color(&BLACK);
        root.draw_text(title, &title_style, (GAP as i32, 8))
            .map_err(err)?;
        let label_style = ("sans-serif", 15).into_font().color(&BLACK);
        for (c, label) in cols.iter().enumerate() {
            root.draw_text(
                label,
                &label_style,
                (col_x(c) as i32, (TITLE_HEIGHT + 4) as i32),
            )
            .map_err(err)?;
        }
        for (r, label) in rows.iter().enumerate() {
            let y = row_y(r) + th / 2;
            root.draw_text(label, &label_style, (GAP as i32, y as i32 - 8))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    RgbImage::from_raw(sw, sh, buffer).ok_or_else(|| anyhow!("contact sheet: buffer size"))
}

/// Writes the study's contact sheet (its warm-up renders, seed 0) to `path`; false when the
/// study kept no renders.
pub fn write(result: &StudyResult, path: &Path) -> Result<bool> {
    let (samplers, budgets) = (&result.config.samplers, &result.config.budgets);
    let thumbnail = |s: &LightSampler, n: &u32| {
        let found = result
            .thumbnails
            .iter()
            .find(|(ts, tn, _)| ts == s && tn == n);
        found.map(|(_, _, img)| img)
    };
    let images: Option<Vec<Vec<&RgbImage>>> = samplers
        .iter()
        .map(|s| budgets.iter().map(|n| thumbnail(s, n)).collect())
        .collect();
    let Some(images) = images.filter(|i| !i.is_empty()) else {
        return Ok(false);
    };
    let title = format!(
        "seed 0, {}×{}: {}",
        result.config.base.width, result.config.base.height, result.scene
    );
    let rows: Vec<String> = samplers.iter().map(|s| s.name().to_string()).collect();
    let cols: Vec<String> = budgets.iter().map(|n| format!("N = {n}")).collect();
    let img = contact_sheet(&title, &rows, &cols, &images)?;
    write_rgb8(&img, path)?;
    Ok(true)
}
