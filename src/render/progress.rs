//! How a long job reports while it runs, for every job that does: a render, `raywave bench`,
//! the variance study and the viewer's renders. The library never prints: the command line
//! turns a [`Progress`] into a progress bar and lines on stderr, the viewer into its render's
//! status, and tests and benches pass [`Progress::SILENT`].

use std::sync::atomic::{AtomicU64, Ordering};

/// Where a job reports how far it is and what it wants the user to read.
#[derive(Clone, Copy)]
pub struct Progress<'a> {
    /// Steps done, steps in all, and what a step is or what is being done now.
    pub report: &'a (dyn Fn(u64, u64, &str) + Sync),
    /// One line for the user, whole: `warning: ...`, `note: ...`, or a scene's
    /// `file:line: warning: ...`.
    pub notice: &'a (dyn Fn(&str) + Sync),
}

impl Progress<'static> {
    /// Reports nothing.
    pub const SILENT: Progress<'static> = Progress {
        report: &|_, _, _| {},
        notice: &|_| {},
    };
}

impl<'a> Progress<'a> {
    /// Runs `work` with this progress, each report's `what` shown as `label (what)`: one pass
    /// of a longer job.
    pub fn within<T>(&self, label: &str, work: impl FnOnce(&Progress) -> T) -> T {
        let report =
            |done, total, what: &str| (self.report)(done, total, &format!("{label} ({what})"));
        work(&Progress {
            report: &report,
            notice: self.notice,
        })
    }

    /// A count of `total` steps of `what` (reported at once as none done), advanced from any
    /// thread.
    pub fn steps(self, total: u64, what: &'a str) -> Steps<'a> {
        (self.report)(0, total, what);
        Steps {
            progress: self,
            done: AtomicU64::new(0),
            total,
            what,
        }
    }
}

/// The steps of one job, counted as they are done.
pub struct Steps<'a> {
    progress: Progress<'a>,
    done: AtomicU64,
    total: u64,
    what: &'a str,
}

impl Steps<'_> {
    /// One more step done.
    pub fn step(&self) {
        self.advance(1, self.what);
    }

    /// `by` more steps done, the job now doing `what`.
    pub fn advance(&self, by: u64, what: &str) {
        let done = self.done.fetch_add(by, Ordering::Relaxed) + by;
        (self.progress.report)(done.min(self.total), self.total, what);
    }
}
