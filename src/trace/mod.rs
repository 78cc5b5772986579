//! One pixel's ray tree: every ray its render traces (camera, reflection and shadow rays), where
//! each goes, what it hits or what blocks it, and the colour each adds to the pixel.
//!
//! ```text
//! trace_pixel(scene, settings, x, y) -> RayTree       tracer.rs: recorded from Reference::pixel
//! check_pixel(scene, settings, &tree) -> PixelCheck   check.rs: Σ contributions, rays vs engines
//! scene_geometry(scene) -> SceneGeometry              scene_view.rs: triangles, spheres, lights
//! summary(&tree) -> String                            summary.rs: the readable tree
//! mesh::groups(scene, &tree) -> obj.rs / ply.rs       the scene and the rays for 3D viewers
//! view.rs (debug camera), draw.rs (rays over its render or render --debug-pixel's), palette.rs
//! ```
//!
//! The types (tree.rs, scene_view.rs) are plain serde values with a JSON Schema
//! (docs/schema/ray-tree.schema.json, docs/TRACE.md).

pub(crate) mod check;
pub mod draw;
pub mod mesh;
pub mod obj;
pub mod palette;
pub mod ply;
pub(crate) mod scene_view;
pub mod summary;
pub(crate) mod tracer;
pub(crate) mod tree;
pub mod view;

pub use check::{check_pixel, contribution_sum, render_pixel_counted, tree_counts};
pub use scene_view::{
    LightView, MaterialView, SceneGeometry, SphereView, TriangleView, scene_bounds, scene_geometry,
};
pub use summary::summary;
pub use tracer::{TraceError, primitive_ref, trace_pixel, trace_settings};
pub use tree::{
    BlockerInfo, CameraInfo, PixelCheck, PixelRef, PrimitiveRef, PrimitiveShape, RayCountCheck,
    RayTree, SCHEMA_ID, Segment, SegmentKind, ShadowInfo, SurfaceInfo, TraceSettings,
};
