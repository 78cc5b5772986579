//! Stage 5, film: every depth adds throughput · (what the hit gives) to its camera sample's
//! radiance; at the end each pixel is the mean of its samples, summed in sample order.
//!
//! The reference nests the same terms (c = 0.2·kd + kr ⊙ c_next + direct); this stage
//! distributes kr over them (L += T ⊙ (0.2·kd + direct), T *= kr), equal up to rounding. With no
//! mirror on the path T = 1 and the two are bit-identical.

use super::batch::{HitBatch, Radiance, RayBatch};
use super::context::Context;
use crate::render::scene::NO_HIT;
use glam::Vec3;

/// Adds this depth's contribution of every path: the background on a miss, else the ambient
/// term plus the direct light.
pub fn accumulate(ctx: &Context, rays: &RayBatch, hits: &HitBatch, radiance: &mut Radiance) {
    let background = ctx.settings.background();
    for i in 0..rays.len() {
        let term = if hits.prim[i] == NO_HIT {
            background
        } else {
            hits.terms[hits.material[i] as usize].ambient + hits.direct.get(i)
        };
        radiance.add(rays.slot[i] as usize, rays.throughput.get(i) * term);
    }
}

/// Writes each pixel of the tile: Σ over its `samples` slots in order, divided by `samples`.
pub fn resolve(radiance: &Radiance, samples: u32, out: &mut [Vec3]) {
    let n = samples.max(1) as usize;
    for (p, px) in out.iter_mut().enumerate() {
        let mut sum = Vec3::ZERO;
        for s in 0..n {
            sum += radiance.get(p * n + s);
        }
        *px = sum / n as f32;
    }
}
