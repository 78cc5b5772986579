//! raywave: a data-oriented SIMD wavefront ray tracer for the lab's Cornell-box scenes.
//!
//! Two engines render the same image from the same samples:
//!
//! - the **wavefront** engine ([`render::wavefront`]) moves rays through stages in
//!   structure-of-arrays batches, 8 or 16 lanes at a time (16 on AVX-512 builds): generate →
//!   intersect → shadow → film → reflect, tiles spread over cores with rayon, meshes through its
//!   own 8-wide BVH;
//! - the **reference** ([`render::reference`](mod@render::reference)) is the lab's recursive
//!   renderer, one scalar ray at a time, written to be obviously right: the twin every fast path
//!   is checked and timed against.
//!
//! Callers choose one through [`render::engine::Engine`]. The modules are in layers: the
//! renderer ([`render`]), outputs and records (`output`), the tools built on both (`diff`,
//! `trace`, `view`, `variance`, `bench`), and the binary's `cli/`. What every module
//! holds is in the module map of docs/ARCHITECTURE.md.
//!
//! A tiny render of a scene given as text, by both engines:
//!
//! ```
//! use raywave::render::engine::Engine;
//! use raywave::render::progress::Progress;
//! use raywave::render::scene::parse_scene_str;
//! use raywave::render::settings::{RenderSettings, ShadowMode};
//!
//! // A white floor under a square light: materials first, then `m i` selects one for the
//! // faces that follow (the lab's format, docs/SCENE_FORMAT.md).
//! let scene = parse_scene_str(
//!     "material\ndiffuse 0.8 0.8 0.8\n\
//!      material\nemitted 1 1 1\n\
//!      v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n\
//!      v -0.2 1 -0.2\nv 0.2 1 -0.2\nv 0.2 1 0.2\nv -0.2 1 0.2\n\
//!      m 0\nf 1 4 3 2\nm 1\nf 5 6 7 8\n",
//!     "floor.obj",
//! )?;
//! let settings = RenderSettings {
//!     width: 16,
//!     height: 16,
//!     shadows: ShadowMode::Soft,
//!     shadow_samples: 4,
//!     ..RenderSettings::default()
//! };
//! let (wavefront, stats) = Engine::Wavefront.render(&scene, &settings, 64, &Progress::SILENT);
//! let (reference, _) = Engine::Reference.render(&scene, &settings, 64, &Progress::SILENT);
//! assert_eq!(stats.counts.camera, 16 * 16);
//! // The floor is lit: some pixel is brighter than the ambient term alone.
//! assert!(wavefront.pixels.iter().any(|p| p.x > 0.2 * 0.8));
//! // Without mirrors the two engines agree bit for bit.
//! assert_eq!(wavefront, reference);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs, unreachable_pub)]

// The layers, each depending only on those above it; docs/ARCHITECTURE.md has the module map.
//
// The renderer: what a frame needs, with no tool's dependencies (`--no-default-features`
// builds only this, as the instruction-count gate's child does).
pub mod render;

// Outputs and records: where a command's files go, the image formats, the render record, the
// machine and build it describes, false-colour figures and the terminal.
#[cfg(feature = "tools")]
pub mod output;

// What the tools share that is not an output: sharding a command's work and merging its
// parts, and the statistics.
#[cfg(feature = "tools")]
pub mod shard;
#[cfg(feature = "tools")]
pub mod stats;

// The tools built on both, one folder per command.
#[cfg(feature = "tools")]
pub mod bench;
#[cfg(feature = "tools")]
pub mod diff;
#[cfg(feature = "tools")]
pub mod frame;
#[cfg(feature = "tools")]
pub mod trace;
#[cfg(feature = "tools")]
pub mod variance;
#[cfg(feature = "tools")]
pub mod view;

/// Which SIMD instructions this build's wavefront engine uses by default (`--lanes auto`),
/// decided at compile time: `f32x16` on AVX-512 builds, else `f32x8` (from the `wide` crate).
pub fn simd_path() -> &'static str {
    simd_path_for(render::wavefront::lanes::LaneWidth::Auto)
}

/// Which SIMD instructions the wavefront engine's kernels use at lane width `width`: the
/// brute-force, light and shading kernels run that wide, the mesh BVH 8-wide.
pub fn simd_path_for(width: render::wavefront::lanes::LaneWidth) -> &'static str {
    use render::wavefront::lanes::LaneWidth;
    let avx2 = cfg!(all(target_feature = "avx2", target_feature = "fma"));
    match width.resolve() {
        LaneWidth::Sixteen => {
            if cfg!(target_feature = "avx512f") {
                "avx512 (f32x16 in one 512-bit register)"
            } else if avx2 {
                "avx2+fma (f32x16 as two 256-bit halves)"
            } else if cfg!(target_feature = "avx") {
                "avx (f32x16 as two 256-bit halves, no FMA)"
            } else if cfg!(target_feature = "sse2") {
                "sse2 (f32x16 as four 128-bit quarters)"
            } else {
                "scalar fallback (f32x16, no x86 SIMD)"
            }
        }
        _ => {
            if avx2 {
                "avx2+fma (f32x8 in one 256-bit register)"
            } else if cfg!(target_feature = "avx") {
                "avx (f32x8 in one 256-bit register, no FMA)"
            } else if cfg!(target_feature = "sse2") {
                "sse2 (f32x8 as two 128-bit halves)"
            } else {
                "scalar fallback (no x86 SIMD)"
            }
        }
    }
}
