//! A study of several cases (scenes, sizes): each case's report in a directory of its own, and
//! a summary across the cases in `summary.txt`, `summary.csv` and `summary.json`.
//!
//! ```text
//! slope(sampler, region)        = mean over the cases of each case's fitted slope
//! ratio(sampler, N, region)     = geometric mean over the cases of random's MSE / the sampler's
//! 95% interval                  = bootstrap: every resample redraws each case's K seeds on its
//!                                 own (stats::grouped_bootstrap_interval), so the interval
//!                                 is the figure's uncertainty from seed noise, for these cases
//! ```
//!
//! The cases are the study's, not a sample of all scenes: the interval does not say how another
//! scene would fare.

use crate::output::terminal::table_line;
use crate::render::sampling::LightSampler;
use crate::stats::{BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, grouped_bootstrap_interval};
use crate::variance::figures::fits::{against_random, fit_rows, fitted, mean_at};
use crate::variance::report::tables::write_text;
use crate::variance::{Region, Row, StudyResult, unique};
use anyhow::{Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A sampler's slope across the cases, in one region.
#[derive(Clone, Debug, Serialize)]
pub struct SlopeAcross {
    /// Sampler name.
    pub sampler: &'static str,
    /// Region.
    pub region: Region,
    /// Each case's fitted slope (None where it had no fit).
    pub per_case: Vec<Option<f64>>,
    /// Mean of `per_case` (None unless every case has a fit).
    pub mean: Option<f64>,
    /// 95% interval of `mean`.
    pub interval: Option<[f64; 2]>,
}

/// A sampler's error reduction against random across the cases, at one N and region.
#[derive(Clone, Debug, Serialize)]
pub struct RatioAcross {
    /// Sampler name.
    pub sampler: &'static str,
    /// Points per light.
    pub n: u32,
    /// Region.
    pub region: Region,
    /// Each case's random MSE / this sampler's MSE.
    pub per_case: Vec<Option<f64>>,
    /// Geometric mean of `per_case` (None unless every case has one).
    pub geometric_mean: Option<f64>,
    /// 95% interval of `geometric_mean`.
    pub interval: Option<[f64; 2]>,
}

/// The summary across cases.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    /// The cases' names, in order.
    pub cases: Vec<String>,
    /// Per sampler and region.
    pub slopes: Vec<SlopeAcross>,
    /// Per sampler other than random, N and region (when random was studied).
    pub ratios: Vec<RatioAcross>,
}

fn row<'r>(rows: &'r [Row], sampler: &str, n: u32, region: Region) -> Option<&'r Row> {
    rows.iter()
        .find(|r| r.sampler == sampler && r.n == n && r.region == region)
}

fn interval(sizes: &[usize], stat: impl FnMut(&[Vec<usize>]) -> f64) -> Option<[f64; 2]> {
    grouped_bootstrap_interval(sizes, BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, stat)
        .map(|(a, b)| [a, b])
}

/// The geometric mean of `values` (1 for none).
fn geomean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, c), v| (s + v.ln(), c + 1));
    (sum / count.max(1) as f64).exp()
}

/// The summary of `cases` (named `names`), which share samplers, budgets and seeds.
pub fn summarize(names: &[String], cases: &[StudyResult]) -> Summary {
    let Some(first) = cases.first() else {
        return Summary::default();
    };
    let config = &first.config;
    let sizes: Vec<usize> = cases.iter().map(|c| c.config.seeds as usize).collect();
    let mut slopes = Vec::new();
    for &sampler in &config.samplers {
        for region in Region::ALL {
            let fits: Vec<Vec<&Row>> = cases
                .iter()
                .map(|c| fitted(&c.rows, sampler, region))
                .collect();
            let per_case: Vec<Option<f64>> = fits
                .iter()
                .map(|pts| fit_rows(pts, None).map(|f| f.slope))
                .collect();
            let mean = per_case
                .iter()
                .copied()
                .sum::<Option<f64>>()
                .map(|s| s / cases.len() as f64);
            let interval = mean.and_then(|_| {
                interval(&sizes, |idx| {
                    fits.iter()
                        .zip(idx)
                        .map(|(pts, i)| fit_rows(pts, Some(i)).map_or(f64::NAN, |f| f.slope))
                        .sum::<f64>()
                        / cases.len() as f64
                })
            });
            slopes.push(SlopeAcross {
                sampler: sampler.name(),
                region,
                per_case,
                mean,
                interval,
            });
        }
    }
    let mut ratios = Vec::new();
    let random = LightSampler::Random.name();
    for sampler in against_random(&config.samplers) {
        for &n in &config.budgets {
            for region in Region::ALL {
                let pairs: Vec<Option<(&Row, &Row)>> = cases
                    .iter()
                    .map(|c| {
                        row(&c.rows, random, n, region)
                            .zip(row(&c.rows, sampler.name(), n, region))
                            .filter(|(b, r)| b.stats.mse > 0.0 && r.stats.mse > 0.0)
                    })
                    .collect();
                let per_case: Vec<Option<f64>> = pairs
                    .iter()
                    .map(|p| p.map(|(b, r)| b.stats.mse / r.stats.mse))
                    .collect();
                let geometric_mean = per_case
                    .iter()
                    .copied()
                    .collect::<Option<Vec<f64>>>()
                    .map(|v| geomean(v.into_iter()));
                let interval = geometric_mean.and_then(|_| {
                    interval(&sizes, |idx| {
                        geomean(pairs.iter().zip(idx).map(|(p, i)| {
                            p.map_or(f64::NAN, |(b, r)| {
                                mean_at(&b.seed_mse, Some(i)) / mean_at(&r.seed_mse, Some(i))
                            })
                        }))
                    })
                });
                ratios.push(RatioAcross {
                    sampler: sampler.name(),
                    n,
                    region,
                    per_case,
                    geometric_mean,
                    interval,
                });
            }
        }
    }
    Summary {
        cases: names.to_vec(),
        slopes,
        ratios,
    }
}

fn figure(v: Option<f64>, iv: Option<[f64; 2]>) -> String {
    match (v, iv) {
        (Some(v), Some([a, b])) => format!("{v:.3} [{a:.3}, {b:.3}]"),
        (Some(v), None) => format!("{v:.3}"),
        (None, _) => "-".into(),
    }
}

/// The summary's files: the table, the CSV, the JSON.
const FILES: [&str; 3] = ["summary.txt", "summary.csv", "summary.json"];

/// The columns of a case's slopes (`table_line`'s widths).
const COLUMNS: [i16; 3] = [-10, -28, -28];

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| v.to_string())
}

impl Summary {
    /// `summary.txt`: a section per case, then the figures across them.
    pub fn table(&self, cases: &[StudyResult]) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "variance study of {} cases", self.cases.len());
        for (name, case) in self.cases.iter().zip(cases) {
            let _ = writeln!(
                s,
                "\n== {name}: {} at {}×{} (report in {name}/) ==",
                case.scene, case.config.base.width, case.config.base.height
            );
            let header = ["sampler", "slope whole [95%]", "slope penumbra [95%]"];
            let _ = writeln!(s, "  {}", table_line(&COLUMNS, header));
            for &sampler in &case.config.samplers {
                let fit = |region: Region| {
                    case.slope(sampler, region)
                        .map_or("-".into(), |(v, iv)| figure(Some(v), iv))
                };
                let cells = [sampler.name(), &fit(Region::Whole), &fit(Region::Penumbra)];
                let _ = writeln!(s, "  {}", table_line(&COLUMNS, cells));
            }
        }
        let _ = writeln!(
            s,
            "\n== across the cases ==\n[low, high]: 95% intervals, bootstrap over each case's seeds (the cases held fixed)"
        );
        for region in [Region::Whole, Region::Penumbra] {
            let _ = writeln!(
                s,
                "\n{} region: mean slope of log MSE against log N",
                region.name()
            );
            for x in self.slopes.iter().filter(|x| x.region == region) {
                let _ = writeln!(s, "  {:<10} {}", x.sampler, figure(x.mean, x.interval));
            }
            let ratios = self.ratios.iter().filter(|x| x.region == region);
            let samplers = unique(ratios.map(|x| x.sampler));
            if samplers.is_empty() {
                continue;
            }
            let _ = writeln!(
                s,
                "{} region: random's MSE / the sampler's, geometric mean over the cases",
                region.name()
            );
            for sampler in samplers {
                let cells: Vec<String> = self
                    .ratios
                    .iter()
                    .filter(|x| x.region == region && x.sampler == sampler)
                    .map(|x| format!("N={} {}", x.n, figure(x.geometric_mean, x.interval)))
                    .collect();
                let _ = writeln!(s, "  {:<10} {}", sampler, cells.join("  "));
            }
        }
        s
    }

    /// `summary.csv`: one row per figure (slope or ratio), sampler, N and region.
    pub fn csv(&self) -> String {
        let mut s = String::from("figure,sampler,n,region,value,low,high");
        for c in &self.cases {
            let _ = write!(s, ",{c}");
        }
        s.push('\n');
        let mut line = |head: String, v: Option<f64>, iv: Option<[f64; 2]>, per: &[Option<f64>]| {
            let [low, high] = iv.map_or([None; 2], |[a, b]| [Some(a), Some(b)]);
            let _ = write!(s, "{head},{},{},{}", opt(v), opt(low), opt(high));
            for p in per {
                let _ = write!(s, ",{}", opt(*p));
            }
            s.push('\n');
        };
        for x in &self.slopes {
            let head = format!("slope,{},,{}", x.sampler, x.region.name());
            line(head, x.mean, x.interval, &x.per_case);
        }
        for x in &self.ratios {
            let head = format!("error_reduction,{},{},{}", x.sampler, x.n, x.region.name());
            line(head, x.geometric_mean, x.interval, &x.per_case);
        }
        s
    }

    /// Writes `summary.txt`, `summary.csv` and `summary.json` into `dir`.
    pub fn write(&self, cases: &[StudyResult], dir: &Path) -> Result<Vec<PathBuf>> {
        let json = serde_json::to_string_pretty(self).context("cannot encode the summary")? + "\n";
        let mut written = Vec::new();
        for (name, body) in FILES.into_iter().zip([self.table(cases), self.csv(), json]) {
            written.push(write_text(&dir.join(name), &body)?);
        }
        Ok(written)
    }
}

/// The files a study of several cases writes: per case its report under `NAME/`, then the
/// summary at the top.
pub fn file_names(names: &[String], per_case: &[String]) -> Vec<String> {
    let in_dirs = names
        .iter()
        .flat_map(|n| per_case.iter().map(move |f| format!("{n}/{f}")));
    in_dirs.chain(FILES.map(String::from)).collect()
}
