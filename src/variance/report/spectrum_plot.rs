//! `spectrum_N<n>.png`: the radially averaged power spectrum of each sampler's error at one
//! budget, over the whole image and over the penumbra, one curve per sampler with its 95%
//! interval as a band, the low band (|f| ≤ 1/8) marked. A blue-noise error is a curve that
//! starts low and rises; white noise is flat.

use crate::output::image_file::write_rgb8;
use crate::render::sampling::LightSampler;
use crate::variance::figures::perceived::Perceived;
use crate::variance::figures::spectrum::{LOW_BAND, RINGS, ring_frequency};
use crate::variance::report::plot::{PALETTE, canvas, line, log_range, with_ends};
use crate::variance::{Region, StudyResult};
use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The regions a spectrum is drawn for.
pub(crate) const REGIONS: [Region; 2] = [Region::Whole, Region::Penumbra];

/// The file of budget `n`.
pub(crate) fn file_name(n: u32) -> String {
    format!("spectrum_N{n}.png")
}

/// Writes one `spectrum_N<n>.png` per budget into `dir`; returns the paths written.
pub(crate) fn spectra(result: &StudyResult, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for &n in &result.config.budgets {
        let img = canvas((1400, 560), |root| {
            for (area, region) in root.split_evenly((1, 2)).iter().zip(REGIONS) {
                panel(area, result, n, region)?;
            }
            Ok(())
        })?;
        let path = dir.join(file_name(n));
        write_rgb8(&img, &path)?;
        written.push(path);
    }
    Ok(written)
}

/// One curve of a spectrum panel: its label, colour, whether dashed, and its figures.
struct Curve<'a> {
    label: String,
    colour: RGBColor,
    dashed: bool,
    perceived: &'a Perceived,
}

/// One panel: every sampler's spectrum at budget `n` over `region`.
fn panel(
    area: &DrawingArea<BitMapBackend, Shift>,
    result: &StudyResult,
    n: u32,
    region: Region,
) -> Result<()> {
    let title = format!(
        "{}: error spectrum at N = {n} ({} px)",
        region.name(),
        result.facts.region_pixels[region as usize]
    );
    let curves: Vec<Curve> = result
        .config
        .samplers
        .iter()
        .enumerate()
        .filter_map(|(k, sampler)| {
            let row = result.rows.iter().find(|r| {
                r.n == n
                    && r.region == region
                    && r.sampler == sampler.name()
                    && !r.perceived.spectrum.is_empty()
            })?;
            let ratio = row
                .perceived
                .low_band_vs_random
                .map(|v| format!(" (low band {v:.2}× random's)"))
                .unwrap_or_default();
            Some(Curve {
                label: format!("{}{ratio}", sampler.name()),
                colour: PALETTE[k % PALETTE.len()],
                // The lab's strategy draws random's points for N > 1: dashed, so both show.
                dashed: *sampler == LightSampler::Lab,
                perceived: &row.perceived,
            })
        })
        .collect();
    draw_curves(area, &title, &curves)
}

/// The viewer's comparison: the spectra of its two samplers' errors over the whole image, with
/// their 95% bands, as an image of `width` × `height`.
pub(crate) fn comparison_image(
    sides: &[(LightSampler, &Perceived)],
    n: u32,
    (width, height): (u32, u32),
) -> Result<image::RgbImage> {
    canvas((width, height), |root| {
        let curves: Vec<Curve> = sides
            .iter()
            .enumerate()
            .map(|(k, (sampler, p))| Curve {
                label: format!(
                    "{} {}: low band's share {:.2}",
                    ["A", "B"][k % 2],
                    sampler.name(),
                    p.low_band_share
                ),
                colour: PALETTE[k % PALETTE.len()],
                dashed: false,
                perceived: p,
            })
            .collect();
        draw_curves(root, &format!("error spectra at N = {n}"), &curves)
    })
}

/// Draws `curves` (radially averaged power against frequency, log power) with their bands and
/// the low band's edge.
fn draw_curves(
    area: &DrawingArea<BitMapBackend, Shift>,
    title: &str,
    curves: &[Curve],
) -> Result<()> {
    let err = |e| anyhow!("plot: {e}");
    let values = curves.iter().flat_map(|c| {
        let p = c.perceived;
        (p.spectrum.iter().copied())
            .zip(p.spectrum_interval.iter().copied())
            .flat_map(with_ends)
    });
    let (y_lo, y_hi) = log_range(values, 1.5, (1e-8, 1.0));
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..0.5f64, (y_lo..y_hi).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("frequency |f|, cycles per pixel")
        .y_desc("error power (white noise: flat at its variance)")
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(LOW_BAND, y_lo), (LOW_BAND, y_hi)],
            BLACK.mix(0.4).stroke_width(1),
        )))
        .map_err(err)?;
    for curve in curves {
        let (colour, p) = (curve.colour, curve.perceived);
        let pts: Vec<(f64, f64)> = (0..RINGS.min(p.spectrum.len()))
            .filter(|&i| p.spectrum[i].is_finite() && p.spectrum[i] > 0.0)
            .map(|i| (ring_frequency(i), p.spectrum[i]))
            .collect();
        // The 95% band: up along the high ends, back along the low ones.
        let ends = |i: usize| p.spectrum_interval.get(i).copied().flatten();
        let mut band: Vec<(f64, f64)> = (0..RINGS)
            .filter_map(|i| ends(i).map(|[_, b]| (ring_frequency(i), b.min(y_hi))))
            .collect();
        band.extend(
            (0..RINGS)
                .rev()
                .filter_map(|i| ends(i).map(|[a, _]| (ring_frequency(i), a.max(y_lo)))),
        );
        if band.len() > 2 {
            chart
                .draw_series(std::iter::once(Polygon::new(
                    band,
                    colour.mix(0.15).filled(),
                )))
                .map_err(err)?;
        }
        line(&mut chart, pts, colour, curve.dashed, curve.label.clone())?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    Ok(())
}
