//! One pixel's ray tree: every ray its render traces (camera, reflection and shadow rays), where
//! each goes, what it hits or what blocks it, and the colour each adds to the pixel.
//!
//! ```text
//! trace_pixel(scene, settings, x, y) -> RayTree       tracer.rs: recorded from Reference::pixel
//! check_pixel(scene, settings, &tree) -> PixelCheck   check.rs: Σ contributions, rays vs engines
//! summary(&tree) -> String                            summary.rs: the readable tree
//! mesh::groups(scene, &tree) -> obj.rs / ply.rs       the scene and the rays for 3D viewers
//! scene_bounds(scene) -> (min, max)                   mesh.rs: sizes misses, markers, near planes
//! view.rs (debug camera), draw.rs (rays over its render or render --debug-pixel's), palette.rs
//! ```
//!
//! The types (tree.rs) are plain serde values with a JSON Schema
//! (docs/schema/ray-tree.schema.json, docs/TRACE.md).

pub(crate) mod check;
pub mod draw;
pub mod mesh;
pub mod obj;
pub mod palette;
pub mod ply;
pub mod summary;
pub(crate) mod tracer;
pub(crate) mod tree;
pub mod view;

pub use check::{check_pixel, contribution_sum, render_pixel_counted, tree_counts};
pub use mesh::scene_bounds;
pub use summary::summary;
pub use tracer::{TraceError, primitive_ref, trace_pixel};
pub use tree::{
    BlockerInfo, CameraInfo, PixelCheck, PixelRef, PrimitiveRef, PrimitiveShape, RayCountCheck,
    RayTree, SCHEMA_ID, Segment, SegmentKind, ShadowInfo, SurfaceInfo, TraceSettings,
};
