//! Stage 1, generate: the camera rays of a tile, every antialiasing sample of every pixel, in
//! (pixel, sample) order. At one sample per pixel (the lab's), the directions come N pixels
//! at a time from `simd::camera_directions`; with antialiasing, from the scalar
//! `CameraRays::rays_of` (each sample's offset is drawn from its own stream). Both give the
//! reference's rays to the bit.

use super::batch::RayBatch;
use super::context::Context;
use super::lanes::at_width;
use super::simd;

/// Fills `rays` (depth 0) with the camera rays of pixels `first..first + count`; ray
/// `p · n + s` is sample `s` of pixel `first + p`, and that is also its radiance slot. The
/// columns every camera ray shares (origin, tmax, throughput) are filled whole, and the rest
/// written by index: pushing ray by ray, 13 columns each, cost more than the rays' arithmetic.
pub fn camera_rays(ctx: &Context, first: u32, count: u32, rays: &mut RayBatch) {
    rays.clear(0);
    let n = ctx.settings.aa_samples.max(1);
    let total = (count * n) as usize;
    let camera = &ctx.camera;
    rays.origin.resize(total, 0.0);
    rays.origin.fill(0..total, camera.origin);
    rays.tmax.resize(total, f32::INFINITY);
    rays.throughput.resize(total, 1.0);
    rays.slot.extend(0..total as u32);
    rays.pixel.resize(total, 0);
    rays.sample.resize(total, 0);
    rays.direction.resize(total, 0.0);
    let (pixels, samples) = (&mut rays.pixel[..total], &mut rays.sample[..total]);
    if n == 1 {
        // Pixel centres: N rays at a time (`simd::camera_directions`, `rays_of`'s twin).
        for (k, pixel) in (first..first + count).enumerate() {
            pixels[k] = pixel;
        }
        let out = rays.direction.slices_mut(0..total);
        at_width!(ctx.lane_width, V => simd::camera_directions::<V>(camera, first, count, out));
        return;
    }
    let [dx, dy, dz] = rays.direction.slices_mut(0..total);
    let mut k = 0;
    camera.rays_of(first, count, n, ctx.settings.seed, |pixel, sample, d| {
        (dx[k], dy[k], dz[k]) = (d.x, d.y, d.z);
        (pixels[k], samples[k]) = (pixel, sample);
        k += 1;
    });
}
