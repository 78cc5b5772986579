//! The report of a study: its tables and files, the summary across cases, the plots, the
//! spectrum plots, the contact sheet and the perceived-error tables.

pub(crate) mod perceived_report;
pub(crate) mod plot;
pub mod sheet;
pub mod spectrum_plot;
pub mod summary;
pub mod tables;
