//! The one error kind that is not the library's fault nor the file's: a usage error.

/// A flag value that clap accepted but that fails a later check (an output extension raywave
/// cannot write, a debug pixel outside the image, ...): `main` reports it like clap's own usage
/// errors, with exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

impl UsageError {
    /// Wraps any error's message (with its causes) as a usage error.
    pub fn from_error(e: &anyhow::Error) -> Self {
        UsageError(format!("{e:#}"))
    }
}
