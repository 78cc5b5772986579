//! `raywave bench`'s exports, one file per format behind [`Format`] (each file says what it
//! writes). [`Exports`] writes the ones asked for, for `raywave bench` and `raywave bench merge`
//! alike. A new format is a new file, a field of [`Exports`] and a line of [`FORMATS`].

mod bmf;
mod continuous;
mod csv;
mod github_action_benchmark;
mod json;
mod markdown;

use crate::output::OutputPlan;
use crate::output::bench_record::BenchRecord;
use anyhow::Result;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One export format: the file it writes.
trait Format: Sync {
    /// The file's text for every point's record; `labels[i]` names point i, `by_host` adds the
    /// host to every row and name.
    fn text(&self, records: &[BenchRecord], labels: &[String], by_host: bool) -> Result<String>;
}

/// Every format and the flag that asks for it, in the order of [`Exports`]' fields.
const FORMATS: [(&str, &dyn Format); 5] = [
    ("--export-json", &json::Json),
    ("--export-csv", &csv::Csv),
    ("--export-markdown", &markdown::Markdown),
    ("--export-bmf", &bmf::Bmf),
    (
        "--export-github-action-benchmark",
        &github_action_benchmark::GithubActionBenchmark,
    ),
];

/// Where each export goes (`--export-*`; `-` is standard output), `None` when not asked for.
#[derive(Clone, Debug, Default)]
pub struct Exports {
    /// `--export-json`: the records as a JSON array.
    pub json: Option<PathBuf>,
    /// `--export-csv`: one row per point, engine and figure.
    pub csv: Option<PathBuf>,
    /// `--export-markdown`: a table for a pull request.
    pub markdown: Option<PathBuf>,
    /// `--export-bmf`: Bencher Metric Format.
    pub bmf: Option<PathBuf>,
    /// `--export-github-action-benchmark`: github-action-benchmark's `customBiggerIsBetter`.
    pub github_action_benchmark: Option<PathBuf>,
}

impl Exports {
    /// `plan` with each export asked for among its outputs, under its flag.
    pub fn plan(&self, plan: OutputPlan) -> OutputPlan {
        (self.asked().into_iter()).fold(plan, |plan, (flag, _, path)| plan.output(flag, path))
    }

    /// Writes every export asked for, each atomically. `labels[i]` names point i; `by_host`
    /// adds the host to every row and name (points measured on several machines).
    pub fn write(&self, records: &[BenchRecord], labels: &[String], by_host: bool) -> Result<()> {
        for (_, format, path) in self.asked() {
            write(path, &format.text(records, labels, by_host)?)?;
        }
        Ok(())
    }

    /// Each export asked for: its flag, its format and its path, in flag order.
    fn asked(&self) -> Vec<(&'static str, &'static dyn Format, &Path)> {
        let paths = [
            &self.json,
            &self.csv,
            &self.markdown,
            &self.bmf,
            &self.github_action_benchmark,
        ];
        FORMATS
            .into_iter()
            .zip(paths)
            .filter_map(|((flag, format), path)| Some((flag, format, path.as_deref()?)))
            .collect()
    }
}

/// Writes `text` to `path` through `crate::output` (atomically; `-` is standard output).
pub(crate) fn write(path: &Path, text: &str) -> Result<()> {
    crate::output::write_output(path, |w| Ok(w.write_all(text.as_bytes())?))
}
