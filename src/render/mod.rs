//! The renderer: a scene and its settings in, a film and its ray counts out.
//!
//! Read top to bottom, these modules are the layers of a frame: the scene and the settings;
//! the kernels both engines share (camera, sampling, geometry, shading, spawn); the two
//! engines, [`reference`](mod@reference) (scalar, recursive, written to be obviously right)
//! and [`wavefront`] (SIMD batches through stages); the [`film`] they fill; and [`engine`],
//! the one entry point that chooses between them. Nothing here depends on a tool: the
//! library built with `--no-default-features` is this layer alone.

pub mod scene;
pub mod settings;

pub mod camera;
pub mod geometry;
pub mod sampling;
pub mod shading;
pub mod spawn;

pub mod reference;
pub mod wavefront;

pub mod engine;
pub mod film;
pub mod per_kind;
pub mod progress;

#[cfg(feature = "textures")]
pub mod digest;
pub mod error;
pub mod quote;
