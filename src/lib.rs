//! raywave: a data-oriented SIMD wavefront ray tracer for the lab's Cornell-box scenes.
//!
//! The pieces, in the order a frame uses them: [`scene`] (the lab's extended `.obj`),
//! [`camera`] and [`sampling`] (where rays and light points go, as pure functions of
//! (pixel, sample, bounce, light, dimension, seed)), [`geometry`] (scalar intersection kernels),
//! [`shading`] (the lab's Shade), and the engines: [`reference`] (scalar, recursive).
#![warn(missing_docs)]

pub mod bench;
pub mod camera;
pub mod debug_view;
pub mod engine;
pub mod error;
pub mod film;
pub mod geometry;
pub mod machine;
pub mod meshgen;
pub mod options;
pub mod output;
pub mod peer;
pub mod reference;
pub mod report;
pub mod sampling;
pub mod scene;
pub mod settings;
pub mod shading;
pub mod spawn;
pub mod stats;
pub mod terminal;
pub mod variance;
pub mod wavefront;

/// Which SIMD instructions this build uses for `wide::f32x8`, decided at compile time.
pub fn simd_path() -> &'static str {
    if cfg!(all(target_feature = "avx2", target_feature = "fma")) {
        "avx2+fma (f32x8 in one 256-bit register)"
    } else if cfg!(target_feature = "avx") {
        "avx (f32x8 in one 256-bit register, no FMA)"
    } else if cfg!(target_feature = "sse2") {
        "sse2 (f32x8 as two 128-bit halves)"
    } else {
        "scalar fallback (no x86 SIMD)"
    }
}
