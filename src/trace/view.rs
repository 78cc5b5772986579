//! The debug camera: where the tree is seen from, as in the lab's debug mode after the user
//! orbits away from the render's camera.
//!
//! ```text
//! eye = look_at + distance · R(up, orbit) · (from − look_at)   from: --view-from, else the render's eye
//! looks at the render camera's point of interest, with its up axis and field of view
//! project(p): the inverse of CameraRays' pixel -> ray mapping (continuous pixel coordinates)
//! ```

use super::summary::v3;
use crate::render::camera::CameraRays;
use crate::render::scene::Camera;
use glam::{Quat, Vec3};

/// The orbit angle about the up axis when neither `--view-from` nor `--orbit` is given, in
/// degrees.
pub const DEFAULT_ORBIT_DEGREES: f32 = 30.0;

/// How the debug camera is placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewPlacement {
    /// The eye before orbiting; the render camera's eye when `None`.
    pub from: Option<Vec3>,
    /// Degrees about the scene's up axis (through the render camera's point of interest),
    /// counter-clockwise seen from above.
    pub orbit_degrees: f32,
    /// The eye's distance from the point of interest is multiplied by this (> 0): above 1 the
    /// debug camera backs away and shows more around the tree.
    pub distance: f32,
}

impl ViewPlacement {
    /// The debug camera for a render camera: same point of interest, up axis and field of view.
    /// Errors when the eye lands on the point of interest or on its up axis through it (no
    /// view direction, or none the up axis can orient).
    pub fn camera(&self, main: &Camera) -> Result<Camera, String> {
        let up = main.up.normalize();
        let from = self.from.unwrap_or(main.position);
        let offset = from - main.point_of_interest;
        let rotated =
            Quat::from_axis_angle(up, self.orbit_degrees.to_radians()) * offset * self.distance;
        let position = main.point_of_interest + rotated;
        let forward = rotated.length();
        let sideways = rotated.cross(up).length();
        if !(forward > 0.0 && sideways > 1e-6 * forward) {
            return Err(format!(
                "the debug camera at {} looks at {} along the up axis or from that very point: expected an eye off the vertical through the point of interest",
                v3(position.to_array()),
                v3(main.point_of_interest.to_array())
            ));
        }
        Ok(Camera {
            position,
            point_of_interest: main.point_of_interest,
            up: main.up,
            fov: main.fov,
        })
    }
}

/// Projects a world point to continuous pixel coordinates (x right, y down; pixel (i, j)
/// covers [i, i + 1) × [j, j + 1)) and its distance from the eye, or `None` behind the eye.
/// The inverse of `CameraRays::screen` and `CameraRays::ray`.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x > 0)` is on purpose: NaN is not in front
pub fn project(camera: &CameraRays, p: Vec3) -> Option<(f32, f32, f32)> {
    let d = p - camera.origin;
    let depth = d.dot(camera.forward);
    if !(depth > 0.0) {
        return None;
    }
    let half2 = camera.right.length_squared();
    let sx = d.dot(camera.right) / (half2 * depth);
    let sy = d.dot(camera.up) / (half2 * depth);
    let (w, h) = (camera.width as f32, camera.height as f32);
    let m = w.max(h);
    // x = (sx + 1)/2 on the screen; i + ox = (x − 0.5)·m + w/2; likewise j from the bottom.
    let col = 0.5 * sx * m + 0.5 * w;
    let row_up = 0.5 * sy * m + 0.5 * h;
    Some((col, h - row_up, d.length()))
}

/// The segments that mark a camera: its eye, a small frustum of depth `size` towards what it
/// looks at (the image's four corners) and a tick above the top edge for its up side.
pub fn camera_marker(camera: &Camera, aspect: f32, size: f32) -> Vec<(Vec3, Vec3)> {
    let forward = (camera.point_of_interest - camera.position).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let half = (camera.fov * 0.5).tan() * size;
    // Non-square images crop the square field of view.
    let (hx, hy) = if aspect >= 1.0 {
        (half, half / aspect)
    } else {
        (half * aspect, half)
    };
    let eye = camera.position;
    let centre = eye + size * forward;
    let corners = [
        centre - hx * right - hy * up,
        centre + hx * right - hy * up,
        centre + hx * right + hy * up,
        centre - hx * right + hy * up,
    ];
    let mut lines: Vec<(Vec3, Vec3)> = corners.iter().map(|&c| (eye, c)).collect();
    for k in 0..4 {
        lines.push((corners[k], corners[(k + 1) % 4]));
    }
    lines.push((centre + hy * up, centre + (hy + 0.5 * hx) * up));
    lines
}
