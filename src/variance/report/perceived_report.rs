//! The perceived-error part of a study's report: a table of each sampler's low-pass error and
//! low band against random's, per budget and region, and the CSV files behind the spectra.

use crate::output::terminal::table_line;
use crate::variance::StudyResult;
use crate::variance::figures::spectrum::{LOWPASS_SIGMAS, RINGS, ring_frequency};
use crate::variance::report::spectrum_plot::REGIONS;
use crate::variance::report::tables::{iv_cells, sci_cell, with_interval};
use std::fmt::Write;

/// `v` with its interval, scientific: `6.4e-5 [6.1e-5, 6.8e-5]`; `-` for a figure with nothing
/// to measure (a low band without a frequency in it, on a tiny image).
fn sci(v: f64, iv: Option<[f64; 2]>) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    with_interval(format!("{v:.2e}"), iv, |x| format!("{x:.1e}"))
}

/// `v` with its interval, fixed: `0.42 [0.31, 0.55]`; `-` as for [`sci`], and without a value.
fn fixed(v: impl Into<Option<f64>>, iv: Option<[f64; 2]>) -> String {
    match v.into().filter(|v| v.is_finite()) {
        Some(v) => with_interval(format!("{v:.2}"), iv, |x| format!("{x:.2}")),
        None => "-".into(),
    }
}

/// The columns of the table (`table_line`'s widths).
const COLUMNS: [i16; 7] = [-10, 5, -28, -28, -28, -22, -22];

impl StudyResult {
    /// The table of where the error sits: per region (whole, penumbra), per sampler and N,
    /// the MSE after the low-pass blurs and the low band, absolute and relative to random.
    pub fn perceived_table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "\nwhere the error sits: mean square error after a Gaussian blur of σ = {} and {} \
             pixels (what a viewer sees at a distance), and the error's power in the lowest \
             quarter of the band (0 < |f| ≤ 1/8 cycles per pixel; white noise: its variance), \
             over random's, and as a share of the whole band's mean power (1: white, below 1: \
             blue) [95%]:",
            LOWPASS_SIGMAS[0], LOWPASS_SIGMAS[1]
        );
        for region in REGIONS {
            if self.facts.region_pixels[region as usize] == 0 {
                continue;
            }
            let _ = writeln!(s, "\n{}", region.name());
            // The header has no title over the last column, the low band's share.
            let header = "sampler|N|blur σ=1 MSE [95%]|blur σ=2 MSE [95%]|low band [95%]|\
                          low band / random's";
            let _ = writeln!(s, "  {}", table_line(&COLUMNS, header.split('|')));
            for r in self.rows.iter().filter(|r| r.region == region) {
                let p = &r.perceived;
                let cells = [
                    r.sampler,
                    &r.n.to_string(),
                    &sci(p.lowpass_mse[0], p.lowpass_interval[0]),
                    &sci(p.lowpass_mse[1], p.lowpass_interval[1]),
                    &sci(p.low_band_power, p.low_band_interval),
                    &fixed(p.low_band_vs_random, p.low_band_vs_random_interval),
                    &fixed(p.low_band_share, p.low_band_share_interval),
                ];
                let _ = writeln!(s, "  {}", table_line(&COLUMNS, cells));
            }
        }
        s
    }

    /// `perceived.csv`: one line per (sampler, N, region).
    pub fn perceived_csv(&self) -> String {
        let mut s = String::from(
            "sampler,n,region,lowpass1_mse,lowpass1_low,lowpass1_high,lowpass2_mse,lowpass2_low,\
             lowpass2_high,low_band_power,low_band_low,low_band_high,low_band_vs_random,\
             low_band_vs_random_low,low_band_vs_random_high,low_band_share,low_band_share_low,\
             low_band_share_high\n",
        );
        for r in &self.rows {
            let p = &r.perceived;
            let _ = writeln!(
                s,
                "{},{},{},{:e},{},{:e},{},{:e},{},{},{},{:e},{}",
                r.sampler,
                r.n,
                r.region.name(),
                p.lowpass_mse[0],
                iv_cells(p.lowpass_interval[0]),
                p.lowpass_mse[1],
                iv_cells(p.lowpass_interval[1]),
                p.low_band_power,
                iv_cells(p.low_band_interval),
                sci_cell(p.low_band_vs_random),
                iv_cells(p.low_band_vs_random_interval),
                p.low_band_share,
                iv_cells(p.low_band_share_interval)
            );
        }
        s
    }

    /// `spectra.csv`: one line per (sampler, N, region, ring), empty power for an empty ring.
    pub fn spectra_csv(&self) -> String {
        let mut s = String::from("sampler,n,region,ring,frequency,power,power_low,power_high\n");
        for r in &self.rows {
            let p = &r.perceived;
            for ring in 0..RINGS.min(p.spectrum.len()) {
                let _ = writeln!(
                    s,
                    "{},{},{},{ring},{},{},{}",
                    r.sampler,
                    r.n,
                    r.region.name(),
                    ring_frequency(ring),
                    sci_cell(Some(p.spectrum[ring]).filter(|x| x.is_finite())),
                    iv_cells(
                        p.spectrum_interval[ring].filter(|[a, b]| a.is_finite() && b.is_finite())
                    )
                );
            }
        }
        s
    }
}
