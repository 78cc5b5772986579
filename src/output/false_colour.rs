//! False-colour figures of a per-pixel quantity (an error, a difference): the 'inferno' colour
//! map, a scale (linear or log10) fixed before drawing so that several figures can share it, and
//! a figure with a title above the map and a labelled colour bar beside it, so that a heat map
//! read on its own says what it shows and in which units.
//!
//! ```text
//! +-----------------------------------------+
//! | title                                   |
//! | +-------------------------+  +--+ 1e-2  |
//! | |                         |  |  |       |
//! | |  map (upscaled to at    |  |  | 1e-3  |
//! | |  least MIN_SIDE pixels) |  |  |       |
//! | +-------------------------+  +--+ 1e-4  |
//! |                            label        |
//! +-----------------------------------------+
//! ```

use anyhow::{Result, anyhow};
use image::RgbImage;
use plotters::prelude::*;
use std::sync::Once;

/// The map is upscaled by a whole factor until its shorter side reaches this many pixels, as
/// long as its longer side stays within [`MAX_SIDE`].
pub const MIN_SIDE: u32 = 256;

/// The longest side an upscaled map may have (a map already longer is not upscaled).
pub const MAX_SIDE: u32 = 2048;

const TITLE_HEIGHT: u32 = 34;
const MARGIN: u32 = 12;
const BAR_WIDTH: u32 = 22;
const BAR_LABELS: u32 = 96;
const FOOTER: u32 = 26;

/// Registers the embedded DejaVu Sans as plotters' "sans-serif" (once), so figures need no
/// system fonts.
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Failure leaves text undrawn but the figure still valid; the font is a fixed asset.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// A five-stop approximation of the 'inferno' colour map: dark for 0, pale yellow for 1;
/// `t` is clamped to [0, 1] and NaN maps to 0.
pub fn inferno(t: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.0, 0.0, 4.0],
        [87.0, 16.0, 110.0],
        [188.0, 55.0, 84.0],
        [249.0, 142.0, 9.0],
        [252.0, 255.0, 164.0],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let c = |k: usize| (STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f).round() as u8;
    [c(0), c(1), c(2)]
}

/// How values map to [0, 1] along the colour map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// The value drawn darkest (and everything below it).
    pub low: f64,
    /// The value drawn brightest (and everything above it).
    pub high: f64,
    /// Logarithmic (decades) rather than linear; then `low` > 0.
    pub log: bool,
}

impl Scale {
    /// A scale from the 1st to the 99.9th percentile of the finite values (the positive ones
    /// for a log scale), so a few outliers do not flatten the map; `None` when no value
    /// qualifies. `low < high` always holds.
    pub fn from_values<'a>(values: impl IntoIterator<Item = &'a f32>, log: bool) -> Option<Scale> {
        let mut v: Vec<f32> = values
            .into_iter()
            .copied()
            .filter(|x| x.is_finite() && (!log || *x > 0.0))
            .collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f32::total_cmp);
        let low = v[v.len() / 100] as f64;
        let high = v[(v.len() * 999 / 1000).min(v.len() - 1)] as f64;
        let high = if log {
            high.max(low * 1.01)
        } else {
            high.max(low + 1e-12_f64.max(low.abs() * 1e-6))
        };
        Some(Scale { low, high, log })
    }

    /// Where `v` falls on the map, in [0, 1]; NaN, and values at or below 0 on a log scale,
    /// fall at 0.
    pub fn position(&self, v: f32) -> f32 {
        let v = v as f64;
        let t = if self.log {
            if v > 0.0 {
                (v.log10() - self.low.log10()) / (self.high.log10() - self.low.log10())
            } else {
                0.0
            }
        } else {
            (v - self.low) / (self.high - self.low)
        };
        if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, 1.0) as f32
        }
    }

    /// The value at position `t` in [0, 1] (the inverse of [`Scale::position`] inside the
    /// range).
    fn value_at(&self, t: f64) -> f64 {
        if self.log {
            10f64.powf(self.low.log10() + t * (self.high.log10() - self.low.log10()))
        } else {
            self.low + t * (self.high - self.low)
        }
    }
}

/// The map alone, one pixel per value: `values` is row-major, `width × height`.
pub fn map_image(values: &[f32], width: u32, height: u32, scale: &Scale) -> RgbImage {
    assert_eq!(values.len(), (width as usize) * (height as usize));
    RgbImage::from_fn(width, height, |x, y| {
        image::Rgb(inferno(
            scale.position(values[y as usize * width as usize + x as usize]),
        ))
    })
}

/// A figure of `values` (row-major, `width × height`): `title` above the map, a colour bar on
/// the right with five labelled ticks of `scale`, and `label` (what is shown, with its unit)
/// under the bar.
pub fn figure(
    values: &[f32],
    width: u32,
    height: u32,
    scale: &Scale,
    title: &str,
    label: &str,
) -> Result<RgbImage> {
    if values.len() != (width as usize) * (height as usize) || width == 0 || height == 0 {
        return Err(anyhow!(
            "false-colour figure: {} values for a {width}×{height} map",
            values.len()
        ));
    }
    register_font();
    let factor = MIN_SIDE
        .div_ceil(width.min(height))
        .min(MAX_SIDE / width.max(height))
        .max(1);
    let (mw, mh) = (width * factor, height * factor);
    let fw = MARGIN + mw + MARGIN + BAR_WIDTH + BAR_LABELS;
    let fh = TITLE_HEIGHT + mh + FOOTER;
    let mut buffer = vec![255u8; (fw * fh * 3) as usize];
    let mut put = |x: u32, y: u32, c: [u8; 3]| {
        let i = ((y * fw + x) * 3) as usize;
        buffer[i..i + 3].copy_from_slice(&c);
    };
    let bar_x = MARGIN + mw + MARGIN;
    for y in 0..mh {
        for x in 0..mw {
            let v = values[((y / factor) * width + x / factor) as usize];
            put(MARGIN + x, TITLE_HEIGHT + y, inferno(scale.position(v)));
        }
        let t = 1.0 - y as f32 / (mh - 1).max(1) as f32;
        for x in 0..BAR_WIDTH {
            put(bar_x + x, TITLE_HEIGHT + y, inferno(t));
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (fw, fh)).into_drawing_area();
        let err = |e| anyhow!("false-colour figure: {e}");
        let title_style = ("sans-serif", 18).into_font().color(&BLACK);
        root.draw_text(title, &title_style, (MARGIN as i32, 8))
            .map_err(err)?;
        let tick_style = ("sans-serif", 13).into_font().color(&BLACK);
        for k in 0..5 {
            let t = k as f64 / 4.0;
            let y = (TITLE_HEIGHT + mh - 1) as f64 - t * (mh - 1) as f64;
            let y = y.round() as i32;
            let x0 = (bar_x + BAR_WIDTH) as i32;
            root.draw(&PathElement::new(vec![(x0, y), (x0 + 4, y)], BLACK))
                .map_err(err)?;
            root.draw_text(
                &tick_label(scale.value_at(t)),
                &tick_style,
                (x0 + 7, (y - 7).max(0)),
            )
            .map_err(err)?;
        }
        let scale_name = if scale.log { "log scale" } else { "linear" };
        root.draw_text(
            &format!("{label} ({scale_name})"),
            &tick_style,
            (MARGIN as i32, (TITLE_HEIGHT + mh + 6) as i32),
        )
        .map_err(err)?;
        root.present().map_err(err)?;
    }
    RgbImage::from_raw(fw, fh, buffer).ok_or_else(|| anyhow!("false-colour figure: buffer size"))
}

/// A short label for a tick value: a whole number below a million as it is (a count), else
/// three decimals, scientific outside [0.01, 1000).
fn tick_label(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if v.fract() == 0.0 && v.abs() < 1e6 {
        format!("{v:.0}")
    } else if (0.01..1000.0).contains(&v.abs()) {
        format!("{v:.3}")
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_maps_ends_and_clamps() {
        let lin = Scale {
            low: 1.0,
            high: 3.0,
            log: false,
        };
        assert_eq!(lin.position(1.0), 0.0);
        assert_eq!(lin.position(2.0), 0.5);
        assert_eq!(lin.position(9.0), 1.0);
        assert_eq!(lin.position(f32::NAN), 0.0);
        let log = Scale {
            low: 1e-4,
            high: 1e-2,
            log: true,
        };
        assert!((log.position(1e-3) - 0.5).abs() < 1e-6);
        assert_eq!(log.position(0.0), 0.0);
        assert!((log.value_at(0.5) - 1e-3).abs() < 1e-9);
    }

    #[test]
    fn scale_from_values_ignores_what_it_cannot_place() {
        let v = [f32::NAN, f32::INFINITY, 0.0, -1.0];
        assert_eq!(Scale::from_values(&v, true), None);
        let s = Scale::from_values(&[2.0, 2.0], false).unwrap();
        assert!(s.low < s.high);
        let s = Scale::from_values(&[0.5, 0.5], true).unwrap();
        assert!(s.low < s.high && s.low > 0.0);
    }

    #[test]
    fn whole_ticks_print_as_counts() {
        assert_eq!(tick_label(92.0), "92");
        assert_eq!(tick_label(2500.0), "2500");
        assert_eq!(tick_label(0.5), "0.500");
        assert_eq!(tick_label(2.5e6), "2.50e6");
    }

    #[test]
    fn colour_map_runs_dark_to_bright() {
        let lum = |c: [u8; 3]| c[0] as u32 + c[1] as u32 + c[2] as u32;
        let mut last = 0;
        for k in 0..=20 {
            let l = lum(inferno(k as f32 / 20.0));
            assert!(l >= last, "luminance fell at {k}");
            last = l;
        }
        assert_eq!(inferno(-1.0), inferno(0.0));
        assert_eq!(inferno(2.0), inferno(1.0));
    }

    #[test]
    fn figure_holds_the_map_upscaled_and_a_bar() {
        let values: Vec<f32> = (0..16).map(|i| i as f32).collect();
        let scale = Scale::from_values(&values, false).unwrap();
        let img = figure(&values, 4, 4, &scale, "t", "units").unwrap();
        let factor = MIN_SIDE / 4;
        assert_eq!(img.height(), TITLE_HEIGHT + 4 * factor + FOOTER);
        // The top-left map pixel and the bottom-right one carry the ends of the map.
        let first = img.get_pixel(MARGIN, TITLE_HEIGHT).0;
        let last = img
            .get_pixel(MARGIN + 4 * factor - 1, TITLE_HEIGHT + 4 * factor - 1)
            .0;
        assert_eq!(first, inferno(0.0));
        assert_eq!(last, inferno(1.0));
        assert!(figure(&values, 5, 4, &scale, "t", "u").is_err());
        // A long, thin map is not blown up past MAX_SIDE.
        let row = vec![1.0f32; 300];
        let img = figure(&row, 300, 1, &scale, "t", "u").unwrap();
        assert!(img.width() < MAX_SIDE + 300, "{}", img.width());
    }
}
