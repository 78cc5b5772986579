//! Pictures of a study: MSE against N and MSE against time per image, on log-log axes (one
//! panel per region, one line per sampler, 95% intervals as bars), and per-pixel error heat
//! maps on one log scale shared by all samplers (`crate::output::false_colour`: title and colour bar).
//! The font is embedded (DejaVu Sans, via the `dejavu` crate), so plots need no system fonts.

use crate::output::false_colour::{self, Scale, figure, register_font};
use crate::output::image_file::write_rgb8;
use crate::render::sampling::LightSampler;
use crate::variance::{Region, Row, StudyResult};
use anyhow::{Context, Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One colour per sampler, in `LightSampler::ALL`'s order where all are studied (matplotlib's
/// tab10 less its grey and olive).
pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// Which quantity a panel puts on its x axis.
#[derive(Clone, Copy, PartialEq)]
enum Axis {
    /// Light samples N.
    Budget,
    /// Median milliseconds per image.
    Time,
}

/// (x, its interval) of a row on `axis`.
fn x_of(r: &Row, axis: Axis) -> (f64, Option<[f64; 2]>) {
    match axis {
        Axis::Budget => (r.n as f64, None),
        Axis::Time => (
            r.seconds * 1e3,
            r.seconds_interval.map(|[a, b]| [a * 1e3, b * 1e3]),
        ),
    }
}

/// A range for a log axis holding `values` (all positive), padded by `pad` times.
pub(crate) fn log_range(
    values: impl Iterator<Item = f64>,
    pad: f64,
    empty: (f64, f64),
) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo.is_finite() && hi > 0.0 {
        (lo / pad, hi * pad)
    } else {
        empty
    }
}

/// `v` and the ends of its interval (`v` again without one), for an axis's range.
pub(crate) fn with_ends((v, iv): (f64, Option<[f64; 2]>)) -> [f64; 3] {
    let [a, b] = iv.unwrap_or([v; 2]);
    [v, a, b]
}

/// One panel: MSE of every sampler in `region` against `axis`, with 95% intervals.
fn panel(
    area: &DrawingArea<BitMapBackend, Shift>,
    result: &StudyResult,
    region: Region,
    axis: Axis,
) -> Result<()> {
    let err = |e| anyhow!("plot: {e}");
    let rows: Vec<&Row> = result
        .rows
        .iter()
        .filter(|r| r.region == region && r.stats.mse > 0.0)
        .collect();
    let y_values = rows
        .iter()
        .flat_map(|r| with_ends((r.stats.mse, r.mse_interval)));
    let (y_lo, y_hi) = log_range(y_values, 1.6, (1e-6, 1.0));
    let x_values = rows.iter().flat_map(|r| with_ends(x_of(r, axis)));
    let (x_lo, x_hi) = log_range(x_values, 1.5, (0.5, 400.0));
    let (what, x_desc) = match axis {
        Axis::Budget => ("MSE against N", "light samples N"),
        Axis::Time => ("MSE against time", "ms per image (median)"),
    };
    let pixels = result.facts.region_pixels[region as usize];
    let title = format!("{}: {what} ({pixels} px)", region.name());
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc("MSE")
        .y_label_formatter(&|y| format!("{y:.0e}"))
        // Whole numbers from 1 up, two decimals below.
        .x_label_formatter(&|x| format!("{:.*}", if *x >= 1.0 { 0 } else { 2 }, x))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for (k, sampler) in result.config.samplers.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let mine: Vec<&&Row> = rows
            .iter()
            .filter(|r| r.sampler == sampler.name())
            .collect();
        let pts: Vec<(f64, f64)> = mine
            .iter()
            .map(|r| (x_of(r, axis).0, r.stats.mse))
            .collect();
        // The slope is against N: only the top row's legend gives it.
        let slope = result
            .slope(*sampler, region)
            .map(|(v, iv)| match iv {
                Some([a, b]) => format!(" (slope {v:.2} [{a:.2}, {b:.2}])"),
                None => format!(" (slope {v:.2})"),
            })
            .filter(|_| axis == Axis::Budget)
            .unwrap_or_default();
        let label = format!("{}{slope}", sampler.name());
        // The lab's strategy draws random's points for N > 1: dash it so both show.
        let dashed = *sampler == LightSampler::Lab;
        line(&mut chart, pts.clone(), colour, dashed, label)?;
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
            .map_err(err)?;
        // 95% intervals: MSE vertically, time horizontally.
        let bar = |ends: Vec<(f64, f64)>| PathElement::new(ends, colour);
        let mut bars = Vec::new();
        for r in &mine {
            let ((x, x_iv), y) = (x_of(r, axis), r.stats.mse);
            if let Some([a, b]) = r.mse_interval {
                bars.push(bar(vec![(x, a.max(y_lo)), (x, b.min(y_hi))]));
            }
            if let Some([a, b]) = x_iv {
                bars.push(bar(vec![(a.max(x_lo), y), (b.min(x_hi), y)]));
            }
        }
        chart.draw_series(bars).map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Draws `pts` as a line of `colour`, solid or dashed, labelled `label` in the legend.
pub(crate) fn line<X, Y>(
    chart: &mut ChartContext<BitMapBackend, Cartesian2d<X, Y>>,
    pts: Vec<(f64, f64)>,
    colour: RGBColor,
    dashed: bool,
    label: String,
) -> Result<()>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let style = colour.stroke_width(2);
    let series = if dashed {
        chart.draw_series(DashedLineSeries::new(pts, 8, 6, style))
    } else {
        chart.draw_series(LineSeries::new(pts, style))
    };
    series
        .map_err(|e| anyhow!("plot: {e}"))?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    Ok(())
}

/// A white `w` × `h` canvas with `draw` drawn on it, as an image.
pub(crate) fn canvas(
    (w, h): (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
) -> Result<image::RgbImage> {
    register_font();
    let mut buffer = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("plot: {e}"))?;
        draw(&root)?;
        root.present().map_err(|e| anyhow!("plot: {e}"))?;
    }
    image::RgbImage::from_raw(w, h, buffer).context("plot buffer")
}

/// Draws `mse.png`: MSE against N (top row) and against median time per image (bottom row),
/// one log-log panel per region (whole, penumbra, lit), 95% intervals as bars.
pub(crate) fn mse_plot(result: &StudyResult, path: &Path) -> Result<()> {
    let img = canvas((1500, 1040), |root| {
        let panels = root.split_evenly((2, 3));
        for (j, region) in Region::ALL.iter().enumerate() {
            panel(&panels[j], result, *region, Axis::Budget)?;
            panel(&panels[3 + j], result, *region, Axis::Time)?;
        }
        Ok(())
    })?;
    write_rgb8(&img, path)
}

/// Writes `heat_<sampler>_N<n>.png` for every sampler: per-pixel MSE over the seeds on the log
/// scale all samplers share, with a title and a labelled colour bar, so each reads on its own.
pub(crate) fn heatmaps(result: &StudyResult, dir: &Path) -> Result<Vec<PathBuf>> {
    let Some(scale) = Scale::from_values(result.heatmaps.iter().flat_map(|(_, m)| m), true) else {
        return Ok(Vec::new());
    };
    let (w, h) = (result.config.base.width, result.config.base.height);
    let (n, seeds) = (result.config.heatmap_n, result.config.seeds);
    let bar = "MSE per pixel, mean of R, G, B; one scale for all samplers";
    let mut written = Vec::new();
    for (sampler, map) in &result.heatmaps {
        let title = format!(
            "{}, N = {n}: per-pixel MSE over {seeds} seeds",
            sampler.name()
        );
        let img = figure(map, w, h, &scale, &title, bar)?;
        let path = dir.join(format!("heat_{}_N{n}.png", sampler.name()));
        write_rgb8(&img, &path)?;
        written.push(path);
    }
    Ok(written)
}

/// Per-pixel MSE maps (each `w` × `h`) as images on one shared log scale (the 1st to the 99.9th
/// percentile of all maps' positive values, [`false_colour::Scale::from_values`]), and that
/// scale as (lo, hi) in log10. `None` when no map has a positive value.
pub(crate) fn heat_images(
    maps: &[&[f32]],
    w: u32,
    h: u32,
) -> Option<(Vec<image::RgbImage>, [f32; 2])> {
    let scale = false_colour::Scale::from_values(maps.iter().flat_map(|m| m.iter()), true)?;
    let images = maps
        .iter()
        .map(|map| false_colour::map_image(map, w, h, &scale))
        .collect();
    Some((
        images,
        [scale.low.log10() as f32, scale.high.log10() as f32],
    ))
}
