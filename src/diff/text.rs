//! A comparison as text: the region, a table of figures per channel, FLIP, and what the
//! figures are (exact; PSNR's peak), as `raywave diff` and `render --mse-reference` print it.

use super::{Comparison, Figures, PSNR_PEAK};
use std::fmt::Write as _;

/// A figure in scientific notation with 4 significant digits ("0" for zero).
fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else {
        format!("{v:.3e}")
    }
}

fn psnr(v: f64) -> String {
    if v == f64::INFINITY {
        "inf".to_string()
    } else {
        format!("{v:.2}")
    }
}

fn row(out: &mut String, name: &str, f: &Figures) {
    let _ = writeln!(
        out,
        "{name:<8} {:>11} {:>11} {:>11} {:>12} {:>10}",
        sci(f.mse),
        sci(f.relmse),
        sci(f.max_abs),
        format!("({}, {})", f.max_at[0], f.max_at[1]),
        psnr(f.psnr)
    );
}

/// The table and its notes.
pub fn table(c: &Comparison) -> String {
    let mut out = String::new();
    let total = c.width as u64 * c.height as u64;
    let _ = writeln!(
        out,
        "region   {}: {} of {} pixels ({:.1}%), {} compared",
        c.region,
        c.region_pixels,
        total,
        100.0 * c.region_pixels as f64 / total as f64,
        c.pixels_compared
    );
    if c.non_finite_pixels > 0 {
        let _ = writeln!(
            out,
            "warning  {} pixel(s) of the region left out: a channel of A or B is not finite (NaN or infinite)",
            c.non_finite_pixels
        );
    }
    let _ = writeln!(
        out,
        "{:<8} {:>11} {:>11} {:>11} {:>12} {:>10}",
        "channel", "MSE", "relMSE", "max |a−b|", "at (x, y)", "PSNR dB"
    );
    for (name, f) in ["R", "G", "B"].iter().zip(&c.channels) {
        row(&mut out, name, f);
    }
    row(&mut out, "all", &c.all);
    if let Some(flip) = &c.flip {
        let _ = writeln!(
            out,
            "FLIP     mean {:.4}, max {:.4} (LDR-FLIP of the 8-bit images at {} pixels per degree; 0 is identical)",
            flip.mean, flip.max, flip.pixels_per_degree
        );
    }
    let _ = writeln!(
        out,
        "exact    computed over all {} pixels compared, not estimated: no sampling error",
        c.pixels_compared
    );
    let _ = writeln!(
        out,
        "defined  relMSE = mean (a−b)²/(b+0.01)² (pbrt-v4's MRSE, B the reference); PSNR = 10·log10({PSNR_PEAK}²/MSE)"
    );
    if c.b_max > PSNR_PEAK {
        let _ = writeln!(
            out,
            "note     B reaches {:.4} > {PSNR_PEAK} (HDR): PSNR's peak of {PSNR_PEAK} does not bound it; prefer MSE and relMSE",
            c.b_max
        );
    }
    out
}
