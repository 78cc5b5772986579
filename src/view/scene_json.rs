//! The scene as the page's WebGL view draws it: flat arrays of triangle corners and colours,
//! spheres as centre and radius (the page tessellates them), lights as outlines, the bounds
//! (to place the orbit camera) and the render camera's frame (to draw it).

use crate::render::camera::CameraRays;
use crate::render::scene::{Camera, Material, Scene};
use crate::trace::scene_bounds;
use glam::Vec3;
use serde::Serialize;

/// The most triangles sent to the page: beyond this the 3D view shows the first ones and says
/// so (a 1M-triangle mesh would be 100 MB of JSON; the render itself is not limited).
const MAX_DRAWN_TRIANGLES: usize = 200_000;

/// The scene for WebGL.
#[derive(Serialize)]
pub(crate) struct SceneJson {
    /// Where the scene came from.
    pub source: String,
    /// Triangle corners, 9 floats per triangle.
    pub positions: Vec<f32>,
    /// Display colour of each triangle, 3 floats per triangle.
    pub colors: Vec<f32>,
    /// Triangles in the scene (more than drawn when `truncated`).
    pub triangle_count: usize,
    /// True when only the first [`MAX_DRAWN_TRIANGLES`] are sent.
    pub truncated: bool,
    pub spheres: Vec<SphereJson>,
    /// Area lights: corners in order around the outline.
    pub lights: Vec<Vec<[f32; 3]>>,
    /// Axis-aligned bounds of the scene's triangles and spheres (`trace::scene_bounds`, all of
    /// them when `truncated`): [min, max].
    pub bounds: [[f32; 3]; 2],
}

/// A sphere for WebGL.
#[derive(Serialize)]
pub(crate) struct SphereJson {
    pub center: [f32; 3],
    pub radius: f32,
    /// Display colour.
    pub color: [f32; 3],
}

/// The colour a surface is drawn with: its emission for lights, else its diffuse colour plus
/// half its mirror colour (so mirrors read as light grey), clamped to [0, 1]; grey without one.
fn display_colour(m: Option<&Material>) -> [f32; 3] {
    let Some(m) = m else { return [0.5; 3] };
    let c = if m.emitted.max_element() > 0.0 {
        m.emitted / m.emitted.max_element()
    } else {
        m.diffuse + 0.5 * m.reflective
    };
    c.clamp(Vec3::ZERO, Vec3::ONE).to_array()
}

impl SceneJson {
    /// The scene's geometry for drawing.
    pub(crate) fn new(scene: &Scene) -> SceneJson {
        let drawn = scene.triangles.len().min(MAX_DRAWN_TRIANGLES);
        let mut positions = Vec::with_capacity(drawn * 9);
        let mut colors = Vec::with_capacity(drawn * 3);
        for t in &scene.triangles[..drawn] {
            for p in [t.v0, t.v0 + t.e1, t.v0 + t.e2] {
                positions.extend_from_slice(&p.to_array());
            }
            colors.extend_from_slice(&display_colour(scene.materials.get(t.material as usize)));
        }
        let spheres = scene
            .spheres
            .iter()
            .map(|s| SphereJson {
                center: s.center.to_array(),
                radius: s.radius,
                color: display_colour(scene.materials.get(s.material as usize)),
            })
            .collect();
        let lights = scene
            .lights
            .iter()
            .map(|l| {
                let mut c = l.corners();
                // A parallelogram's corners come as o, o+u, o+v, o+u+v: swap the last two to
                // go round the outline.
                if c.len() == 4 {
                    c.swap(2, 3);
                }
                c.iter().map(|p| p.to_array()).collect()
            })
            .collect();
        let (lo, hi) = match scene_bounds(scene) {
            // Nothing to draw: a unit box around the origin.
            (lo, hi) if lo == hi => (Vec3::splat(-1.0), Vec3::ONE),
            bounds => bounds,
        };
        SceneJson {
            source: scene.source.clone(),
            positions,
            colors,
            triangle_count: scene.triangles.len(),
            truncated: drawn < scene.triangles.len(),
            spheres,
            lights,
            bounds: [lo.to_array(), hi.to_array()],
        }
    }
}

/// The render camera's frame for drawing: its eye and the four corners of the image at unit
/// distance along the view direction, top-left first, clockwise.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct CameraFrame {
    pub eye: [f32; 3],
    /// Image corners one unit in front of the eye.
    pub corners: [[f32; 3]; 4],
}

impl CameraFrame {
    /// The frame of `camera` for a `width` × `height` image (the lab's square field of view,
    /// cropped by non-square images).
    pub(crate) fn new(camera: &Camera, width: u32, height: u32) -> CameraFrame {
        let rays = CameraRays::new(camera, width, height);
        let scale = 1.0 / width.max(height) as f32;
        let (hx, hy) = (width as f32 * scale, height as f32 * scale);
        let corner = |sx: f32, sy: f32| {
            (rays.origin + rays.forward + sx * hx * rays.right + sy * hy * rays.up).to_array()
        };
        CameraFrame {
            eye: rays.origin.to_array(),
            corners: [
                corner(-1.0, 1.0),
                corner(1.0, 1.0),
                corner(1.0, -1.0),
                corner(-1.0, -1.0),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builtin_box_is_sent_whole_with_its_lights() {
        let scene = Scene::builtin_default();
        let json = SceneJson::new(&scene);
        assert_eq!(json.positions.len(), 9 * scene.triangles.len());
        assert_eq!(json.colors.len(), 3 * scene.triangles.len());
        assert_eq!(json.spheres.len(), scene.spheres.len());
        assert_eq!(json.lights.len(), scene.lights.len());
        assert!(!json.truncated);
    }

    #[test]
    fn a_textured_material_is_drawn_in_its_textures_average_colour() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/textured_box.obj");
        let scene = Scene::load(std::path::Path::new(path)).unwrap();
        let json = SceneJson::new(&scene);
        let textured = scene
            .materials
            .iter()
            .position(|m| m.texture.is_some())
            .unwrap();
        let average = scene.textures[0].average;
        // The mean of the texture's linear texels, not black (its material has no `diffuse`).
        assert!(average.min_element() > 0.1, "{average}");
        let t = scene
            .triangles
            .iter()
            .position(|t| t.material as usize == textured)
            .unwrap();
        assert_eq!(json.colors[3 * t..3 * t + 3], average.to_array());
    }

    #[test]
    fn the_frame_corners_are_the_corner_pixels_directions() {
        let cam = Camera::default();
        let frame = CameraFrame::new(&cam, 4, 2);
        let rays = CameraRays::new(&cam, 4, 2);
        // The top-left corner of the image: screen point (0, 0.25) for a 4×2 image.
        let d = rays.ray(0.0, 0.75).direction;
        let c = Vec3::from_array(frame.corners[0]) - rays.origin;
        assert!(c.normalize().dot(d) > 0.99999, "{c} vs {d}");
    }
}
