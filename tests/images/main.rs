//! Whole-image tests: the wavefront engine against its whole-image twin, the reference renderer;
//! a cancelled render that stops within a unit per thread, an uncancelled one unchanged;
//! determinism across seeds, threads and runs; and both engines against the independent f64
//! oracle (`tests/oracle/`), pixel by pixel and in the mean over seeds, textures included. One
//! test binary; each file is a module (docs/TESTING.md).

#[path = "../common/mod.rs"]
mod common;
#[path = "../oracle/mod.rs"]
mod oracle;

mod cancel;
mod determinism;
mod oracle_agreement;
mod oracle_bias;
mod oracle_textures;
mod wavefront_images;
