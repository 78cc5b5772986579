//! A test that needs something from outside the project (a batch system, a validator) and does
//! not find it: outside CI it prints SKIPPED and the reason, and passes; in CI it fails with the
//! reason, as a silent pass there would be a false green (`.ci/run` installs what the tests
//! need).

/// Whether `CI` is set to something other than empty, `false` or `0`.
pub fn in_ci() -> bool {
    std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// Fails the test with `reason` in CI; elsewhere prints `SKIPPED: reason`, and the caller
/// returns.
pub fn skip_or_fail(reason: &str) {
    assert!(!in_ci(), "CI is set, and {reason}");
    println!("SKIPPED: {reason}");
}
