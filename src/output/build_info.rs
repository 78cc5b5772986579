//! What this binary was built from, as `build.rs` found it at build time: the git commit and
//! whether tracked files had uncommitted changes, the cargo profile, the target triple, the
//! enabled target features and the RUSTFLAGS. Bench records and `raywave info` show it.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The build this binary is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BuildInfo {
    /// `git rev-parse HEAD` when the sources were compiled, or "unknown" (no git, e.g. a source
    /// tarball). `build.rs` does not rerun on a commit alone.
    pub commit: String,
    /// Whether the compiled files differed from the commit then (None when unknown).
    pub dirty: Option<bool>,
    /// Cargo profile ("release", "debug").
    pub profile: String,
    /// Target triple.
    pub target: String,
    /// Enabled target features, comma-separated (`avx,avx2,fma,...`).
    pub target_features: String,
    /// RUSTFLAGS as cargo passed them (e.g. `-C target-cpu=native`), space-separated.
    pub rustflags: String,
}

/// This binary's build.
pub fn current() -> BuildInfo {
    BuildInfo {
        commit: env!("RAYWAVE_GIT_COMMIT").to_string(),
        // "true", "false", or "unknown" (None).
        dirty: env!("RAYWAVE_GIT_DIRTY").parse().ok(),
        profile: env!("RAYWAVE_BUILD_PROFILE").to_string(),
        target: env!("RAYWAVE_BUILD_TARGET").to_string(),
        target_features: env!("RAYWAVE_TARGET_FEATURES").to_string(),
        rustflags: env!("RAYWAVE_RUSTFLAGS").to_string(),
    }
}

impl BuildInfo {
    /// The commit's first 12 hex digits, with " (dirty)" when the tree was.
    pub fn short_commit(&self) -> String {
        let c = self.commit.get(..12).unwrap_or(&self.commit);
        match self.dirty {
            Some(true) => format!("{c} (dirty)"),
            _ => c.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_build_is_described() {
        let b = super::current();
        assert!(
            b.commit == "unknown" || b.commit.len() == 40,
            "{}",
            b.commit
        );
        assert!(!b.profile.is_empty() && !b.target.is_empty());
    }
}
