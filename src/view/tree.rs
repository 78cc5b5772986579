//! One pixel's ray tree for the page: `raywave::trace`'s [`RayTree`] (every segment the
//! render's recursion casts for the pixel, its outcome and the colour it adds), checked against
//! both engines' render of that pixel.

use super::http::ApiError;
use crate::render::scene::Scene;
use crate::render::settings::RenderSettings;
use crate::trace::tracer::max_segments;
use crate::trace::{RayTree, TraceError, check_pixel, trace_pixel};

/// The most segments a tree may have before it is traced (its JSON is about 1 KB a segment, and
/// the page draws and lists each one).
const MAX_TREE_SEGMENTS: u64 = 50_000;

/// The ray tree of pixel (x, y) (from the top-left), with `check` filled in; a pixel outside
/// the image, or settings whose tree could pass [`MAX_TREE_SEGMENTS`], are a 400.
pub(crate) fn pixel_tree(
    scene: &Scene,
    settings: &RenderSettings,
    x: u32,
    y: u32,
) -> Result<RayTree, ApiError> {
    let bound = max_segments(scene, settings);
    if bound > MAX_TREE_SEGMENTS {
        return Err(ApiError::bad(format!(
            "this pixel's tree could have {bound} segments (aa × (bounces + 1) × (1 + lights × \
             points per light)): the viewer shows at most {MAX_TREE_SEGMENTS}; lower aa, bounces \
             or shadow samples"
        )));
    }
    let mut tree =
        trace_pixel(scene, settings, x, y).map_err(|e: TraceError| ApiError::bad(e.to_string()))?;
    tree.check = Some(check_pixel(scene, settings, &tree));
    Ok(tree)
}
