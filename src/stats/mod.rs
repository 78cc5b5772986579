//! The statistics the tools share, in one place, so that bench, its A/B gate, the variance
//! study and the viewer summarise alike. Statistics are not outputs: the records and reports
//! that print these figures are.
//!
//! ```text
//! median.rs     the median, its distribution-free interval (order statistics, sign test),
//!               modified Z-scores and outliers
//! bootstrap.rs  percentile-bootstrap intervals, plain and grouped, from a fixed seed
//! fit.rs        the least-squares log-log fit of a power law (MSE against N)
//! looks.rs      planned looks with a Bonferroni split (bench --until-decided)
//! ```

pub mod bootstrap;
pub mod fit;
pub mod looks;
pub mod median;

pub use bootstrap::{
    BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, bootstrap_interval, grouped_bootstrap_interval,
};
pub use fit::{LogLogFit, loglog_fit};
pub use median::*;
