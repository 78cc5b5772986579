//! The tree drawn over an image, two ways:
//!
//! - [`Overlay`] (`raywave trace-pixel --png`): over a render from the debug camera, as the
//!   lab's debug mode draws it: every segment twice, first a faint copy over everything
//!   (see-through), then in full colour where nothing in the scene is in front of it
//!   (depth-tested against the first hit through each pixel);
//! - [`draw_over_render`] (`raywave render --debug-pixel`): over the render itself, from its own
//!   camera: every segment in full colour, no depth test, and a cross on each camera ray's end
//!   (a camera ray runs along the line of sight and projects to a dot).
//!
//! ```text
//! Overlay:
//! depth[pixel] = distance to the first hit of the ray through the pixel's centre (∞: none)
//! for each segment (clipped to the eye's near plane), sampled twice per pixel of its length:
//!     faint:  pixel = 0.65·pixel + 0.35·colour   (once per pixel and segment)
//!     solid:  pixel = colour   where |p − eye| ≤ depth + tolerance (and on the dash, if dashed)
//! draw_over_render:
//! for each segment, 2049 points evenly along it: pixel = colour (where in front of the eye)
//! for each camera segment: a 9-pixel cross at its end
//! ```

use super::palette::{CAMERA, MAIN_CAMERA, Rgb, Style};
use super::tree::{RayTree, SegmentKind};
use super::view::{camera_marker, project};
use crate::render::camera::CameraRays;
use crate::render::geometry::Accel;
use crate::render::scene::{Camera, Scene};
use glam::Vec3;
use image::RgbImage;
use rayon::prelude::*;

/// How much of a segment's colour its see-through copy mixes into the image.
const FAINT_ALPHA: f32 = 0.35;
/// Dash and gap length of blocked shadow rays, in pixels.
const DASH_PIXELS: f32 = 6.0;
/// The depth test lets a segment through this fraction of the scene's diagonal behind the first
/// surface (segments end on surfaces).
const DEPTH_TOLERANCE: f32 = 2e-3;
/// The render camera's marker is a frustum this fraction of the scene's diagonal deep.
pub const MARKER_SIZE: f32 = 0.08;

/// Distance to the first hit through each pixel's centre (row-major), ∞ where nothing is hit.
pub fn depth_buffer(scene: &Scene, camera: &CameraRays, two_sided: bool) -> Vec<f32> {
    let accel = Accel::new(scene);
    (0..camera.width * camera.height)
        .into_par_iter()
        .map(|pixel| {
            let (x, y) = camera.screen(pixel, 0.5, 0.5);
            let ray = camera.ray(x, y);
            accel.closest(scene, &ray, f32::INFINITY, two_sided).t
        })
        .collect()
}

/// What to draw over the debug render.
pub struct Overlay<'a> {
    /// The debug camera's rays (its image size is the image's).
    pub camera: CameraRays,
    /// Its depth buffer (`depth_buffer`).
    pub depth: &'a [f32],
    /// The scene's diagonal: sets the depth tolerance, the near plane and the marker's size.
    pub diagonal: f32,
}

impl Overlay<'_> {
    /// Draws the tree's segments (unless `rays` is false) and the render camera's marker.
    pub fn draw(
        &self,
        img: &mut RgbImage,
        tree: &RayTree,
        main: &Camera,
        main_aspect: f32,
        rays: bool,
    ) {
        let mut lines: Vec<(Vec3, Vec3, Rgb, bool)> = Vec::new();
        if rays {
            for s in &tree.segments {
                let style = Style::of(s);
                lines.push((
                    Vec3::from_array(s.origin),
                    Vec3::from_array(s.end),
                    style.colour(),
                    style.dashed(),
                ));
            }
        }
        for (a, b) in camera_marker(main, main_aspect, MARKER_SIZE * self.diagonal) {
            lines.push((a, b, MAIN_CAMERA, false));
        }
        let mut stamp = vec![0u32; (img.width() * img.height()) as usize];
        for (i, &(a, b, colour, dashed)) in lines.iter().enumerate() {
            self.line(img, a, b, dashed, &mut |img, x, y, _| {
                let k = (y * img.width() + x) as usize;
                // Once per pixel and segment, so a line's faint copy has one alpha everywhere.
                if stamp[k] != i as u32 + 1 {
                    stamp[k] = i as u32 + 1;
                    let p = img.get_pixel_mut(x, y);
                    for (channel, &c) in p.0.iter_mut().zip(&colour) {
                        *channel = (f32::from(*channel) * (1.0 - FAINT_ALPHA)
                            + f32::from(c) * FAINT_ALPHA)
                            .round() as u8;
                    }
                }
            });
        }
        let tolerance = DEPTH_TOLERANCE * self.diagonal;
        let width = self.camera.width;
        for &(a, b, colour, dashed) in &lines {
            self.line(img, a, b, dashed, &mut |img, x, y, dist| {
                if dist <= self.depth[(y * width + x) as usize] + tolerance {
                    img.put_pixel(x, y, image::Rgb(colour));
                }
            });
        }
    }

    /// Calls `plot(img, x, y, distance from the eye)` for the pixels along a → b (clipped to
    /// the near plane), leaving the gaps of a dashed line out.
    fn line(
        &self,
        img: &mut RgbImage,
        mut a: Vec3,
        mut b: Vec3,
        dashed: bool,
        plot: &mut dyn FnMut(&mut RgbImage, u32, u32, f32),
    ) {
        let cam = &self.camera;
        let near = 1e-4 * self.diagonal.max(f32::MIN_POSITIVE);
        let (da, db) = (
            (a - cam.origin).dot(cam.forward),
            (b - cam.origin).dot(cam.forward),
        );
        if !(da > near || db > near) {
            return;
        }
        if da < near {
            a += (b - a) * ((near - da) / (db - da));
        } else if db < near {
            b += (a - b) * ((near - db) / (da - db));
        }
        let (Some(pa), Some(pb)) = (project(cam, a), project(cam, b)) else {
            return;
        };
        let length = (pb.0 - pa.0).hypot(pb.1 - pa.1);
        if !length.is_finite() {
            return;
        }
        // Two samples per pixel of length; a segment far longer than the image (one ending just
        // past the near plane) is capped, its samples then spread over it.
        let limit = 8.0 * (img.width() + img.height()) as f32;
        let steps = (2.0 * length).clamp(1.0, limit).ceil() as u32;
        for k in 0..=steps {
            let f = k as f32 / steps as f32;
            if dashed && ((f * length / DASH_PIXELS) as u64) % 2 == 1 {
                continue;
            }
            let Some((x, y, dist)) = project(cam, a.lerp(b, f)) else {
                continue;
            };
            if x >= 0.0 && y >= 0.0 && x < img.width() as f32 && y < img.height() as f32 {
                plot(img, x as u32, y as u32, dist);
            }
        }
    }
}

/// Draws the tree's segments over `img`, the render of `camera` (`raywave render
/// --debug-pixel`): each in its colour (`Style`), in tree order, then a cross in the camera
/// rays' colour on each camera segment's end (its hit, or `miss_length` out), drawn last so the
/// rays leaving that hit do not cover it.
pub fn draw_over_render(img: &mut RgbImage, tree: &RayTree, camera: &CameraRays) {
    for s in &tree.segments {
        let (a, b) = (Vec3::from_array(s.origin), Vec3::from_array(s.end));
        let colour = Style::of(s).colour();
        // Walk the 3D segment so the part in front of the eye is drawn even if an end is
        // behind it.
        let steps = 2048;
        for k in 0..=steps {
            let p = a.lerp(b, k as f32 / steps as f32);
            if let Some((x, y)) = project_onto_render(camera, p) {
                put(img, x.floor() as i64, y.floor() as i64, colour);
            }
        }
    }
    for s in tree
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Camera)
    {
        if let Some((x, y)) = project_onto_render(camera, Vec3::from_array(s.end)) {
            for d in -4..=4 {
                put(img, x as i64 + d, y as i64, CAMERA);
                put(img, x as i64, y as i64 + d, CAMERA);
            }
        }
    }
}

/// Projects a world point to continuous pixel coordinates (x right, y down), or None within
/// 1e-4 of the eye's plane or behind it: `view::project`'s mapping with another near limit and
/// another order of f32 operations, kept so that `render --debug-pixel` draws on the same
/// pixels as it always has.
fn project_onto_render(camera: &CameraRays, p: Vec3) -> Option<(f32, f32)> {
    let d = p - camera.origin;
    let depth = d.dot(camera.forward);
    if depth <= 1e-4 {
        return None;
    }
    let half = camera.right.length();
    let sx = d.dot(camera.right) / (half * half * depth);
    let sy = d.dot(camera.up) / (half * half * depth);
    let (w, h) = (camera.width as f32, camera.height as f32);
    let m = w.max(h);
    let x = ((sx + 1.0) * 0.5 - 0.5) * m + 0.5 * w;
    let y = ((sy + 1.0) * 0.5 - 0.5) * m + 0.5 * h;
    Some((x, h - y))
}

/// Sets a pixel if (x, y) lies inside the image.
fn put(img: &mut RgbImage, x: i64, y: i64, colour: Rgb) {
    if x >= 0 && y >= 0 && (x as u64) < img.width() as u64 && (y as u64) < img.height() as u64 {
        img.put_pixel(x as u32, y as u32, image::Rgb(colour));
    }
}
