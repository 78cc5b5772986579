//! Pictures of a study: MSE against N on log-log axes (one panel per region, one line per
//! sampler) and per-pixel error heat maps on one shared log scale. The font is embedded
//! (DejaVu Sans, via the `dejavu` crate), so plots need no system fonts.

use super::{Region, StudyResult};
use crate::false_colour::{self, register_font};
use crate::film::write_atomically;
use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const PALETTE: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
];

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

/// Per-pixel MSE maps (each `w` × `h`) as images on one shared log scale
/// ([`false_colour::Scale::from_values`]: the 1st to the 99.9th percentile of all maps' positive
/// values; dark = low error, bright = high), so that the maps compare directly; also returns
/// that scale as (lo, hi) in log10. `None` when no map has a positive value.
pub fn heat_images(maps: &[&[f32]], w: u32, h: u32) -> Option<(Vec<image::RgbImage>, [f32; 2])> {
    let scale = false_colour::Scale::from_values(maps.iter().flat_map(|m| m.iter()), true)?;
    let images = maps
        .iter()
        .map(|map| false_colour::map_image(map, w, h, &scale))
        .collect();
    Some((images, [scale.low.log10() as f32, scale.high.log10() as f32]))
}
