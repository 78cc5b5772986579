//! What the criterion benches share: criterion's settings and the test-mode switch. (A folder
//! module, so that cargo does not take it for a bench of its own.)
#![allow(dead_code)]

use criterion::Criterion;
use std::time::Duration;

/// Criterion's test mode: `cargo bench -- --test`, or `cargo test --all-targets`, which runs
/// the bench binary without the `--bench` flag that `cargo bench` passes. A bench in test mode
/// runs its code once on small inputs, so that CI keeps it from rotting.
pub fn test_mode() -> bool {
    let args: Vec<String> = std::env::args().collect();
    args.iter().any(|a| a == "--test") || !args.iter().any(|a| a == "--bench")
}

/// Criterion without plots: the plotters backend panics without system fonts
/// (FontUnavailable) on the lab machine.
pub fn criterion() -> Criterion {
    Criterion::default().without_plots()
}

/// For benches whose one iteration is a whole frame or ray set: 10 samples, `warm_up`, 2 s of
/// measuring, then criterion's own command-line flags.
pub fn criterion_for_frames(warm_up: Duration) -> Criterion {
    criterion()
        .sample_size(10)
        .warm_up_time(warm_up)
        .measurement_time(Duration::from_secs(2))
        .configure_from_args()
}
