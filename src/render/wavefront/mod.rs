//! The wavefront engine: rays in structure-of-arrays batches flowing through stages, 8 lanes
//! at a time, tiles spread over cores.
//!
//! ```text
//! for each tile (rayon; a fixed range of pixels, independent of the thread count):
//!     skip it if the render was cancelled (render_until: one flag load per tile)
//!     generate   camera rays, one per (pixel, aa sample)          generate.rs
//!     for bounce in 0..=max bounces, while rays are left:
//!         intersect  closest hit of every ray                      intersect.rs
//!         texels     kd at hits on textured materials              texels.rs
//!         shadow     shadow rays, occlusion, Shade sums             shadow.rs
//!         film       radiance += throughput · (0.2·kd + direct)     film.rs
//!         reflect    mirror rays into the next batch                reflect.rs
//!         swap the two ray batches
//!     film       pixel = mean of its samples, in sample order        film.rs
//! ```
//!
//! Every random number comes from `sampling`'s pure hash of (pixel, sample, bounce, light,
//! dimension, seed), and each pixel is summed inside one tile in a fixed order, so the image
//! does not depend on scheduling: `--threads 1` and `--threads 2` give the same bytes. Memory
//! is the film plus one `Workspace` per worker, bounded by the batch size.
//!
//! [`Wavefront::render_counted`] runs the same loop with the intersect and shadow stages'
//! traversal counted (`cost.rs`): a second instantiation of the stages, for `--stats` and
//! `--cost-map`; [`Wavefront::render`] counts nothing.

pub mod batch;
pub mod bvh;
pub mod context;
pub mod cost;
pub mod film;
pub mod generate;
pub mod intersect;
pub mod lanes;
pub mod reflect;
pub mod shade;
pub mod shadow;
pub mod simd;
pub mod stats;
pub mod texels;

use crate::render::film::Film;
use crate::render::per_kind::RayKind;
use crate::render::progress::Progress;
use crate::render::scene::Scene;
use crate::render::settings::RenderSettings;
use batch::{HitBatch, Radiance, RayBatch, ShadowQueue};
use context::Context;
use cost::{CostReport, NoCount, Tally, TileCosts};
use glam::Vec3;
use rayon::prelude::*;
use stats::{RenderStats, Stage};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// Camera samples per tile unless told otherwise (measured in docs/TRIED.md).
pub const DEFAULT_BATCH_SIZE: usize = 4096;

/// Buffers one worker reuses from tile to tile.
#[derive(Default)]
pub struct Workspace {
    rays: RayBatch,
    next: RayBatch,
    hits: HitBatch,
    shadow: ShadowQueue,
    radiance: Radiance,
}

/// The wavefront renderer for one scene and one set of settings.
pub struct Wavefront<'a> {
    ctx: Context<'a>,
    /// Pixels per tile: the batch size divided by the antialiasing samples.
    tile_pixels: usize,
    /// Shadow rays queued before an occlusion pass.
    queue_capacity: usize,
    /// Workspaces between rayon jobs and between renders. rayon asks for a fresh one per job
    /// (23 per 1024² frame on 2 threads, 2 on one), and a fresh one grows its buffers again
    /// from empty, page faults included.
    pool: Mutex<Vec<Workspace>>,
}

/// A workspace borrowed from the pool for one rayon job, returned when the job ends.
struct Pooled<'p> {
    ws: Workspace,
    pool: &'p Mutex<Vec<Workspace>>,
}

impl Drop for Pooled<'_> {
    fn drop(&mut self) {
        let ws = std::mem::take(&mut self.ws);
        // A poisoned pool only means another job panicked; the panic propagates anyway.
        if let Ok(mut pool) = self.pool.lock() {
            pool.push(ws);
        }
    }
}

impl<'a> Wavefront<'a> {
    /// Prepares the tables (and the BVH for meshes); `batch_size` is camera samples per tile.
    pub fn new(scene: &'a Scene, settings: &'a RenderSettings, batch_size: usize) -> Self {
        let ctx = Context::new(scene, settings);
        let batch_size = batch_size.max(1);
        Wavefront {
            tile_pixels: (batch_size / settings.aa_samples.max(1) as usize).max(1),
            queue_capacity: batch_size.max(16),
            ctx,
            pool: Mutex::new(Vec::new()),
        }
    }

    /// The same engine with its brute-force, light and shading kernels run `width` lanes wide
    /// (`LaneWidth::Auto`, the default: 16 on AVX-512 builds, else 8). Speed only: the image,
    /// the counts and the records' figures other than times are the same at every width.
    pub fn with_lane_width(mut self, width: lanes::LaneWidth) -> Self {
        self.ctx = self.ctx.with_lane_width(width);
        self.queue_capacity = self.queue_capacity.max(self.ctx.lane_width.lanes());
        self
    }

    /// The same engine with its shadow stage run by `path` (`Context::with_shadow_path`; the
    /// context must admit it). Speed only: the image and the counts are the same on every
    /// path (tests hold them so).
    pub fn with_shadow_path(mut self, path: shadow::ShadowPath) -> Self {
        self.ctx = self.ctx.with_shadow_path(path);
        self
    }

    /// The shadow path this engine's renders take.
    pub fn shadow_path(&self) -> shadow::ShadowPath {
        self.ctx.shadow_path
    }

    /// The lane width the kernels run at (resolved: `Eight` or `Sixteen`).
    pub fn lane_width(&self) -> lanes::LaneWidth {
        self.ctx.lane_width
    }

    /// The derived tables, BVH included.
    pub fn context(&self) -> &Context<'a> {
        &self.ctx
    }

    /// Number of tiles (for progress reporting).
    pub fn tile_count(&self) -> usize {
        let s = self.ctx.settings;
        (s.width as usize * s.height as usize).div_ceil(self.tile_pixels)
    }

    /// Renders on the current rayon pool, reporting each tile to `progress`.
    pub fn render(&self, progress: &Progress) -> (Film, RenderStats) {
        self.render_until(progress, &AtomicBool::new(false))
            .expect("a render whose cancel flag is never set renders every tile")
    }

    /// [`Wavefront::render`] that stops early once `cancel` is set: every worker reads the flag
    /// before each tile and skips the tile when it is set, so the call returns within about
    /// one tile per thread. `None` when a tile was skipped (the film is incomplete); an image
    /// that got every tile is the same, bit for bit, as `render`'s, whatever the flag did.
    pub fn render_until(
        &self,
        progress: &Progress,
        cancel: &AtomicBool,
    ) -> Option<(Film, RenderStats)> {
        let (film, tiles) = self.tiles(progress, cancel, |first, out, ws| {
            let mut stats = RenderStats::default();
            self.render_tile(first, out, ws, &mut stats);
            stats
        })?;
        Some((
            film,
            tiles.into_iter().fold(RenderStats::default(), |a, b| a + b),
        ))
    }

    /// Runs `tile(first pixel, its pixels, a workspace)` on every tile, on the current rayon
    /// pool, one pooled workspace per rayon job; the tiles' results in tile order, or `None`
    /// when `cancel` made a worker skip a tile (one relaxed load per tile).
    #[inline]
    fn tiles<T: Send>(
        &self,
        progress: &Progress,
        cancel: &AtomicBool,
        tile: impl Fn(u32, &mut [Vec3], &mut Workspace) -> T + Sync + Send,
    ) -> Option<(Film, Vec<T>)> {
        let s = self.ctx.settings;
        let steps = progress.steps(self.tile_count() as u64, "tiles");
        let mut film = Film::new(s.width, s.height);
        let tiles: Vec<Option<T>> = film
            .pixels
            .par_chunks_mut(self.tile_pixels)
            .enumerate()
            .map_init(
                || self.pooled(),
                |pooled, (i, out)| {
                    if cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    let t = tile((i * self.tile_pixels) as u32, out, &mut pooled.ws);
                    steps.step();
                    Some(t)
                },
            )
            .collect();
        Some((film, tiles.into_iter().collect::<Option<_>>()?))
    }

    /// A workspace from the pool (or a new one) for one rayon job.
    fn pooled(&self) -> Pooled<'_> {
        Pooled {
            ws: self
                .pool
                .lock()
                .map(|mut p| p.pop())
                .ok()
                .flatten()
                .unwrap_or_default(),
            pool: &self.pool,
        }
    }

    /// [`Wavefront::render`] with the traversal counted (`cost.rs`): the same image and ray
    /// counts, and every ray's nodes, leaves and primitive tests by kind, summed over the frame
    /// and, when `per_pixel`, kept for each pixel (summed inside its tile, so the same for any
    /// thread count). A separate instantiation of the stages: `render` runs none of the counting.
    ///
    /// `#[inline]` so that the counting instantiation of the stages is compiled in the crate
    /// that calls this (the binary, a test), never beside the library's uncounted stages: in one
    /// codegen unit, the second caller it gives the stages' helpers (`shadow::spawn`, `shade`)
    /// made LLVM stop inlining them into the uncounted stage (+1.5% instructions on the
    /// icount gate's mesh shadow stage, the BVH walk itself unchanged to the instruction).
    #[inline]
    pub fn render_counted(
        &self,
        progress: &Progress,
        per_pixel: bool,
    ) -> (Film, RenderStats, CostReport) {
        self.render_counted_until(progress, per_pixel, &AtomicBool::new(false))
            .expect("a render whose cancel flag is never set renders every tile")
    }

    /// [`Wavefront::render_counted`] that stops early once `cancel` is set, as
    /// [`Wavefront::render_until`] does: `None` when a tile was skipped.
    #[inline]
    pub fn render_counted_until(
        &self,
        progress: &Progress,
        per_pixel: bool,
        cancel: &AtomicBool,
    ) -> Option<(Film, RenderStats, CostReport)> {
        let (film, tiles) = self.tiles(progress, cancel, |first, out, ws| {
            let mut stats = RenderStats::default();
            let mut costs = TileCosts::new(first, out.len());
            self.render_tile_with(first, out, ws, &mut stats, &mut costs);
            (stats, costs.totals(), per_pixel.then_some(costs.pixels))
        })?;
        let mut stats = RenderStats::default();
        let mut report = CostReport {
            pixels: per_pixel.then(Vec::new),
            ..CostReport::default()
        };
        // In tile order: the pixels' counts come out row-major.
        for (tile_stats, totals, pixels) in tiles {
            stats = stats + tile_stats;
            report.totals = report.totals + totals;
            if let (Some(all), Some(p)) = (&mut report.pixels, pixels) {
                all.extend(p);
            }
        }
        Some((film, stats, report))
    }

    /// Renders pixels `first..first + out.len()` into `out`: the architecture diagram.
    pub fn render_tile(
        &self,
        first: u32,
        out: &mut [Vec3],
        ws: &mut Workspace,
        st: &mut RenderStats,
    ) {
        self.render_tile_with(first, out, ws, st, &mut NoCount);
    }

    /// [`Wavefront::render_tile`], the traversal work of every ray added to `tally` by its
    /// pixel and kind (`NoCount`: nothing is counted, and no counting code runs).
    fn render_tile_with<T: Tally>(
        &self,
        first: u32,
        out: &mut [Vec3],
        ws: &mut Workspace,
        st: &mut RenderStats,
        tally: &mut T,
    ) {
        let ctx = &self.ctx;
        st.time_kind(Stage::Generate, RayKind::Camera, || {
            generate::camera_rays(ctx, first, out.len() as u32, &mut ws.rays);
            ws.radiance.reset(ws.rays.len());
        });
        st.counts.camera += ws.rays.len() as u64;
        // The first batch holds the camera rays, every later one mirror rays.
        let mut traced = RayKind::Camera;
        while !ws.rays.is_empty() {
            st.time_kind(Stage::Intersect, traced, || {
                let costs = &mut tally.batch(ws.rays.len());
                intersect::closest(ctx, &ws.rays, &mut ws.hits, costs);
            });
            tally.settle(&ws.rays.pixel, traced);
            st.counts.shadow += st.time_kind(Stage::Shadow, RayKind::Shadow, || {
                let capacity = self.queue_capacity;
                let costs = &mut tally.batch(ws.rays.len());
                shadow::direct_light(ctx, &ws.rays, &mut ws.hits, &mut ws.shadow, capacity, costs)
            });
            tally.settle(&ws.rays.pixel, RayKind::Shadow);
            st.time(Stage::Film, || {
                film::accumulate(ctx, &ws.rays, &ws.hits, &mut ws.radiance);
            });
            st.counts.reflection += st.time_kind(Stage::Reflect, RayKind::Reflection, || {
                reflect::mirror_rays(ctx, &ws.rays, &ws.hits, &mut ws.next)
            });
            std::mem::swap(&mut ws.rays, &mut ws.next);
            traced = RayKind::Reflection;
        }
        st.time(Stage::Film, || {
            film::resolve(&ws.radiance, ctx.settings.aa_samples, out);
        });
    }
}
