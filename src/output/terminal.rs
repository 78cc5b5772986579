//! What the commands show while they run: progress bars on standard error and text on standard
//! output, each made in one place.

use crate::render::progress::Progress;
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::Write;

/// Runs `work` with a progress bar on standard error, drawn with indicatif's `template` (its
/// `{msg}` is what the job says it is doing), and the job's notices printed above the bar. No
/// bar when `quiet`; indicatif draws none when standard error is not a terminal.
pub fn with_bar<T>(template: &str, quiet: bool, work: impl FnOnce(&Progress) -> T) -> T {
    let bar = match quiet {
        true => ProgressBar::hidden(),
        false => ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr()),
    };
    bar.set_style(
        ProgressStyle::with_template(template)
            .expect("valid template")
            .progress_chars("=> "),
    );
    let report = |done, total, what: &str| {
        if done == 0 {
            // A new count (the next pass of a render): its own elapsed time and estimate.
            bar.reset();
        }
        bar.set_length(total);
        bar.set_position(done);
        bar.set_message(what.to_owned());
    };
    let notice = |line: &str| bar.suspend(|| eprintln!("{line}"));
    let out = work(&Progress {
        report: &report,
        notice: &notice,
    });
    bar.finish_and_clear();
    out
}

/// Writes `text` to standard output and flushes it. A closed pipe (`raywave ... | head`) or a
/// full disk is an error, so that `main` exits 1 with a message instead of panicking as
/// `println!` does.
pub fn print(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .context("cannot write to standard output")
}

/// One line of a text table, without its line break: each cell padded to its column's width,
/// left-aligned where the width is negative and right-aligned where it is positive, one space
/// between cells. A table's header (its cells split at `|`: `"engine|figure|median"`) and its
/// rows share one list of widths, so that they stay aligned.
pub fn table_line<S: AsRef<str>>(widths: &[i16], cells: impl IntoIterator<Item = S>) -> String {
    let padded: Vec<String> = (widths.iter().zip(cells))
        .map(|(&w, c)| {
            let (c, n) = (c.as_ref(), usize::from(w.unsigned_abs()));
            if w < 0 {
                format!("{c:<n$}")
            } else {
                format!("{c:>n$}")
            }
        })
        .collect();
    padded.join(" ")
}
