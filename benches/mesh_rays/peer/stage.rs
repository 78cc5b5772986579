//! The renderer's whole shadow stage on a peer scene, for the peer table's stage rows.
//!
//! The ray sets time traversal against traversal: the same segments through every engine.
//! The renderer does more per shadow ray: it spawns the ray from the hit and a light point
//! (the sampler, the light's end, the offset), tests it, and shades it. [`ShadowStage`] times
//! that whole stage (`shadow::direct_light`, as a frame at zero bounces runs it) over the
//! camera hits of a scene, so that its rays per second can stand beside a peer's traversal of
//! rays of the same kind: one per (hit, light) for hard shadows, n per (hit, light) for n soft
//! points, from the same camera hits to the same light.
//!
//! They are the rays a frame at zero bounces casts from those hits (the camera set's ray i is
//! pixel i's, so the stage draws the frame's light points: `tests/kernels/peer_agreement.rs`
//! counts them against a frame), of the same kind as the sets' but not the same rays: hard
//! shadows aim at the light's centroid (the set's at a uniform point on it), soft shadows at
//! the default sampler's stratified points from every camera hit, where the fan sets take
//! one origin in n hits.

use super::{BATCH, RaySet, RaySetKind};
use raywave::render::scene::Scene;
use raywave::render::settings::{RenderSettings, ShadowMode};
use raywave::render::wavefront::batch::{HitBatch, ShadowQueue};
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::cost::NoCount;
use raywave::render::wavefront::{intersect, shadow};

/// The shadow stage of one ray kind, ready to run over the camera hits it was built with.
pub struct ShadowStage<'s> {
    ctx: Context<'s>,
    hits: Vec<HitBatch>,
    queue: ShadowQueue,
}

impl<'s> ShadowStage<'s> {
    /// The settings of the stage that casts `kind`'s rays: hard shadows for `Shadow`, n soft
    /// points for `ShadowFan(n)`, zero bounces, `base` otherwise (two-sided for peer scenes).
    /// `None` for a closest-hit kind.
    pub fn settings(base: &RenderSettings, kind: RaySetKind) -> Option<RenderSettings> {
        let (shadows, shadow_samples) = match kind {
            RaySetKind::Shadow => (ShadowMode::Hard, 1),
            RaySetKind::ShadowFan(n) => (ShadowMode::Soft, n),
            RaySetKind::Primary | RaySetKind::Incoherent => return None,
        };
        Some(RenderSettings {
            bounces: 0,
            shadows,
            shadow_samples,
            ..base.clone()
        })
    }

    /// The stage of `settings` (see [`ShadowStage::settings`]) over the camera hits of
    /// `primary`'s rays. Builds the scene's context, its BVH included.
    pub fn new(scene: &'s Scene, settings: &'s RenderSettings, primary: &RaySet) -> Self {
        let ctx = Context::new(scene, settings);
        let hits = primary
            .batches
            .iter()
            .map(|batch| {
                let mut hits = HitBatch::default();
                intersect::closest(&ctx, batch, &mut hits, &mut NoCount);
                hits
            })
            .collect();
        ShadowStage {
            ctx,
            hits,
            queue: ShadowQueue::default(),
        }
    }

    /// One pass of the stage over every camera hit of `primary` (the set the stage was built
    /// with): spawning, occlusion and shading, as the renderer's frame runs them. Returns the
    /// number of shadow rays cast.
    pub fn run(&mut self, primary: &RaySet) -> u64 {
        let capacity = BATCH.max(16);
        primary
            .batches
            .iter()
            .zip(&mut self.hits)
            .map(|(batch, hits)| {
                shadow::direct_light(
                    &self.ctx,
                    batch,
                    hits,
                    &mut self.queue,
                    capacity,
                    &mut NoCount,
                )
            })
            .sum()
    }
}
