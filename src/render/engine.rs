//! One entry point for both renderers: the command line, `raywave bench`, the variance study,
//! the benches and the tests choose an [`Engine`] and call it, instead of each matching on the
//! choice and calling `Wavefront` or `Reference` in its own way.
//!
//! ```text
//! Engine::render(scene, settings, batch, progress)            one image
//! Engine::prepare(scene, settings, batch) -> Prepared         set-up once (BVH, tables) ...
//!     Prepared::render(progress) -> (Film, RenderStats)       ... then render as often as asked
//!     Prepared::render_until(progress, cancel)                 ... or until `cancel` is set:
//!         -> Option<(Film, RenderStats)>                           None once a unit was skipped
//! ```

use crate::render::film::Film;
use crate::render::per_kind::RayCounts;
use crate::render::progress::Progress;
use crate::render::reference::Reference;
use crate::render::scene::Scene;
use crate::render::settings::RenderSettings;
use crate::render::wavefront::lanes::LaneWidth;
use crate::render::wavefront::shadow::ShadowPath;
use crate::render::wavefront::stats::RenderStats;
use crate::render::wavefront::{DEFAULT_BATCH_SIZE, Wavefront};
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;

/// The renderers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// Structure-of-arrays batches through 8-wide SIMD stages (the default).
    Wavefront,
    /// The scalar recursive renderer, one ray at a time: the whole-image twin.
    Reference,
}

impl Engine {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Wavefront => "wavefront",
            Engine::Reference => "reference",
        }
    }

    /// Builds what the engine needs before its first ray (the BVH for meshes, the tables);
    /// `batch_size` is the wavefront engine's camera samples per tile (the reference ignores it).
    pub fn prepare<'a>(
        self,
        scene: &'a Scene,
        settings: &'a RenderSettings,
        batch_size: usize,
    ) -> Prepared<'a> {
        self.prepare_lanes(scene, settings, batch_size, LaneWidth::Auto)
    }

    /// [`Engine::prepare`] with the wavefront engine's kernels run `lanes` wide (the reference
    /// ignores it). Speed only: the image is the same at every width.
    pub fn prepare_lanes<'a>(
        self,
        scene: &'a Scene,
        settings: &'a RenderSettings,
        batch_size: usize,
        lanes: LaneWidth,
    ) -> Prepared<'a> {
        match self {
            Engine::Wavefront => Prepared::Wavefront(
                Wavefront::new(scene, settings, batch_size).with_lane_width(lanes),
            ),
            Engine::Reference => Prepared::Reference(Reference::new(scene, settings)),
        }
    }

    /// Renders one image on the current rayon pool, reporting each unit of work (a wavefront
    /// tile, a reference row) to `progress`. The reference has no stages: its `stage_time` is
    /// zero.
    pub fn render(
        self,
        scene: &Scene,
        settings: &RenderSettings,
        batch_size: usize,
        progress: &Progress,
    ) -> (Film, RenderStats) {
        self.prepare(scene, settings, batch_size).render(progress)
    }

    /// One image at the default batch size, without progress, as the variance study's
    /// `RenderFn` takes it. Pixels it clamps are not reported: a caller that warns of them
    /// uses [`Engine::render`] and [`clamped_warning`].
    pub fn image(self, scene: &Scene, settings: &RenderSettings) -> (Film, RayCounts) {
        let (film, stats) = self.render(scene, settings, DEFAULT_BATCH_SIZE, &Progress::SILENT);
        (film, stats.counts)
    }
}

/// An engine set up for one scene and one set of settings.
pub enum Prepared<'a> {
    /// The wavefront engine.
    Wavefront(Wavefront<'a>),
    /// The reference renderer.
    Reference(Reference<'a>),
}

impl Prepared<'_> {
    /// Which engine this is.
    pub fn engine(&self) -> Engine {
        match self {
            Prepared::Wavefront(_) => Engine::Wavefront,
            Prepared::Reference(_) => Engine::Reference,
        }
    }

    /// The SIMD path this engine's kernels run on (`raywave::simd_path_for` its lane width; the
    /// build's default path for the scalar reference, as records have always said).
    pub fn simd_path(&self) -> &'static str {
        match self {
            Prepared::Wavefront(w) => crate::simd_path_for(w.lane_width()),
            Prepared::Reference(_) => crate::simd_path(),
        }
    }

    /// How the wavefront engine's shadow stage runs (`shadow::ShadowPath`, chosen once per
    /// render); `None` for the reference.
    pub fn shadow_path(&self) -> Option<ShadowPath> {
        match self {
            Prepared::Wavefront(w) => Some(w.shadow_path()),
            Prepared::Reference(_) => None,
        }
    }

    /// Seconds spent building the wavefront engine's mesh BVH: `None` for the reference, and
    /// `Some(None)` when the scene needs no BVH.
    pub fn bvh_build_seconds(&self) -> Option<Option<f64>> {
        match self {
            Prepared::Wavefront(w) => Some(
                w.context()
                    .accel
                    .as_ref()
                    .map(|bvh| bvh.build_time.as_secs_f64()),
            ),
            Prepared::Reference(_) => None,
        }
    }

    /// Renders the image on the current rayon pool, reporting each work unit to `progress`.
    ///
    /// Every pixel comes out finite: a scene's numbers are bounded by the parser, but a mirror
    /// that reflects more than it receives, over many bounces, or a bright light next to a
    /// surface can still overflow f32; such pixels are clamped (see [`clamp_to_finite`]) and
    /// counted in `clamped_pixels`, for the caller to warn with [`clamped_warning`].
    pub fn render(&self, progress: &Progress) -> (Film, RenderStats) {
        self.render_until(progress, &AtomicBool::new(false))
            .expect("a render whose cancel flag is never set renders every unit")
    }

    /// [`Prepared::render`] that stops early once `cancel` is set (by another thread, or by
    /// `progress` itself): each worker reads the flag before each work unit and skips the unit
    /// when it is set, so the call returns within about one unit per thread. `None` when a unit
    /// was skipped; otherwise the image and statistics are `render`'s, bit for bit.
    pub fn render_until(
        &self,
        progress: &Progress,
        cancel: &AtomicBool,
    ) -> Option<(Film, RenderStats)> {
        let (mut film, mut stats) = match self {
            Prepared::Wavefront(w) => w.render_until(progress, cancel)?,
            Prepared::Reference(r) => {
                let (film, counts) = r.render_until(progress, cancel)?;
                (
                    film,
                    RenderStats {
                        counts,
                        ..RenderStats::default()
                    },
                )
            }
        };
        stats.clamped_pixels = clamp_to_finite(&mut film) as u64;
        Some((film, stats))
    }
}

/// Makes every channel of every pixel finite: +inf becomes `f32::MAX`, NaN (infinity times
/// zero) becomes 0. Returns how many pixels changed; finite images are left untouched.
pub fn clamp_to_finite(film: &mut Film) -> usize {
    let mut changed = 0;
    for p in film.pixels.iter_mut().filter(|p| !p.is_finite()) {
        changed += 1;
        *p = p.map(|c| {
            if c.is_nan() {
                0.0
            } else {
                c.clamp(-f32::MAX, f32::MAX)
            }
        });
    }
    changed
}

/// The warning for a render whose `stats` clamped pixels (`None` when none was clamped).
pub fn clamped_warning(stats: &RenderStats) -> Option<String> {
    (stats.clamped_pixels > 0).then(|| {
        format!(
            "warning: {} pixel(s) overflowed f32 and were clamped to finite values (the scene's colours \
             or mirrors amplify light past 3.4e38)",
            stats.clamped_pixels
        )
    })
}

/// The worker threads the engines render on: `threads`, or rayon's default (all cores), which
/// its `num_threads(0)` also means.
pub fn thread_pool(threads: Option<u32>) -> anyhow::Result<rayon::ThreadPool> {
    let builder = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0) as usize);
    anyhow::Context::context(builder.build(), "cannot start the worker threads")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_engines_render_the_same_rays_through_the_facade() {
        let scene = Scene::builtin_default();
        let settings = RenderSettings {
            width: 12,
            height: 8,
            shadow_samples: 2,
            ..RenderSettings::default()
        };
        for engine in [Engine::Wavefront, Engine::Reference] {
            let last = std::sync::Mutex::new(Vec::new());
            let report =
                |done, total, what: &str| last.lock().unwrap().push((done, total, what.to_owned()));
            let progress = Progress {
                report: &report,
                ..Progress::SILENT
            };
            let prepared = engine.prepare(&scene, &settings, 16);
            assert_eq!(prepared.engine(), engine);
            let units = match &prepared {
                Prepared::Wavefront(w) => w.tile_count() as u64,
                Prepared::Reference(_) => 8,
            };
            let (film, stats) = prepared.render(&progress);
            let reports = last.into_inner().unwrap();
            assert_eq!(
                reports.len() as u64,
                units + 1,
                "{engine:?} reports none done, then each unit"
            );
            assert_eq!(reports.last().map(|r| (r.0, r.1)), Some((units, units)));
            assert_eq!((film.width, film.height), (12, 8));
            assert_eq!(stats.counts.camera, 96);
            assert_eq!(engine.image(&scene, &settings).1, stats.counts);
        }
        assert_eq!(
            Engine::Reference
                .prepare(&scene, &settings, 16)
                .bvh_build_seconds(),
            None
        );
        assert_eq!(
            Engine::Reference
                .render(&scene, &settings, 16, &Progress::SILENT)
                .1
                .stage_time,
            RenderStats::default().stage_time
        );
    }
}
