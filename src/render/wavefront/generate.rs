//! Stage 1, generate: the camera rays of a tile, every antialiasing sample of every pixel, in
//! (pixel, sample) order. Scalar on purpose: one camera ray per path is a few percent of the
//! rays of a render with shadows, and the scalar `CameraRays` code keeps the rays bit-identical
//! to the reference's.

use super::batch::{PathId, RayBatch};
use super::context::Context;
use glam::Vec3;

/// Fills `rays` (depth 0) with the camera rays of pixels `first..first + count`; ray
/// `p · n + s` is sample `s` of pixel `first + p`, and that is also its radiance slot.
pub fn camera_rays(ctx: &Context, first: u32, count: u32, rays: &mut RayBatch) {
    rays.clear(0);
    let n = ctx.settings.aa_samples.max(1);
    for pixel in first..first + count {
        for sample in 0..n {
            let ray = ctx.camera.sample_ray(pixel, sample, n, ctx.settings.seed);
            let slot = (pixel - first) * n + sample;
            rays.push(
                ray.origin,
                ray.direction,
                Vec3::ONE,
                PathId {
                    pixel,
                    sample,
                    slot,
                },
            );
        }
    }
}
