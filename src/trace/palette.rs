//! The colours of the debug view, the lab's by default: camera rays white, reflection rays red,
//! shadow rays green, and blocked shadow rays magenta (and dashed in the PNG), so that a blocked
//! ray stands out against both the green ones and a dark scene. docs/TRACE.md lists them.

use super::tree::{Segment, SegmentKind};

/// An 8-bit sRGB colour.
pub type Rgb = [u8; 3];

/// Camera rays.
pub const CAMERA: Rgb = [255, 255, 255];
/// Reflection (mirror) rays.
pub const REFLECTION: Rgb = [255, 40, 40];
/// Shadow rays that reach their light point.
pub const SHADOW_VISIBLE: Rgb = [40, 230, 40];
/// Shadow rays that something blocks.
pub const SHADOW_BLOCKED: Rgb = [230, 0, 230];
/// Shadow rays with shadows off (not tested: the point counts as visible).
pub const SHADOW_UNTESTED: Rgb = [160, 255, 160];
/// The render camera's marker.
pub const MAIN_CAMERA: Rgb = [255, 210, 0];

/// How a segment is drawn and grouped: its kind, and for shadow rays the outcome.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Style {
    /// A camera ray.
    Camera,
    /// A reflection ray.
    Reflection,
    /// A shadow ray that reaches the light.
    ShadowVisible,
    /// A blocked shadow ray.
    ShadowBlocked,
    /// A shadow ray with shadows off.
    ShadowUntested,
}

impl Style {
    /// Every style, in the order groups are written.
    pub const ALL: [Style; 5] = [
        Style::Camera,
        Style::Reflection,
        Style::ShadowVisible,
        Style::ShadowBlocked,
        Style::ShadowUntested,
    ];

    /// The style of a segment.
    pub fn of(segment: &Segment) -> Style {
        match segment.kind {
            SegmentKind::Camera => Style::Camera,
            SegmentKind::Reflection => Style::Reflection,
            SegmentKind::Shadow => match segment.shadow.as_ref().and_then(|s| s.blocked) {
                Some(true) => Style::ShadowBlocked,
                Some(false) => Style::ShadowVisible,
                None => Style::ShadowUntested,
            },
        }
    }

    /// Each style's colour and name, in declaration order.
    const LOOK: [(Rgb, &'static str); 5] = [
        (CAMERA, "camera"),
        (REFLECTION, "reflection"),
        (SHADOW_VISIBLE, "shadow_visible"),
        (SHADOW_BLOCKED, "shadow_blocked"),
        (SHADOW_UNTESTED, "shadow_untested"),
    ];

    /// Its colour.
    pub fn colour(self) -> Rgb {
        Style::LOOK[self as usize].0
    }

    /// Its name in the viewer's palette (and, for camera and reflection rays, the summary's);
    /// its group (OBJ object) is `rays_` and the name.
    pub fn name(self) -> &'static str {
        Style::LOOK[self as usize].1
    }

    /// Drawn dashed in the PNG.
    pub fn dashed(self) -> bool {
        self == Style::ShadowBlocked
    }
}
