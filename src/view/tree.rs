//! One pixel's ray tree for the page: every segment the tracer cast for it, with its kind (the
//! colour it is drawn in), its end points and its outcome.

use crate::debug_view::{LoggedKind, RayRecorder};
use crate::reference::Reference;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::stats::RayCounts;
use serde::Serialize;

/// How far a ray that hits nothing is drawn, in scene-size units.
const MISS_LENGTH: f32 = 10.0;

/// The kinds of segment, each drawn in its own colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// From the eye (white/grey).
    Camera,
    /// A mirror ray (red).
    Reflection,
    /// Towards a light point (green; dark red when blocked).
    Shadow,
}

/// One segment.
#[derive(Clone, Debug, Serialize)]
pub struct Segment {
    /// Kind.
    pub kind: Kind,
    /// 0 for the camera hit, k after k reflections.
    pub depth: u32,
    /// Start.
    pub from: [f32; 3],
    /// End: the hit, the light point, or far along a miss.
    pub to: [f32; 3],
    /// Whether a camera or mirror ray hit something.
    pub hit: bool,
    /// A shadow ray's outcome (null when shadows are off and none was cast).
    pub blocked: Option<bool>,
}

/// The tree of one pixel.
#[derive(Clone, Debug, Serialize)]
pub struct PixelTree {
    /// Column, from the left.
    pub x: u32,
    /// Row, from the top.
    pub y: u32,
    /// The pixel's linear colour.
    pub colour: [f32; 3],
    /// The segments, in tree order.
    pub segments: Vec<Segment>,
    /// Counts by kind.
    pub counts: RayCounts,
}

/// The ray tree of pixel (x, y), which the caller has checked is inside the image.
pub fn pixel_tree(scene: &Scene, settings: &RenderSettings, x: u32, y: u32) -> PixelTree {
    let mut recorder = RayRecorder {
        miss_length: MISS_LENGTH,
        ..Default::default()
    };
    let reference = Reference::new(scene, settings);
    let mut counts = RayCounts::default();
    let colour = reference.pixel(y * settings.width + x, &mut counts, &mut recorder);
    let segments = recorder
        .tree_order()
        .into_iter()
        .map(|r| {
            let (kind, hit, blocked) = match r.kind {
                LoggedKind::Path { hit } if r.bounce == 0 => (Kind::Camera, hit.is_some(), None),
                LoggedKind::Path { hit } => (Kind::Reflection, hit.is_some(), None),
                LoggedKind::Shadow { blocked, .. } => (Kind::Shadow, false, blocked),
            };
            Segment {
                kind,
                depth: r.bounce,
                from: r.from.to_array(),
                to: r.to.to_array(),
                hit,
                blocked,
            }
        })
        .collect();
    PixelTree {
        x,
        y,
        colour: colour.to_array(),
        segments,
        counts,
    }
}
