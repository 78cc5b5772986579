//! The scalar reference renderer: the lab's recursive `trace`, one ray at a time.
//!
//! It is the whole-image twin of the wavefront engine, so it is written to be obviously right
//! rather than clever, while staying a fair baseline for timing: no allocation per ray, no
//! dynamic dispatch per primitive, a BVH for meshes, rayon over rows.
//!
//! ```text
//! trace(ray, bounce):
//!   no hit -> background
//!   hit    -> ambient ⊙ kd
//!           + kr ⊙ trace(reflected ray, bounce + 1)        if kr ≠ 0 and bounce < max bounces
//!           + Σ lights Σ j<N  Shade(l_j) / N                if n·l_j > 0 and p_j is visible
//! ```

use crate::render::camera::CameraRays;
use crate::render::film::Film;
use crate::render::geometry::{Accel, Hit, Ray};
use crate::render::per_kind::{KindClock, PerKind, RayCounts, RayKind};
use crate::render::progress::Progress;
use crate::render::sampling::{PointSet, SampleKey};
use crate::render::scene::{Material, Scene};
use crate::render::settings::{RenderSettings, ShadowMode};
use crate::render::shading::shade;
use crate::render::spawn::{
    ShadowRay, SurfaceHit, falloff, light_end, light_offset, mirror_ray, shadow_ray, surface_hit,
};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Receives every ray the tracer casts, with what the pixel gets from it; `()` ignores them at
/// no cost. `trace::trace_pixel` records the one-pixel ray tree through it.
///
/// `key` is the path's: its sample and bounce (the light loop's own key, with the light's
/// index, is not passed on, so a hook reads the bounce and light as the loop sees them, not as
/// its random numbers are keyed). The calls come in the recursion's order: a hit, then the
/// whole path of its mirror ray, then the hit's own light points.
pub trait TraceLog {
    /// A camera ray (bounce 0) or mirror ray that hits nothing: the ray returns `background`.
    fn path_miss(&mut self, _key: &SampleKey, _ray: &Ray, _background: Vec3) {}
    /// A camera or mirror ray's closest hit, the surface there and its material (a textured
    /// one with kd the texel there), and the hit's own term `ambient` = ambient ⊙ kd (the ray
    /// returns it plus kr ⊙ its mirror ray's colour plus its light points' terms).
    fn path_hit(
        &mut self,
        _key: &SampleKey,
        _ray: &Ray,
        _hit: &Hit,
        _surface: &SurfaceHit,
        _material: &Material,
        _ambient: Vec3,
    ) {
    }
    /// A light point not above the hit's tangent plane (or the light's own plane): no ray,
    /// nothing added.
    fn no_shadow_ray(&mut self, _key: &SampleKey, _target: &LightPoint) {}
    /// A shadow ray towards `target`: `blocked` is the occlusion test's outcome (`None` when
    /// shadows are off and no test runs) and `term` = Shade(l) / N what it adds to the hit's
    /// colour (zero when blocked).
    fn shadow_ray(
        &mut self,
        _key: &SampleKey,
        _target: &LightPoint,
        _shadow: &ShadowRay,
        _blocked: Option<bool>,
        _term: Vec3,
    ) {
    }
}

/// A point a hit's light loop aims a shadow ray at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPoint {
    /// Index of the light.
    pub light: u32,
    /// Which of the light's points it is (0..points per light).
    pub index: u32,
    /// Its (u, v) on the light's square with soft shadows; none for the centroid.
    pub uv: Option<[f32; 2]>,
    /// The point.
    pub point: Vec3,
}

impl TraceLog for () {}

/// The reference renderer for one scene and one set of settings.
pub struct Reference<'a> {
    scene: &'a Scene,
    settings: &'a RenderSettings,
    accel: Accel,
    camera: CameraRays,
    /// `spawn::light_offset` of every light.
    light_offsets: Vec<f32>,
    /// Where soft shadows' points fall on a light.
    points: PointSet,
}

impl<'a> Reference<'a> {
    /// Prepares the acceleration structure and camera.
    pub fn new(scene: &'a Scene, settings: &'a RenderSettings) -> Self {
        Reference {
            scene,
            settings,
            accel: Accel::new(scene),
            camera: CameraRays::new(&scene.camera, settings.width, settings.height),
            light_offsets: scene.lights.iter().map(light_offset).collect(),
            points: settings.point_set(),
        }
    }

    /// The acceleration structure it traces with (`trace::trace_pixel` names the blocker of a
    /// blocked shadow ray with it).
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    /// Renders the image on the current rayon pool, reporting each row to `progress`.
    pub fn render(&self, progress: &Progress) -> (Film, RayCounts) {
        self.render_until(progress, &AtomicBool::new(false))
            .expect("a render whose cancel flag is never set renders every row")
    }

    /// [`Reference::render`] that skips every row left once `cancel` is set, so it returns within
    /// about one row per thread: `None` when a row was skipped; otherwise `render`'s image, bit
    /// for bit.
    pub fn render_until(
        &self,
        progress: &Progress,
        cancel: &AtomicBool,
    ) -> Option<(Film, RayCounts)> {
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        let rows = progress.steps(h as u64, "rows");
        let mut film = Film::new(self.settings.width, self.settings.height);
        // Set only on the skip path: a row costs one relaxed load more.
        let skipped = AtomicBool::new(false);
        let counts = film
            .pixels
            .par_chunks_mut(w)
            .enumerate()
            .map(|(row, out)| {
                let mut counts = RayCounts::default();
                if cancel.load(Ordering::Relaxed) {
                    skipped.store(true, Ordering::Relaxed);
                    return counts;
                }
                self.pixels((row * w) as u32, out, &mut counts);
                rows.step();
                counts
            })
            .reduce(RayCounts::default, |a, b| a + b);
        debug_assert_eq!(film.pixels.len(), w * h);
        (!skipped.into_inner()).then_some((film, counts))
    }

    /// [`Reference::render`] with the thread-time of each kind's work measured (what each kind
    /// covers: [`KindClock`]). A separate copy of the loop (the clock is a type parameter), so
    /// `render` carries no timer; this one reads the clock two or three times per path segment,
    /// which costs time: docs/SCHEMA.md gives the measured overhead. Same image, same counts.
    pub fn render_timed(&self, progress: &Progress) -> (Film, RayCounts, PerKind<Duration>) {
        let w = self.settings.width as usize;
        let rows = progress.steps(self.settings.height as u64, "rows");
        let mut film = Film::new(self.settings.width, self.settings.height);
        let (counts, times) = film
            .pixels
            .par_chunks_mut(w)
            .enumerate()
            .map(|(row, out)| {
                let mut counts = RayCounts::default();
                let mut times = PerKind::<Duration>::default();
                let first = (row * w) as u32;
                for (i, px) in out.iter_mut().enumerate() {
                    *px = self.pixel_clocked(first + i as u32, &mut counts, &mut (), &mut times);
                }
                rows.step();
                (counts, times)
            })
            .reduce(Default::default, |a, b| (a.0 + b.0, a.1 + b.1));
        (film, counts, times)
    }

    /// Pixels `first..first + out.len()` into `out`, without a trace log: the loop `render`
    /// runs for each row. Not generic, so it is compiled once, in this crate: the
    /// instruction-count gate (`tests/gates/icount.rs`) calls it to count the code the renderer
    /// runs, where a call to the generic `pixel` would count a copy compiled into the test.
    pub fn pixels(&self, first: u32, out: &mut [Vec3], counts: &mut RayCounts) {
        for (i, px) in out.iter_mut().enumerate() {
            *px = self.pixel(first + i as u32, counts, &mut ());
        }
    }

    /// The colour of one pixel: the mean over its antialiasing samples.
    pub fn pixel(&self, pixel: u32, counts: &mut RayCounts, log: &mut impl TraceLog) -> Vec3 {
        self.pixel_clocked(pixel, counts, log, &mut ())
    }

    /// [`Reference::pixel`], reporting each kind's work to `clock`.
    #[inline]
    fn pixel_clocked(
        &self,
        pixel: u32,
        counts: &mut RayCounts,
        log: &mut impl TraceLog,
        clock: &mut impl KindClock,
    ) -> Vec3 {
        let n = self.settings.aa_samples.max(1);
        let mut sum = Vec3::ZERO;
        for sample in 0..n {
            let key = SampleKey {
                pixel,
                sample,
                bounce: 0,
                light: 0,
                seed: self.settings.seed,
            };
            let start = clock.mark();
            let ray = self.camera.sample_ray(pixel, sample, n, self.settings.seed);
            counts.camera += 1;
            sum += self.trace(&ray, key, counts, log, clock, start);
        }
        sum / n as f32
    }

    #[allow(clippy::too_many_arguments)]
    fn trace<M: Copy>(
        &self,
        ray: &Ray,
        key: SampleKey,
        counts: &mut RayCounts,
        log: &mut impl TraceLog,
        clock: &mut impl KindClock<Mark = M>,
        start: M,
    ) -> Vec3 {
        // `start` is when this ray's making began (its kind's work: making it, then its
        // closest hit and the surface data there).
        let kind = if key.bounce == 0 {
            RayKind::Camera
        } else {
            RayKind::Reflection
        };
        let hit = self
            .accel
            .closest(self.scene, ray, f32::INFINITY, self.settings.two_sided);
        if !hit.is_hit() {
            clock.since(kind, start);
            let background = self.settings.background();
            log.path_miss(&key, ray, background);
            return background;
        }
        let surface = surface_hit(self.scene, hit.prim, ray, hit.t, self.settings.two_sided);
        // One reading ends this ray's work and starts what follows (the few operations of
        // the ambient term go with it).
        let mut start = clock.since(kind, start);
        // A textured material's kd is the texel at the hit: the material as it is there.
        let textured;
        let mut material = self.scene.material_of(hit.prim);
        if material.texture.is_some() {
            textured = Material {
                diffuse: self.scene.diffuse_at(hit.prim, surface.point),
                ..*material
            };
            material = &textured;
        }
        let mut color = Vec3::from_array(self.settings.ambient) * material.diffuse;
        log.path_hit(&key, ray, &hit, &surface, material, color);
        if material.is_reflective() && key.bounce < self.settings.bounces {
            let next = mirror_ray(&surface, ray.direction);
            counts.reflection += 1;
            let bounced = SampleKey {
                bounce: key.bounce + 1,
                ..key
            };
            color += material.reflective * self.trace(&next, bounced, counts, log, clock, start);
            // The mirror ray's path took its own time: the light loop starts now.
            start = clock.mark();
        }
        let direct = self.direct(&surface, -ray.direction, material, key, counts, log);
        clock.since(RayKind::Shadow, start);
        color + direct
    }

    /// Σ over lights and their N points of Shade / N for the visible points.
    fn direct(
        &self,
        surface: &SurfaceHit,
        e: Vec3,
        material: &Material,
        key: SampleKey,
        counts: &mut RayCounts,
        log: &mut impl TraceLog,
    ) -> Vec3 {
        let settings = self.settings;
        let count = settings.points_per_light();
        let weight = 1.0 / count as f32;
        let mut sum = Vec3::ZERO;
        for (li, light) in self.scene.lights.iter().enumerate() {
            let light_key = SampleKey {
                light: li as u32,
                ..key
            };
            let end_offset = self.light_offsets[li];
            let end = light_end(light, end_offset, surface);
            // The table samplers' per-stream state, taken once for the N points.
            let stream = match settings.shadows {
                ShadowMode::Soft => self.points.stream(&light_key),
                _ => None,
            };
            for j in 0..count {
                let (uv, point) = match settings.shadows {
                    ShadowMode::Soft => {
                        let (u, v) = match &stream {
                            Some(stream) => stream.point(j),
                            None => self.points.point(&light_key, j),
                        };
                        (Some([u, v]), light.point(u, v))
                    }
                    _ => (None, light.centroid),
                };
                let target = LightPoint {
                    light: li as u32,
                    index: j,
                    uv,
                    point,
                };
                let Some(shadow) = shadow_ray(surface, point, &end) else {
                    log.no_shadow_ray(&key, &target);
                    continue;
                };
                let (blocked, visible) = match settings.shadows {
                    ShadowMode::Off => (None, true),
                    _ => {
                        counts.shadow += 1;
                        let blocked = self.accel.occluded(
                            self.scene,
                            &shadow.ray,
                            shadow.tmax,
                            settings.two_sided,
                        );
                        (Some(blocked), !blocked)
                    }
                };
                let mut term = Vec3::ZERO;
                if visible {
                    let light_color = light.color * falloff(settings.light_model, shadow.dist);
                    let l = shadow.ray.direction;
                    term =
                        shade(material, surface.normal, e, l, shadow.n_dot_l, light_color) * weight;
                    sum += term;
                }
                log.shadow_ray(&key, &target, &shadow, blocked, term);
            }
        }
        sum
    }
}
