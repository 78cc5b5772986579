//! A study's results as files: the table as printed, `results.csv` (one row per sampler, N and
//! region, with 95% intervals), `seeds.csv` (one row per seed), and a self-describing
//! `results.json` (schema, version, commit, machine, settings, rows, slopes, matching budgets,
//! per-seed rows), plus the plots, heat maps and contact sheet.

use super::{plot, sheet, spectrum_plot};
use crate::output::machine::Machine;
use crate::output::terminal::table_line;
use crate::render::sampling::LightSampler;
use crate::variance::figures::fits::{LAB_RANDOM_POINTS, against_random};
use crate::variance::{Region, Row, StudyConfig, StudyResult, unique};
use anyhow::{Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Version of `results.json`'s layout; raised whenever a key changes meaning or goes away.
const SCHEMA_VERSION: u32 = 3;

/// The keys of `results.json`, each with what it holds.
pub const SCHEMA: [(&str, &str); 15] = [
    (
        "schema",
        "this table: the layout's version and what each key holds",
    ),
    (
        "raywave_version",
        "the version of raywave that ran the study",
    ),
    (
        "commit",
        "the source commit raywave was built from (\"unknown\" outside a checkout)",
    ),
    (
        "commit_dirty",
        "true if the source tree had uncommitted changes; null if unknown",
    ),
    ("created", "when the study finished, UTC, RFC 3339"),
    (
        "machine",
        "host name, CPU model, logical CPUs, OS and architecture",
    ),
    (
        "settings",
        "everything the figures depend on: scene, engine, threads, the study's configuration (render settings, budgets, samplers, seeds, reference and mask samples, heat-map budget) and the bootstrap's resamples, seed and level",
    ),
    (
        "region_pixels",
        "pixels in each region (whole, penumbra, lit)",
    ),
    (
        "reference_mse",
        "the converged reference's own error variance per region",
    ),
    (
        "reference_cached",
        "true if the converged reference was read from the cache",
    ),
    (
        "rows",
        "per sampler, N and region: mse, bias, bias_bound, variance, pixels; mse_interval; excluded_from_fit; seconds (median per image) and seconds_interval; rays, rays_per_second; efficiency = 1/(mse·seconds) and efficiency_interval; efficiency_vs_random (over random's at the same N and region) and its interval; error_reduction (random's MSE over this one's) and its interval; perceived: lowpass_mse (MSE after a Gaussian blur of σ = 1 and 2 pixels) and lowpass_interval, low_band_power (mean error power over 0 < |f| ≤ 1/8 cycles per pixel) and its interval, low_band_vs_random (over random's) and its interval, low_band_share (over the mean power of the whole band: 1 for white noise) and its interval, spectrum (radially averaged error power in 32 rings of width 1/64 cycles per pixel up to 1/2; null for a ring the image has no frequency in) and spectrum_interval. Intervals are 95%, [low, high]; null when there are too few seeds (an end of null is unbounded)",
    ),
    (
        "slopes",
        "per sampler and region: the least-squares fit of log10 MSE against log10 N (slope, intercept), slope_interval, the budgets fitted and those excluded",
    ),
    (
        "matching",
        "per sampler (other than random) and region: the budget whose fitted MSE equals random's at random_n points, and its interval",
    ),
    (
        "seeds",
        "one row per sampler, N, region and seed: mse, bias, seconds of that seed's image",
    ),
    (
        "outputs",
        "the other files of the report and what they show",
    ),
];

/// The files a study writes into its directory (`heatmap_n` is the budget drawn).
pub fn file_names(samplers: &[LightSampler], budgets: &[u32], heatmap_n: u32) -> Vec<String> {
    let mut names: Vec<String> = [
        "table.txt",
        "results.csv",
        "seeds.csv",
        "perceived.csv",
        "spectra.csv",
        "results.json",
        "mse.png",
        "contact_sheet.png",
    ]
    .map(String::from)
    .to_vec();
    names.extend(
        samplers
            .iter()
            .map(|s| format!("heat_{}_N{heatmap_n}.png", s.name())),
    );
    names.extend(
        unique(budgets.iter().copied())
            .into_iter()
            .map(spectrum_plot::file_name),
    );
    names
}

/// Writes `body` to `path` atomically; returns the path.
pub(crate) fn write_text(path: &Path, body: &str) -> Result<PathBuf> {
    crate::output::write_output(path, |w| {
        std::io::Write::write_all(w, body.as_bytes())?;
        Ok(())
    })?;
    Ok(path.to_path_buf())
}

/// One seed's image of a (sampler, N), over one region.
#[derive(Serialize)]
struct SeedRow {
    sampler: &'static str,
    n: u32,
    region: Region,
    seed: u32,
    mse: f64,
    bias: f64,
    seconds: f64,
}

/// The settings block of `results.json`.
#[derive(Serialize)]
struct Settings<'a> {
    scene: &'a str,
    engine: &'a str,
    threads: usize,
    study: &'a StudyConfig,
    bootstrap: Bootstrap,
}

#[derive(Serialize)]
struct Bootstrap {
    resamples: usize,
    seed: u64,
    level: f64,
    unit: &'static str,
}

#[derive(Serialize)]
struct Schema {
    version: u32,
    fields: std::collections::BTreeMap<&'static str, &'static str>,
}

/// A per-region array as a map from the regions' names.
fn by_region<T>(v: [T; 3]) -> std::collections::BTreeMap<&'static str, T> {
    Region::ALL.iter().map(|r| r.name()).zip(v).collect()
}

/// `results.json`.
#[derive(Serialize)]
struct Document<'a> {
    schema: Schema,
    raywave_version: &'static str,
    commit: String,
    commit_dirty: Option<bool>,
    created: String,
    machine: Machine,
    settings: Settings<'a>,
    region_pixels: std::collections::BTreeMap<&'static str, usize>,
    reference_mse: std::collections::BTreeMap<&'static str, f64>,
    reference_cached: bool,
    rows: &'a [Row],
    slopes: &'a [crate::variance::Slope],
    matching: &'a [crate::variance::Matching],
    seeds: Vec<SeedRow>,
    outputs: std::collections::BTreeMap<String, String>,
}

/// `v [low, high]`, or `v [-]` without an interval; `end` writes each end.
pub(crate) fn with_interval(
    v: String,
    iv: Option<[f64; 2]>,
    end: impl Fn(f64) -> String,
) -> String {
    match iv {
        Some([a, b]) => format!("{v} [{}, {}]", end(a), end(b)),
        None => format!("{v} [-]"),
    }
}

/// An interval as two CSV cells, empty without one.
pub(crate) fn iv_cells(iv: Option<[f64; 2]>) -> String {
    match iv {
        Some([a, b]) => format!("{a:e},{b:e}"),
        None => ",".to_string(),
    }
}

/// A value as a CSV cell, empty without one.
pub(crate) fn sci_cell(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| format!("{v:e}"))
}

/// `text`, or `inf` where `x` is not finite (an unbounded end).
fn or_inf(x: f64, text: String) -> String {
    if x.is_finite() { text } else { "inf".into() }
}

/// `v` in scientific notation with its interval: `6.37e-4 [6.1e-4, 6.6e-4]`.
fn sci_iv(v: f64, iv: Option<[f64; 2]>) -> String {
    with_interval(format!("{v:.3e}"), iv, |x| or_inf(x, format!("{x:.2e}")))
}

/// One row of a per-region table: the sampler, then `cell` of the whole image, the penumbra
/// and the lit region.
fn region_row(s: &mut String, sampler: &str, cell: impl Fn(Region) -> String) {
    let _ = writeln!(
        s,
        "  {:<10} {:<24} {:<24} {:<24}",
        sampler,
        cell(Region::Whole),
        cell(Region::Penumbra),
        cell(Region::Lit)
    );
}

/// A fixed-point value with its interval: `-1.49 [-1.55, -1.43]`; `-` without a value.
fn fixed_iv(v: impl Into<Option<f64>>, iv: Option<[f64; 2]>, digits: usize) -> String {
    let e = |x: f64| or_inf(x, format!("{x:.digits$}"));
    v.into().map_or("-".into(), |v| with_interval(e(v), iv, e))
}

/// The columns of a region's table (`table_line`'s widths).
const COLUMNS: [i16; 11] = [-10, 5, -29, -22, 10, 9, 10, -22, 7, -29, -20];

impl StudyResult {
    /// The per-seed rows, seeds 1..=K.
    fn seed_rows(&self) -> Vec<SeedRow> {
        let mut out = Vec::new();
        for r in &self.rows {
            for (k, mse) in r.seed_mse.iter().enumerate() {
                out.push(SeedRow {
                    sampler: r.sampler,
                    n: r.n,
                    region: r.region,
                    seed: k as u32 + 1,
                    mse: *mse,
                    bias: r.seed_bias[k],
                    seconds: r.seed_seconds[k],
                });
            }
        }
        out
    }

    /// A readable report: one table per region, the slopes and matching budgets with their
    /// 95% intervals, and the checks.
    pub fn table(&self) -> String {
        let (mut s, base, seeds) = (String::new(), &self.config.base, self.config.seeds);
        let _ = writeln!(
            s,
            "variance study: {} at {}×{}, {} bounces, {seeds} seeds per point, engine {}, {} threads",
            self.scene, base.width, base.height, base.bounces, self.engine, self.threads
        );
        let _ = writeln!(
            s,
            "[low, high]: 95% intervals (MSE, efficiency, slopes, budgets: bootstrap over the \
             seeds; time: the median's sign-test interval, from 6 seeds)"
        );
        let hosts = unique(self.rows.iter().map(|r| r.host.as_str()));
        if hosts.len() > 1 {
            let _ = writeln!(
                s,
                "timed on {} hosts ({}): each row's times and efficiencies are its host's (results.csv, column host)",
                hosts.len(),
                hosts.join(", ")
            );
        }
        for (i, region) in Region::ALL.iter().enumerate() {
            if self.facts.region_pixels[i] == 0 {
                let _ = writeln!(
                    s,
                    "\n{}: no pixels in this region, nothing measured",
                    region.name()
                );
                continue;
            }
            let _ = writeln!(
                s,
                "\n{} ({} pixels; reference MSE {:.2e}, {:.0}× below the smallest measured)",
                region.name(),
                self.facts.region_pixels[i],
                self.facts.reference_mse[i],
                self.reference_margin(*region)
            );
            let header = "sampler|N|MSE [95%]|random/MSE [95%]|bias|±bound|variance|\
                          ms/image [95%]|Mrays/s|1/(MSE·s) [95%]|vs random [95%]";
            let _ = writeln!(s, "  {}", table_line(&COLUMNS, header.split('|')));
            for r in self.rows.iter().filter(|r| r.region == *region) {
                let ms = r.seconds_interval.map(|[a, b]| [a * 1e3, b * 1e3]);
                let flags = [
                    (r.stats.bias.abs() > r.stats.bias_bound, "BIASED?"),
                    (r.excluded_from_fit, "not fitted"),
                ];
                let notes: Vec<&str> = flags.iter().filter(|f| f.0).map(|f| f.1).collect();
                let cells = [
                    r.sampler,
                    &r.n.to_string(),
                    &sci_iv(r.stats.mse, r.mse_interval),
                    &fixed_iv(r.error_reduction, r.error_reduction_interval, 2),
                    &format!("{:.2e}", r.stats.bias),
                    &format!("{:.2e}", r.stats.bias_bound),
                    &format!("{:.3e}", r.stats.variance),
                    &fixed_iv(r.seconds * 1e3, ms, 2),
                    &format!("{:.2}", r.rays_per_second / 1e6),
                    &sci_iv(r.efficiency, r.efficiency_interval),
                    &fixed_iv(r.efficiency_vs_random, r.efficiency_vs_random_interval, 2),
                ];
                let notes = match notes.is_empty() {
                    true => String::new(),
                    false => format!("  {}", notes.join(", ")),
                };
                let _ = writeln!(s, "  {}{notes}", table_line(&COLUMNS, cells));
            }
        }
        let _ = writeln!(
            s,
            "\nslope of log MSE against log N [95%] (points where the sampler ignores the seed, \
             such as lab at N = 1, are bias, not noise, and are left out):"
        );
        region_row(&mut s, "sampler", |region| region.name().into());
        for sampler in &self.config.samplers {
            let cell = |region: Region| {
                self.slope(*sampler, region)
                    .map_or("-".into(), |(v, iv)| fixed_iv(v, iv, 3))
            };
            region_row(&mut s, sampler.name(), cell);
        }
        if !self.matching.is_empty() {
            let _ = writeln!(
                s,
                "\nbudget matching the MSE of {} random points (the lab's choice), from the fits \
                 [95%]:",
                LAB_RANDOM_POINTS
            );
            for sampler in against_random(&self.config.samplers) {
                let cell = |region: Region| {
                    self.matching
                        .iter()
                        .find(|m| m.sampler == sampler.name() && m.region == region)
                        .and_then(|m| m.budget.map(|b| fixed_iv(b, m.interval, 1)))
                        .unwrap_or_else(|| "-".into())
                };
                region_row(&mut s, sampler.name(), cell);
            }
        }
        s.push_str(&self.perceived_table());
        s
    }

    /// The rows as CSV, with the 95% intervals (empty cells where there is none).
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "sampler,n,region,pixels,mse,mse_low,mse_high,bias,bias_bound,variance,\
             excluded_from_fit,seconds,seconds_low,seconds_high,rays,rays_per_second,\
             efficiency,efficiency_low,efficiency_high,efficiency_vs_random,\
             efficiency_vs_random_low,efficiency_vs_random_high,error_reduction,\
             error_reduction_low,error_reduction_high,host\n",
        );
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{},{},{},{},{:e},{},{:e},{:e},{:e},{},{:e},{},{},{:e},{:e},{},{},{},{},{},{}",
                r.sampler,
                r.n,
                r.region.name(),
                r.stats.pixels,
                r.stats.mse,
                iv_cells(r.mse_interval),
                r.stats.bias,
                r.stats.bias_bound,
                r.stats.variance,
                r.excluded_from_fit,
                r.seconds,
                iv_cells(r.seconds_interval),
                r.rays,
                r.rays_per_second,
                r.efficiency,
                iv_cells(r.efficiency_interval),
                sci_cell(r.efficiency_vs_random),
                iv_cells(r.efficiency_vs_random_interval),
                sci_cell(r.error_reduction),
                iv_cells(r.error_reduction_interval),
                r.host
            );
        }
        s
    }

    /// One row per sampler, N, region and seed.
    fn seeds_csv(&self) -> String {
        let mut s = String::from("sampler,n,region,seed,mse,bias,seconds\n");
        for r in self.seed_rows() {
            let region = r.region.name();
            let _ = writeln!(
                s,
                "{},{},{region},{},{:e},{:e},{:e}",
                r.sampler, r.n, r.seed, r.mse, r.bias, r.seconds
            );
        }
        s
    }

    /// `results.json`: the figures with everything needed to read and reproduce them.
    pub fn json(&self) -> Result<String> {
        let build = crate::output::build_info::current();
        let outputs = file_names(&self.config.samplers, &self.config.budgets, self.config.heatmap_n)
            .into_iter()
            .filter(|n| n != "results.json")
            .map(|n| {
                let what = match n.as_str() {
                    "table.txt" => "the report as printed",
                    "results.csv" => "the rows of `rows`",
                    "seeds.csv" => "the rows of `seeds`",
                    "mse.png" => "MSE against N (top) and against time per image (bottom), per region, with 95% intervals",
                    "contact_sheet.png" => "seed 0's render of every sampler (rows) and budget (columns)",
                    "perceived.csv" => "per row: MSE after the σ = 1 and 2 pixel blurs, the low band and its ratio to random's, with 95% intervals",
                    "spectra.csv" => "per row and ring: the radially averaged error power with its 95% interval",
                    s if s.starts_with("spectrum_N") => "the error's radially averaged power spectrum at one budget, whole image and penumbra, one curve per sampler with its 95% band",
                    _ => "per-pixel MSE at the heat-map budget, on one log scale shared by all samplers",
                };
                (n, what.to_string())
            })
            .collect();
        let doc = Document {
            schema: Schema {
                version: SCHEMA_VERSION,
                fields: SCHEMA.into_iter().collect(),
            },
            raywave_version: env!("CARGO_PKG_VERSION"),
            commit: build.commit,
            commit_dirty: build.dirty,
            created: crate::output::bench_record::now_utc(),
            machine: Machine::current(),
            settings: Settings {
                scene: &self.scene,
                engine: &self.engine,
                threads: self.threads,
                study: &self.config,
                bootstrap: Bootstrap {
                    resamples: crate::stats::BOOTSTRAP_RESAMPLES,
                    seed: crate::stats::BOOTSTRAP_SEED,
                    level: 0.95,
                    unit: "seed: one resample draws K seeds with replacement, the same for every sampler, budget and region",
                },
            },
            region_pixels: by_region(self.facts.region_pixels),
            reference_mse: by_region(self.facts.reference_mse),
            reference_cached: self.facts.reference_cached,
            rows: &self.rows,
            slopes: &self.slopes,
            matching: &self.matching,
            seeds: self.seed_rows(),
            outputs,
        };
        Ok(serde_json::to_string_pretty(&doc)? + "\n")
    }

    /// Writes every file of [`file_names`] into `dir`; returns the paths written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut written = Vec::new();
        for (name, body) in [
            ("table.txt", self.table()),
            ("results.csv", self.csv()),
            ("seeds.csv", self.seeds_csv()),
            ("perceived.csv", self.perceived_csv()),
            ("spectra.csv", self.spectra_csv()),
            ("results.json", self.json()?),
        ] {
            written.push(write_text(&dir.join(name), &body)?);
        }
        let plot_path = dir.join("mse.png");
        plot::mse_plot(self, &plot_path)?;
        written.push(plot_path);
        let sheet_path = dir.join("contact_sheet.png");
        if sheet::write(self, &sheet_path)? {
            written.push(sheet_path);
        }
        written.extend(plot::heatmaps(self, dir)?);
        written.extend(spectrum_plot::spectra(self, dir)?);
        Ok(written)
    }
}
