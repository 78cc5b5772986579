//! Camera ray generation with the lab's pixel mapping.
//!
//! Pixel (i, j), j counted from the bottom, sub-pixel offset (ox, oy) (0.5 = centre):
//! x = (i + ox − w/2)/max(w, h) + 0.5, likewise y, so (x, y) ∈ [0, 1]² spans the square field
//! of view and non-square images crop it.

use crate::render::geometry::Ray;
use crate::render::sampling::{CAMERA_LIGHT, SampleKey, pixel_offset};
use crate::render::scene::Camera;
use glam::Vec3;

/// A camera ready to generate rays for one image size.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    /// Eye position: every camera ray starts here.
    pub origin: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Right vector scaled by tan(fov/2).
    pub right: Vec3,
    /// Up vector scaled by tan(fov/2).
    pub up: Vec3,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
}

impl CameraRays {
    /// Sets up the basis for a `width` × `height` image.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.point_of_interest - camera.position).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let half = (camera.fov * 0.5).tan();
        CameraRays {
            origin: camera.position,
            forward,
            right: right * half,
            up: up * half,
            width,
            height,
        }
    }

    /// The screen position (x, y) ∈ [0, 1]² of pixel `pixel` (row-major from the top-left)
    /// with sub-pixel offset (ox, oy).
    #[inline]
    pub fn screen(&self, pixel: u32, ox: f32, oy: f32) -> (f32, f32) {
        let (column, row) = (pixel % self.width, self.height - 1 - pixel / self.width);
        self.screen_at(column, row, ox, oy, self.scale())
    }

    /// 1 / max(width, height): pixels to screen units.
    #[inline]
    pub(crate) fn scale(&self) -> f32 {
        1.0 / (self.width as f32).max(self.height as f32)
    }

    /// [`Self::screen`] of the pixel in `column`, `row` (counted from the bottom), given
    /// [`Self::scale`]: the one formula both it and [`Self::rays_of`] use.
    #[inline]
    pub(crate) fn screen_at(
        &self,
        column: u32,
        row: u32,
        ox: f32,
        oy: f32,
        scale: f32,
    ) -> (f32, f32) {
        let (w, h) = (self.width as f32, self.height as f32);
        (
            (column as f32 + ox - 0.5 * w) * scale + 0.5,
            (row as f32 + oy - 0.5 * h) * scale + 0.5,
        )
    }

    /// Every camera ray of pixels `first..first + count`, `samples` each, in (pixel, sample)
    /// order: `f(pixel, sample, direction)`, each direction [`Self::sample_ray`]'s to the bit
    /// (the origin is always `origin`). Walks the rows instead of dividing each pixel index
    /// by the width.
    #[inline]
    pub fn rays_of(
        &self,
        first: u32,
        count: u32,
        samples: u32,
        seed: u32,
        mut f: impl FnMut(u32, u32, Vec3),
    ) {
        let scale = self.scale();
        let (mut column, mut from_top) = (first % self.width, first / self.width);
        for pixel in first..first + count {
            let row = self.height - 1 - from_top;
            for sample in 0..samples {
                let (ox, oy) = pixel_offset(&camera_key(pixel, sample, seed), sample, samples);
                let (x, y) = self.screen_at(column, row, ox, oy, scale);
                f(pixel, sample, self.ray(x, y).direction);
            }
            column += 1;
            if column == self.width {
                (column, from_top) = (0, from_top + 1);
            }
        }
    }

    /// The ray of antialiasing sample `sample` of `samples` in `pixel`: through the pixel centre
    /// for one sample, through a jittered stratum for more (`sampling::pixel_offset`). Both
    /// engines generate their camera rays here, so they start from identical rays.
    #[inline]
    pub fn sample_ray(&self, pixel: u32, sample: u32, samples: u32, seed: u32) -> Ray {
        let (ox, oy) = pixel_offset(&camera_key(pixel, sample, seed), sample, samples);
        let (x, y) = self.screen(pixel, ox, oy);
        self.ray(x, y)
    }

    /// The camera ray through screen point (x, y).
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let d = self.forward + (2.0 * x - 1.0) * self.right + (2.0 * y - 1.0) * self.up;
        Ray {
            origin: self.origin,
            direction: d.normalize(),
        }
    }
}

/// The sample stream of a pixel's antialiasing sample.
#[inline]
fn camera_key(pixel: u32, sample: u32, seed: u32) -> SampleKey {
    SampleKey {
        pixel,
        sample,
        bounce: 0,
        light: CAMERA_LIGHT,
        seed,
    }
}
