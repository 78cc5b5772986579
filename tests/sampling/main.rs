//! Statistical tests of sampling: the samples both renderers draw (uniform in their strata,
//! independent across every key field), every point set's points (uniform, independent, and
//! what its construction promises), the samplers' limits, placement and edges, unbiased soft
//! shadows (against closed forms and the f64 oracle, `tests/oracle/`), and the variance study's
//! statistics and report. One test binary; each file is a module (docs/TESTING.md).

#[path = "../common/mod.rs"]
mod common;
#[path = "../oracle/mod.rs"]
mod oracle;

mod low_band_share;
mod point_statistics;
mod sample_streams;
mod sampler_limits;
mod sampling;
mod sampling_edges;
mod sampling_study;
mod soft_shadows;
mod study_split;
mod variance_report;
mod variance_stats;
