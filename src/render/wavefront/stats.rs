//! Per-stage timing, per-kind timing and ray counts of a wavefront render.

use crate::render::per_kind::{PerKind, RayCounts, RayKind};
use serde::{Deserialize, Serialize};
use std::ops::Add;
use std::time::{Duration, Instant};

/// The stages, in pipeline order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Camera rays.
    Generate,
    /// Closest hits and surface data.
    Intersect,
    /// Shadow rays: spawn, occlusion, Shade.
    Shadow,
    /// Mirror rays.
    Reflect,
    /// Radiance accumulation and pixel resolve.
    Film,
}

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; 5] = [
        Stage::Generate,
        Stage::Intersect,
        Stage::Shadow,
        Stage::Reflect,
        Stage::Film,
    ];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        ["generate", "intersect", "shadow", "reflect", "film"][self as usize]
    }
}

/// Rays by kind, thread-time by stage and by kind, summed over tiles.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Rays cast, by kind (live lanes only).
    pub counts: RayCounts,
    /// Thread-time spent in each stage, in `Stage::ALL` order (zero for the reference).
    pub stage_time: [Duration; 5],
    /// Thread-time spent on each kind's work; `None` when it was not measured (the reference
    /// unless asked, see `Reference::render_timed`). The wavefront engine's comes from the
    /// stage timers: camera = generate + intersect of the camera rays; reflection = reflect +
    /// intersect of the mirror rays; shadow = the shadow stage; film belongs to no kind.
    pub kind_time: Option<PerKind<Duration>>,
    /// Pixels that overflowed f32 and were clamped to finite values
    /// ([`crate::render::engine::clamp_to_finite`]); the caller warns.
    pub clamped_pixels: u64,
}

impl RenderStats {
    /// Runs `f`, adding its duration to `stage`.
    #[inline]
    pub fn time<T>(&mut self, stage: Stage, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        self.stage_time[stage as usize] += start.elapsed();
        out
    }

    /// Runs `f`, adding its duration to `stage` and to `kind`'s work (the same reading of
    /// the clock: no timer more than [`RenderStats::time`]).
    #[inline]
    pub fn time_kind<T>(&mut self, stage: Stage, kind: RayKind, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        let d = start.elapsed();
        self.stage_time[stage as usize] += d;
        self.kind_time.get_or_insert_default()[kind] += d;
        out
    }

    /// The rays a stage handles: generate makes camera rays, intersect traces camera and
    /// mirror rays, shadow casts shadow rays, reflect makes mirror rays, film resolves camera
    /// samples.
    pub fn stage_rays(&self, stage: Stage) -> u64 {
        let c = &self.counts;
        match stage {
            Stage::Generate | Stage::Film => c.camera,
            Stage::Intersect => c.camera + c.reflection,
            Stage::Shadow => c.shadow,
            Stage::Reflect => c.reflection,
        }
    }

    /// Each stage's figures, in pipeline order.
    pub fn stage_figures(&self) -> Vec<StageFigure> {
        Stage::ALL
            .iter()
            .map(|&s| {
                let seconds = self.stage_time[s as usize].as_secs_f64();
                let rays = self.stage_rays(s);
                StageFigure {
                    stage: s.name().to_string(),
                    rays,
                    thread_seconds: seconds,
                    rays_per_thread_second: if seconds > 0.0 {
                        rays as f64 / seconds
                    } else {
                        0.0
                    },
                }
            })
            .collect()
    }
}

/// One wavefront stage's figures, as reports print them and records store them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
pub struct StageFigure {
    /// Stage name (generate, intersect, shadow, reflect, film).
    pub stage: String,
    /// Rays the stage handled.
    pub rays: u64,
    /// Thread-seconds spent in it, summed over worker threads.
    pub thread_seconds: f64,
    /// rays / thread_seconds: the stage's headline figure (0 when the stage took no time).
    pub rays_per_thread_second: f64,
}

impl Add for RenderStats {
    type Output = RenderStats;
    fn add(mut self, o: RenderStats) -> RenderStats {
        self.counts += o.counts;
        for (a, b) in self.stage_time.iter_mut().zip(o.stage_time) {
            *a += b;
        }
        self.clamped_pixels += o.clamped_pixels;
        self.kind_time = match (self.kind_time, o.kind_time) {
            (Some(a), Some(b)) => Some(a + b),
            (a, b) => a.or(b),
        };
        self
    }
}
