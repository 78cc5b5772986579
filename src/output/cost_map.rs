//! The cost map of `render --cost-map`: each pixel's traversal work (BVH nodes visited,
//! primitives tested) as a false-colour figure with a colour bar and its scale
//! (`false_colour::figure`), for one kind of ray or all of them.
//!
//! ```text
//! value(pixel) = Σ over the chosen kinds of the measure, over every ray of the pixel's samples
//!                / camera samples per pixel          (the work of one camera sample's paths)
//! scale        = linear, 0 to the 99.9th percentile rounded up to a multiple of 4 (whole
//!                ticks); the label under the map gives the mean per ray and the largest value
//! both         = the nodes figure and the tests figure side by side, each with its own bar
//! ```

use crate::output::false_colour::{self, Scale};
use crate::render::per_kind::{PerKind, RayCounts, RayKind};
use crate::render::wavefront::cost::{Cost, CostSum};
use anyhow::Result;
use image::RgbImage;

/// Which rays a cost map counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CostKind {
    /// Camera rays' closest hits.
    Camera,
    /// Shadow rays' occlusion tests.
    Shadow,
    /// Mirror rays' closest hits.
    Reflection,
    /// Every ray.
    All,
}

impl CostKind {
    /// The kinds it sums.
    fn kinds(self) -> &'static [RayKind] {
        match self {
            CostKind::Camera => &[RayKind::Camera],
            CostKind::Shadow => &[RayKind::Shadow],
            CostKind::Reflection => &[RayKind::Reflection],
            CostKind::All => &RayKind::ALL,
        }
    }

    /// How the figure's title names its rays.
    fn title(self) -> &'static str {
        match self {
            CostKind::Camera => "camera rays",
            CostKind::Shadow => "shadow rays",
            CostKind::Reflection => "mirror rays",
            CostKind::All => "all rays",
        }
    }
}

/// What a cost map shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CostMeasure {
    /// BVH nodes visited (each an 8-wide test of child boxes).
    Nodes,
    /// Primitives tested (triangles of the leaves visited, spheres, brute force's every one).
    Tests,
    /// Both figures, side by side.
    Both,
}

/// One count a map shows: a panel of the figure, or the viewer's overlay.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Count {
    /// BVH nodes visited.
    #[default]
    Nodes,
    /// Primitives tested.
    Tests,
}

impl Count {
    fn of(self, c: &Cost) -> u32 {
        match self {
            Count::Nodes => c.nodes,
            Count::Tests => c.tests,
        }
    }
    fn of_sum(self, c: &CostSum) -> u64 {
        match self {
            Count::Nodes => c.nodes,
            Count::Tests => c.tests,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Count::Nodes => "BVH nodes visited",
            Count::Tests => "primitives tested",
        }
    }
}

/// What the figure is drawn from: a counted render's per-pixel counts and its totals.
pub struct CostInput<'a> {
    /// Each pixel's work by kind, row-major (`CostReport::pixels`).
    pub pixels: &'a [PerKind<Cost>],
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Camera samples per pixel: the values are per sample.
    pub aa_samples: u32,
    /// The frame's sums by kind (`CostReport::totals`), for the title's mean per ray.
    pub totals: &'a PerKind<CostSum>,
    /// Rays cast by kind.
    pub rays: &'a RayCounts,
}

/// The cost map of `input`: `kind`'s rays, `measure` (two panels for `Both`).
pub fn figure(input: &CostInput, kind: CostKind, measure: CostMeasure) -> Result<RgbImage> {
    let panel = |one| panel(input, kind, one);
    match measure {
        CostMeasure::Nodes => panel(Count::Nodes),
        CostMeasure::Tests => panel(Count::Tests),
        CostMeasure::Both => Ok(side_by_side(&panel(Count::Nodes)?, &panel(Count::Tests)?)),
    }
}

/// One count's figure.
fn panel(input: &CostInput, kind: CostKind, one: Count) -> Result<RgbImage> {
    let map = overlay(input, kind, one);
    let mean = map
        .per_ray
        .map_or("no rays".to_string(), |m| format!("{m:.2} per ray"));
    let title = format!("{}: {}", kind.title(), one.name());
    let label = format!(
        "per pixel and camera sample; {mean}, largest {}",
        number(map.largest)
    );
    false_colour::figure(
        &map.values,
        input.width,
        input.height,
        &map.scale,
        &title,
        &label,
    )
}

/// A map's values and what its legend says, without the figure around it.
pub struct Overlay {
    /// Each pixel's value (row-major): the count per camera sample.
    pub values: Vec<f32>,
    /// The colour scale (0 to the 99.9th percentile, rounded up to a multiple of 4).
    pub scale: Scale,
    /// The largest value.
    pub largest: f32,
    /// The frame's mean per ray of the kinds counted (`None` without rays).
    pub per_ray: Option<f64>,
}

impl Overlay {
    /// The map alone, one pixel per image pixel: what the viewer lays over the render.
    pub fn image(&self, width: u32, height: u32) -> RgbImage {
        false_colour::map_image(&self.values, width, height, &self.scale)
    }
}

/// `kind`'s `one` count per pixel and camera sample, its scale and its legend's figures.
pub fn overlay(input: &CostInput, kind: CostKind, one: Count) -> Overlay {
    let (kinds, per_sample) = (kind.kinds(), input.aa_samples.max(1) as f32);
    let values: Vec<f32> = (input.pixels.iter())
        .map(|p| kinds.iter().map(|&k| one.of(&p[k]) as u64).sum::<u64>() as f32 / per_sample)
        .collect();
    let rays: u64 = kinds.iter().map(|&k| input.rays[k]).sum();
    let work: u64 = kinds.iter().map(|&k| one.of_sum(&input.totals[k])).sum();
    Overlay {
        scale: scale_of(&values),
        largest: values.iter().copied().fold(0.0f32, f32::max),
        per_ray: (rays > 0).then(|| work as f64 / rays as f64),
        values,
    }
}

/// Linear from 0 to the 99.9th percentile, so that a few hot pixels do not flatten the map
/// (those above it are drawn brightest), rounded up to a multiple of 4 so that the bar's five
/// ticks are whole counts; at least 0 to 4.
fn scale_of(values: &[f32]) -> Scale {
    let mut sorted: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f32::total_cmp);
    let high = sorted
        .get((sorted.len() * 999 / 1000).min(sorted.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0);
    Scale {
        low: 0.0,
        high: ((high as f64 / 4.0).ceil() * 4.0).max(4.0),
        log: false,
    }
}

/// A count for a title: whole when it is one, else two decimals.
fn number(v: f32) -> String {
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.2}")
    }
}

/// `a` and `b` side by side on white, tops aligned.
fn side_by_side(a: &RgbImage, b: &RgbImage) -> RgbImage {
    let mut out = RgbImage::from_pixel(
        a.width() + b.width(),
        a.height().max(b.height()),
        image::Rgb([255, 255, 255]),
    );
    image::imageops::replace(&mut out, a, 0, 0);
    image::imageops::replace(&mut out, b, i64::from(a.width()), 0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input<'a>(
        pixels: &'a [PerKind<Cost>],
        totals: &'a PerKind<CostSum>,
        rays: &'a RayCounts,
    ) -> CostInput<'a> {
        CostInput {
            pixels,
            width: 2,
            height: 2,
            aa_samples: 2,
            totals,
            rays,
        }
    }

    #[test]
    fn the_map_sums_the_chosen_kinds_per_camera_sample() {
        let c = |nodes, tests| Cost {
            nodes,
            leaves: 0,
            tests,
        };
        let pixels: Vec<PerKind<Cost>> = (0..4)
            .map(|i| PerKind {
                camera: c(2 * i, 0),
                shadow: c(4 * i, 8),
                reflection: c(0, 0),
            })
            .collect();
        let totals = PerKind::default();
        let rays = RayCounts::default();
        let one = figure(
            &input(&pixels, &totals, &rays),
            CostKind::Shadow,
            CostMeasure::Nodes,
        )
        .unwrap();
        let both = figure(
            &input(&pixels, &totals, &rays),
            CostKind::All,
            CostMeasure::Both,
        )
        .unwrap();
        assert_eq!(both.width(), 2 * one.width());
        assert_eq!(both.height(), one.height());
        // Shadow nodes per sample 0, 2, 4, 6: a scale from 0 to 8 (whole ticks of 2).
        let scale = scale_of(&[0.0, 2.0, 4.0, 6.0]);
        assert_eq!((scale.low, scale.high), (0.0, 8.0));
        assert_eq!(scale_of(&[0.0; 4]).high, 4.0);
        assert_eq!(scale_of(&[368.0]).high, 368.0);
        assert_eq!(number(3.0), "3");
        assert_eq!(number(2.5), "2.50");
    }
}
