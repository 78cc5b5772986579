//! Pictures of a study: MSE against N on log-log axes (one panel per region, one line per
//! sampler) and per-pixel error heat maps on one shared log scale. The font is embedded
//! (DejaVu Sans, via the `dejavu` crate), so plots need no system fonts.

use super::{Region, StudyResult};
use crate::film::write_atomically;
use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

const PALETTE: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
];

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Failure leaves text undrawn but the plot still valid; the font is a fixed asset.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Draws `mse.png`: three log-log panels (whole, penumbra, lit).
pub fn mse_plot(result: &StudyResult, path: &Path) -> Result<()> {
    register_font();
    let (w, h) = (1500u32, 520u32);
    let mut buffer = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("plot: {e}"))?;
        let panels = root.split_evenly((1, 3));
        let budgets = &result.config.budgets;
        let x_lo = *budgets.iter().min().unwrap_or(&1) as f64 / 1.5;
        let x_hi = *budgets.iter().max().unwrap_or(&256) as f64 * 1.5;
        for (panel, region) in panels.iter().zip(Region::ALL) {
            let rows: Vec<_> = result
                .rows
                .iter()
                .filter(|r| r.region == region && r.stats.mse > 0.0)
                .collect();
            let (y_lo, y_hi) = rows.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
                (lo.min(r.stats.mse), hi.max(r.stats.mse))
            });
            let (y_lo, y_hi) = if rows.is_empty() {
                (1e-6, 1.0)
            } else {
                (y_lo / 2.0, y_hi * 2.0)
            };
            let i = Region::ALL.iter().position(|&r| r == region).unwrap_or(0);
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!("{} ({} px)", region.name(), result.region_pixels[i]),
                    ("sans-serif", 22),
                )
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())
                .map_err(|e| anyhow!("plot: {e}"))?;
            chart
                .configure_mesh()
                .x_desc("light samples N")
                .y_desc("MSE")
                .y_label_formatter(&|y| format!("{y:.0e}"))
                .x_label_formatter(&|x| format!("{x:.0}"))
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(|e| anyhow!("plot: {e}"))?;
            for (k, sampler) in result.config.samplers.iter().enumerate() {
                let colour = PALETTE[k % PALETTE.len()];
                let pts: Vec<(f64, f64)> = rows
                    .iter()
                    .filter(|r| r.sampler == sampler.name())
                    .map(|r| (r.n as f64, r.stats.mse))
                    .collect();
                let slope = result
                    .slopes
                    .iter()
                    .find(|s| s.sampler == sampler.name() && s.region == region)
                    .and_then(|s| s.fit)
                    .map(|f| format!(" (slope {:.2})", f.slope))
                    .unwrap_or_default();
                // The lab's strategy draws random's points for N > 1: dash it so both show.
                let series = if *sampler == crate::sampling::LightSampler::Lab {
                    chart.draw_series(DashedLineSeries::new(
                        pts.clone(),
                        8,
                        6,
                        colour.stroke_width(2),
                    ))
                } else {
                    chart.draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                };
                series
                    .map_err(|e| anyhow!("plot: {e}"))?
                    .label(format!("{}{slope}", sampler.name()))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                    });
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                    .map_err(|e| anyhow!("plot: {e}"))?;
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .draw()
                .map_err(|e| anyhow!("plot: {e}"))?;
        }
        root.present().map_err(|e| anyhow!("plot: {e}"))?;
    }
    let img = image::RgbImage::from_raw(w, h, buffer).context("plot buffer")?;
    write_atomically(path, |out| {
        img.write_to(out, image::ImageFormat::Png)
            .map_err(anyhow::Error::from)
    })
}

/// Writes `heat_<sampler>_N<n>.png` for every sampler (see [`heat_images`]).
pub fn heatmaps(result: &StudyResult, dir: &Path) -> Result<Vec<PathBuf>> {
    let (w, h) = (result.config.base.width, result.config.base.height);
    let maps: Vec<&[f32]> = result.heatmaps.iter().map(|(_, m)| m.as_slice()).collect();
    let Some((images, _)) = heat_images(&maps, w, h) else {
        return Ok(Vec::new());
    };
    let mut written = Vec::new();
    for ((sampler, _), img) in result.heatmaps.iter().zip(images) {
        let path = dir.join(format!(
            "heat_{}_N{}.png",
            sampler.name(),
            result.config.heatmap_n
        ));
        write_atomically(&path, |out| {
            img.write_to(out, image::ImageFormat::Png)
                .map_err(anyhow::Error::from)
        })?;
        written.push(path);
    }
    Ok(written)
}

/// Per-pixel MSE maps (each `w` × `h`) as images on one shared scale, log10 of the error from
/// the 1st to the 99.9th percentile of all maps' positive values (dark = low error, bright =
/// high), so that the maps compare directly; also returns that scale as (lo, hi) in log10.
/// `None` when no map has a positive value.
pub fn heat_images(maps: &[&[f32]], w: u32, h: u32) -> Option<(Vec<image::RgbImage>, [f32; 2])> {
    let mut sorted: Vec<f32> = maps
        .iter()
        .flat_map(|m| m.iter().copied().filter(|v| *v > 0.0))
        .collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(f32::total_cmp);
    // So that a few outliers do not flatten the map.
    let lo = sorted[sorted.len() / 100].max(1e-12).log10();
    let hi = sorted[(sorted.len() * 999 / 1000).min(sorted.len() - 1)]
        .max(1e-12)
        .log10()
        .max(lo + 1e-3);
    let images = maps
        .iter()
        .map(|map| {
            let mut img = image::RgbImage::new(w, h);
            for (px, v) in img.pixels_mut().zip(map.iter()) {
                let t = if *v > 0.0 {
                    ((v.log10() - lo) / (hi - lo)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                *px = image::Rgb(inferno(t));
            }
            img
        })
        .collect();
    Some((images, [lo, hi]))
}

/// A five-stop approximation of the 'inferno' colour map.
fn inferno(t: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.0, 0.0, 4.0],
        [87.0, 16.0, 110.0],
        [188.0, 55.0, 84.0],
        [249.0, 142.0, 9.0],
        [252.0, 255.0, 164.0],
    ];
    let x = t * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let c = |k: usize| (STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f) as u8;
    [c(0), c(1), c(2)]
}
