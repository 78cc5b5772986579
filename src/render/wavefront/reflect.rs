//! Stage 4, reflect: hits on a mirror (kr ≠ 0) with bounces left spawn their reflected ray
//! into the next batch, compacted and in order; every other path is finished and leaves.

use super::batch::{HitBatch, RayBatch};
use super::context::Context;
use crate::render::scene::NO_HIT;
use crate::render::spawn::mirror_ray;

/// Fills `next` (depth `rays.bounce + 1`) and returns how many mirror rays it holds.
pub fn mirror_rays(ctx: &Context, rays: &RayBatch, hits: &HitBatch, next: &mut RayBatch) -> u64 {
    next.clear(rays.bounce + 1);
    if rays.bounce >= ctx.settings.bounces {
        return 0;
    }
    for i in 0..rays.len() {
        if hits.prim[i] == NO_HIT {
            continue;
        }
        let m = &hits.terms[hits.material[i] as usize];
        if !m.is_reflective {
            continue;
        }
        let ray = mirror_ray(&hits.surface(i), rays.direction.get(i));
        next.push(
            ray.origin,
            ray.direction,
            rays.throughput.get(i) * m.reflective,
            rays.path(i),
        );
    }
    next.len() as u64
}
