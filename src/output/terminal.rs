//! What the commands show while they run: progress bars on standard error and text on standard
//! output, each made in one place.

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::Write;

/// A progress bar of `len` steps on standard error drawn with indicatif's `template`, or a
/// hidden one when `quiet`. indicatif draws nothing when standard error is not a terminal.
pub fn progress_bar(len: u64, template: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(template)
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// Writes `text` to standard output and flushes it. A closed pipe (`raywave ... | head`) or a
/// full disk is an error, so that `main` exits 1 with a message instead of panicking as
/// `println!` does.
pub(crate) fn write_stdout(text: &str) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()
}

/// [`write_stdout`], with the message the commands give when it fails.
pub fn print(text: &str) -> Result<()> {
    write_stdout(text).context("cannot write to standard output")
}
