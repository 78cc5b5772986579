//! Statistical tests on the samples the renderers actually draw, read from their own code
//! paths: the reference's `TraceLog` (every camera ray, every light point with its bounce and
//! light) and the wavefront engine's stages (`generate`'s camera rays, `shadow`'s queue). A
//! bug planted alike in both engines, which the twin tests cannot see, shows up here:
//!
//! - light points repeated across lights, bounces, antialiasing samples, seeds or pixels (a
//!   shadow-sample key missing a field), or tied to the camera's jitter: χ² test of
//!   independence on the within-stratum offsets of paired streams;
//! - light points or camera rays not uniform inside their strata (no jitter, or u and v drawn
//!   from one dimension): χ² on 4 × 4 sub-bins of the within-stratum offset, and exactly one
//!   point in every stratum.
//!
//! Every χ² is compared with its critical value at significance α = 1e-6 (from the χ²
//! distribution's upper tail, see `CHI2_*`): about a hundred statistics are checked, so a
//! correct renderer fails one with probability below 1e-4, while each planted bug gives a χ²
//! in the thousands. The seeds are fixed, so each test is deterministic: it passes or fails
//! the same way on every run and machine.
//!
//! The scene: two 1 × 1 lights facing down at y = 2, a mirror floor at y = 0 and a mirror
//! ceiling at y = 3 (both also diffuse), a camera between them. Camera rays hit the floor
//! (bounce 0), reflect to the ceiling (bounce 1) and back to the floor (bounce 2), and every
//! one of those hits sees all the points of both lights above its tangent plane.

use glam::{DVec2, DVec3};
use raywave::render::camera::CameraRays;
use raywave::render::geometry::{Hit, Ray};
use raywave::render::per_kind::RayCounts;
use raywave::render::reference::{LightPoint, Reference, TraceLog};
use raywave::render::sampling::{LightSampler, SampleKey, strata_grid};
use raywave::render::scene::{LightShape, Material, Scene, parse_scene_str};
use raywave::render::settings::{RenderSettings, ShadowMode};
use raywave::render::spawn::{ShadowRay, SurfaceHit};
use raywave::render::wavefront::batch::{HitBatch, RayBatch, ShadowQueue};
use raywave::render::wavefront::context::Context;
use raywave::render::wavefront::cost::NoCount;
use raywave::render::wavefront::shadow::ShadowPath;
use raywave::render::wavefront::{generate, intersect, reflect, shadow};
use std::collections::BTreeMap;

/// Upper 1e-6 point of χ² with 15 degrees of freedom (4 × 4 bins), from the regularised
/// incomplete gamma function: P(χ²₁₅ > 56.49) = 1e-6.
const CHI2_15: f64 = 56.49;
/// Upper 1e-6 point of χ² with 63 degrees of freedom (8 × 8 bins): P(χ²₆₃ > 131.37) = 1e-6.
const CHI2_63: f64 = 131.37;

fn corridor() -> Scene {
    let text = "
        material
        emitted 5 5 5
        material
        diffuse 0.3 0.3 0.3
        reflective 0.5 0.5 0.5
        glossiness 0.2
        v -1.5 2 -0.5
        v -0.5 2 -0.5
        v -0.5 2 0.5
        v -1.5 2 0.5
        v 0.5 2 -0.5
        v 1.5 2 -0.5
        v 1.5 2 0.5
        v 0.5 2 0.5
        m 0
        f 1 2 3 4
        f 5 6 7 8
        v -60 0 -60
        v -60 0 60
        v 60 0 60
        v 60 0 -60
        v -60 3 -60
        v 60 3 -60
        v 60 3 60
        v -60 3 60
        m 1
        f 9 10 11 12
        f 13 14 15 16
        PerspectiveCamera {
          camera_position 0 1.5 4
          point_of_interest 0 0.5 0
          angle 50
        }
    ";
    let scene = parse_scene_str(text, "corridor.obj").expect("the corridor parses");
    assert_eq!(scene.lights.len(), 2);
    scene
}

fn settings(sampler: LightSampler, n: u32, aa: u32, seed: u32) -> RenderSettings {
    RenderSettings {
        width: 32,
        height: 32,
        bounces: 2,
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        aa_samples: aa,
        seed,
        ..RenderSettings::default()
    }
}

/// One stream of light points: (pixel, antialiasing sample, bounce, light).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Stream {
    pixel: u32,
    sample: u32,
    bounce: u32,
    light: u32,
}

/// What one engine drew for one image: the light points of every stream whose N points were
/// all cast, as (u, v) on the light, in sample order; and every camera ray.
#[derive(Default)]
struct Drawn {
    points: BTreeMap<Stream, Vec<DVec2>>,
    camera: BTreeMap<(u32, u32), Ray>,
}

#[derive(Clone, Copy, Debug)]
enum Engine {
    Reference,
    Wavefront,
}

const ENGINES: [Engine; 2] = [Engine::Reference, Engine::Wavefront];

/// (u, v) of a point on a parallelogram light: the inverse of `Light::point`, in f64.
fn light_uv(scene: &Scene, light: u32, p: DVec3) -> DVec2 {
    let LightShape::Parallelogram {
        origin,
        edge_u,
        edge_v,
    } = scene.lights[light as usize].shape
    else {
        panic!("the corridor's lights are parallelograms");
    };
    let (eu, ev, d) = (edge_u.as_dvec3(), edge_v.as_dvec3(), p - origin.as_dvec3());
    let (a, b, c) = (eu.dot(eu), eu.dot(ev), ev.dot(ev));
    let (x, y) = (d.dot(eu), d.dot(ev));
    let det = a * c - b * b;
    DVec2::new((c * x - b * y) / det, (a * y - b * x) / det)
}

/// Where the ray from `origin` along `l` meets the plane of light `light`, in f64.
fn on_light_plane(scene: &Scene, light: u32, origin: DVec3, l: DVec3) -> DVec3 {
    let LightShape::Parallelogram {
        origin: corner,
        edge_u,
        edge_v,
    } = scene.lights[light as usize].shape
    else {
        panic!("the corridor's lights are parallelograms");
    };
    let n = edge_u.as_dvec3().cross(edge_v.as_dvec3());
    origin + l * (n.dot(corner.as_dvec3() - origin) / n.dot(l))
}

/// Keeps the streams that got all `n` points (a point below a hit's tangent plane casts no ray).
fn complete(points: BTreeMap<Stream, Vec<DVec2>>, n: u32) -> BTreeMap<Stream, Vec<DVec2>> {
    points
        .into_iter()
        .filter(|(_, p)| p.len() == n as usize)
        .collect()
}

/// The reference's samples, from its trace log.
fn reference_draws(scene: &Scene, s: &RenderSettings) -> Drawn {
    struct Log<'s> {
        scene: &'s Scene,
        pixel: u32,
        /// The antialiasing sample being traced: a camera ray (a path hit or miss at bounce 0)
        /// starts the next one.
        sample: Option<u32>,
        drawn: Drawn,
    }
    impl Log<'_> {
        fn path(&mut self, key: &SampleKey, ray: &Ray) {
            if key.bounce == 0 {
                let sample = self.sample.map_or(0, |s| s + 1);
                self.sample = Some(sample);
                self.drawn.camera.insert((self.pixel, sample), *ray);
            }
        }
    }
    impl TraceLog for Log<'_> {
        fn path_miss(&mut self, key: &SampleKey, ray: &Ray, _background: glam::Vec3) {
            self.path(key, ray);
        }
        fn path_hit(
            &mut self,
            key: &SampleKey,
            ray: &Ray,
            _hit: &Hit,
            _surface: &SurfaceHit,
            _material: &Material,
            _ambient: glam::Vec3,
        ) {
            self.path(key, ray);
        }
        fn shadow_ray(
            &mut self,
            key: &SampleKey,
            target: &LightPoint,
            _shadow: &ShadowRay,
            _blocked: Option<bool>,
            _term: glam::Vec3,
        ) {
            let stream = Stream {
                pixel: self.pixel,
                sample: self.sample.expect("a camera ray comes first"),
                bounce: key.bounce,
                light: target.light,
            };
            let uv = light_uv(self.scene, target.light, target.point.as_dvec3());
            self.drawn.points.entry(stream).or_default().push(uv);
        }
    }
    let reference = Reference::new(scene, s);
    let mut log = Log {
        scene,
        pixel: 0,
        sample: None,
        drawn: Drawn::default(),
    };
    for pixel in 0..s.width * s.height {
        log.pixel = pixel;
        log.sample = None;
        reference.pixel(pixel, &mut RayCounts::default(), &mut log);
    }
    let mut drawn = log.drawn;
    drawn.points = complete(drawn.points, s.points_per_light());
    drawn
}

/// The wavefront engine's samples: its stages run one depth at a time, as `render_tile`
/// does, with a shadow queue large enough for a whole depth, read after `direct_light`.
fn wavefront_draws(scene: &Scene, s: &RenderSettings) -> Drawn {
    // Hit by hit through the queue, where the drawn points can be read back: the fused
    // soft-shadow path draws the same points (`every_shadow_path_gives_the_per_hit_path_s_bytes`).
    let ctx = Context::new(scene, s).with_shadow_path(ShadowPath::QueuedPerHit);
    let n = s.points_per_light();
    let (mut rays, mut next) = (RayBatch::default(), RayBatch::default());
    let (mut hits, mut queue) = (HitBatch::default(), ShadowQueue::default());
    let mut drawn = Drawn::default();
    generate::camera_rays(&ctx, 0, s.width * s.height, &mut rays);
    for i in 0..rays.len() {
        let ray = Ray {
            origin: rays.origin.get(i),
            direction: rays.direction.get(i),
        };
        drawn.camera.insert((rays.pixel[i], rays.sample[i]), ray);
    }
    while !rays.is_empty() {
        intersect::closest(&ctx, &rays, &mut hits, &mut NoCount);
        let capacity = rays.len() * scene.lights.len() * (n as usize).div_ceil(8) * 8;
        shadow::direct_light(&ctx, &rays, &mut hits, &mut queue, capacity, &mut NoCount);
        for q in 0..queue.len {
            // Dead lanes (no ray: the point is below the tangent plane, or padding) have n·l 0.
            if queue.n_dot_l[q] <= 0.0 {
                continue;
            }
            let i = queue.path[q] as usize;
            let stream = Stream {
                pixel: rays.pixel[i],
                sample: rays.sample[i],
                bounce: rays.bounce,
                light: queue.light[q],
            };
            // The light point is where the Shade formula's l, which runs from the hit point
            // itself, meets the light's plane (not read from the tested segment, so the test
            // does not depend on where the engine starts and ends that segment).
            let origin = hits.point.get(i).as_dvec3();
            let target = on_light_plane(
                scene,
                stream.light,
                origin,
                queue.direction.get(q).as_dvec3(),
            );
            let uv = light_uv(scene, stream.light, target);
            drawn.points.entry(stream).or_default().push(uv);
        }
        reflect::mirror_rays(&ctx, &rays, &hits, &mut next);
        std::mem::swap(&mut rays, &mut next);
    }
    drawn.points = complete(drawn.points, n);
    drawn
}

fn draws(engine: Engine, scene: &Scene, s: &RenderSettings) -> Drawn {
    match engine {
        Engine::Reference => reference_draws(scene, s),
        Engine::Wavefront => wavefront_draws(scene, s),
    }
}

/// The offset of point j of `count` inside its stratum of the `strata_grid(count)` grid,
/// in [0, 1)² (up to the rounding of the round trip through the light point). For samplers
/// that do not stratify by j, the offset inside whatever cell the point is in.
fn in_stratum(uv: DVec2, j: usize, count: u32, stratified: bool) -> DVec2 {
    let (nx, ny) = strata_grid(count);
    let (nx, ny) = (nx as f64, ny as f64);
    let (x, y) = (uv.x * nx, uv.y * ny);
    if stratified {
        let (cx, cy) = ((j as u32 % nx as u32) as f64, (j as u32 / nx as u32) as f64);
        let d = DVec2::new(x - cx, y - cy);
        assert!(
            d.x > -1e-4 && d.x < 1.0 + 1e-4 && d.y > -1e-4 && d.y < 1.0 + 1e-4,
            "point {j} of {count} at {uv} is outside its stratum ({cx}, {cy})"
        );
        d.clamp(DVec2::ZERO, DVec2::splat(1.0 - 1e-12))
    } else {
        DVec2::new(x.rem_euclid(1.0), y.rem_euclid(1.0))
    }
}

/// Pearson's χ² of `points` in [0, 1)² binned on a k × k grid, against a uniform expectation.
fn chi2_uniform(points: &[DVec2], k: usize) -> f64 {
    let mut bins = vec![0u32; k * k];
    for p in points {
        let (x, y) = ((p.x * k as f64) as usize, (p.y * k as f64) as usize);
        bins[y.min(k - 1) * k + x.min(k - 1)] += 1;
    }
    let e = points.len() as f64 / (k * k) as f64;
    assert!(
        e >= 5.0,
        "too few points for χ²: {} in {} bins",
        points.len(),
        k * k
    );
    bins.iter().map(|&c| (c as f64 - e).powi(2) / e).sum()
}

/// Independence of paired uniform variables: χ² of the pairs on an 8 × 8 grid, each marginal
/// uniform, so every cell expects n/64 under independence. Identical or tied streams put
/// every pair near the diagonal.
fn assert_independent(what: &str, pairs: &[(f64, f64)]) {
    let points: Vec<DVec2> = pairs.iter().map(|&(a, b)| DVec2::new(a, b)).collect();
    let x = chi2_uniform(&points, 8);
    println!("{what}: χ² = {x:.1} over {} pairs", pairs.len());
    assert!(
        x < CHI2_63,
        "{what}: χ² = {x:.1} over {} pairs ≥ {CHI2_63} (α = 1e-6, 63 dof): not independent",
        pairs.len()
    );
}

/// Pairs the within-stratum offsets of streams `a` and `b = partner(a)`, point by point, both
/// coordinates; at least `min_pairs` pairs are required so the test has power.
fn paired_offsets(
    a: &Drawn,
    b: &Drawn,
    count: u32,
    stratified: bool,
    partner: impl Fn(Stream) -> Option<Stream>,
    min_pairs: usize,
) -> Vec<(f64, f64)> {
    let mut pairs = Vec::new();
    for (stream, points) in &a.points {
        let Some(other) = partner(*stream).and_then(|s| b.points.get(&s)) else {
            continue;
        };
        for (j, (p, q)) in points.iter().zip(other).enumerate() {
            let (p, q) = (
                in_stratum(*p, j, count, stratified),
                in_stratum(*q, j, count, stratified),
            );
            pairs.push((p.x, q.x));
            pairs.push((p.y, q.y));
        }
    }
    assert!(
        pairs.len() >= min_pairs,
        "only {} pairs: the scene does not exercise these streams",
        pairs.len()
    );
    pairs
}

const SAMPLERS: [LightSampler; 3] = [
    LightSampler::Random,
    LightSampler::Stratified,
    LightSampler::Sobol,
];

#[test]
fn light_points_are_independent_across_lights_and_bounces() {
    let scene = corridor();
    for sampler in SAMPLERS {
        let stratified = sampler == LightSampler::Stratified;
        let s = settings(sampler, 4, 1, 7);
        for engine in ENGINES {
            let d = draws(engine, &scene, &s);
            let what = |pair: &str| format!("{engine:?} {}: {pair}", sampler.name());
            let other_light = |st: Stream| (st.light == 0).then_some(Stream { light: 1, ..st });
            for bounce in 0..=2 {
                let pairs = paired_offsets(
                    &d,
                    &d,
                    4,
                    stratified,
                    |st| other_light(st).filter(|_| st.bounce == bounce),
                    1000,
                );
                assert_independent(&what(&format!("light 0 vs 1 at bounce {bounce}")), &pairs);
            }
            for (from, to) in [(0, 1), (1, 2), (0, 2)] {
                let pairs = paired_offsets(
                    &d,
                    &d,
                    4,
                    stratified,
                    |st| (st.bounce == from).then_some(Stream { bounce: to, ..st }),
                    1000,
                );
                assert_independent(&what(&format!("bounce {from} vs {to}")), &pairs);
            }
        }
    }
}

#[test]
fn light_points_are_independent_across_aa_samples_pixels_and_seeds() {
    let scene = corridor();
    let s = settings(LightSampler::Stratified, 4, 4, 3);
    let other_seed = RenderSettings {
        seed: 4,
        ..s.clone()
    };
    for engine in ENGINES {
        let d = draws(engine, &scene, &s);
        let e = draws(engine, &scene, &other_seed);
        let next_sample = |st: Stream| {
            Some(Stream {
                sample: (st.sample + 1) % 4,
                ..st
            })
        };
        let pairs = paired_offsets(&d, &d, 4, true, next_sample, 1000);
        assert_independent(&format!("{engine:?}: aa sample s vs s + 1"), &pairs);
        let next_pixel = |st: Stream| {
            Some(Stream {
                pixel: st.pixel + 1,
                ..st
            })
        };
        let pairs = paired_offsets(&d, &d, 4, true, next_pixel, 1000);
        assert_independent(&format!("{engine:?}: pixel p vs p + 1"), &pairs);
        let pairs = paired_offsets(&d, &e, 4, true, Some, 1000);
        assert_independent(&format!("{engine:?}: seed 3 vs 4"), &pairs);
    }
}

#[test]
fn light_points_fill_their_strata_uniformly() {
    // Every point j in stratum j (checked in `in_stratum`), and the offsets inside the strata
    // uniform on 4 × 4 sub-bins, pooled over all streams: no fixed offset, no u = v.
    let scene = corridor();
    for n in [4u32, 16, 6] {
        let s = settings(LightSampler::Stratified, n, 1, 11);
        for engine in ENGINES {
            let d = draws(engine, &scene, &s);
            let offsets: Vec<DVec2> = d
                .points
                .values()
                .flat_map(|p| {
                    p.iter()
                        .enumerate()
                        .map(|(j, uv)| in_stratum(*uv, j, n, true))
                })
                .collect();
            let x = chi2_uniform(&offsets, 4);
            println!(
                "{engine:?} N = {n}: χ² = {x:.1} over {} points",
                offsets.len()
            );
            assert!(
                x < CHI2_15,
                "{engine:?} N = {n}: χ² = {x:.1} over {} points ≥ {CHI2_15} (α = 1e-6)",
                offsets.len()
            );
            // And u and v inside a stratum are independent of each other.
            let pairs: Vec<(f64, f64)> = offsets.iter().map(|o| (o.x, o.y)).collect();
            assert_independent(&format!("{engine:?} N = {n}: u vs v"), &pairs);
        }
    }
}

/// The sub-pixel offset (ox, oy) ∈ [0, 1)² of a camera ray through `pixel`: the inverse of
/// `CameraRays::screen` and `ray`, in f64 (x = (i + ox − w/2)/max(w, h) + 0.5, likewise y,
/// with j counted from the bottom).
fn pixel_offset_of(cam: &CameraRays, pixel: u32, ray: &Ray) -> DVec2 {
    let d = ray.direction.as_dvec3();
    let (f, r, u) = (
        cam.forward.as_dvec3(),
        cam.right.as_dvec3(),
        cam.up.as_dvec3(),
    );
    let x = (d.dot(r) / r.length_squared() / d.dot(f) + 1.0) / 2.0;
    let y = (d.dot(u) / u.length_squared() / d.dot(f) + 1.0) / 2.0;
    let (w, h) = (cam.width as f64, cam.height as f64);
    let i = (pixel % cam.width) as f64;
    let j = (cam.height - 1 - pixel / cam.width) as f64;
    let size = w.max(h);
    DVec2::new(
        (x - 0.5) * size + 0.5 * w - i,
        (y - 0.5) * size + 0.5 * h - j,
    )
}

/// The camera rays' within-stratum offsets by (pixel, sample), each checked to lie in its
/// sample's stratum of the `strata_grid(aa)` grid.
fn camera_offsets(
    engine: Engine,
    scene: &Scene,
    s: &RenderSettings,
) -> BTreeMap<(u32, u32), DVec2> {
    let cam = CameraRays::new(&scene.camera, s.width, s.height);
    let d = draws(engine, scene, s);
    assert_eq!(d.camera.len(), (s.width * s.height * s.aa_samples) as usize);
    d.camera
        .iter()
        .map(|(&(pixel, sample), ray)| {
            let o = pixel_offset_of(&cam, pixel, ray);
            let (nx, ny) = strata_grid(s.aa_samples);
            let cell = DVec2::new((sample % nx) as f64, (sample / nx) as f64);
            let f = o * DVec2::new(nx as f64, ny as f64) - cell;
            assert!(
                f.min_element() > -1e-3 && f.max_element() < 1.0 + 1e-3,
                "{engine:?}: pixel {pixel} sample {sample} at {o}, outside stratum {cell}"
            );
            (
                (pixel, sample),
                f.clamp(DVec2::ZERO, DVec2::splat(1.0 - 1e-12)),
            )
        })
        .collect()
}

#[test]
fn camera_rays_fill_their_strata_uniformly() {
    let scene = corridor();
    // Non-square images, wider and taller: the screen mapping divides by max(w, h).
    for (aa, width, height) in [(16u32, 24u32, 18u32), (8, 24, 36)] {
        let s = RenderSettings {
            width,
            height,
            shadows: ShadowMode::Off,
            ..settings(LightSampler::Stratified, 1, aa, 5)
        };
        for engine in ENGINES {
            let offsets = camera_offsets(engine, &scene, &s);
            let points: Vec<DVec2> = offsets.values().copied().collect();
            let x = chi2_uniform(&points, 4);
            println!("{engine:?} aa {aa}: χ² = {x:.1} over {} rays", points.len());
            assert!(
                x < CHI2_15,
                "{engine:?} aa {aa}: χ² of the camera jitter = {x:.1} over {} rays ≥ {CHI2_15} \
                 (α = 1e-6): not uniform in its strata",
                points.len()
            );
            let pairs: Vec<(f64, f64)> = points.iter().map(|o| (o.x, o.y)).collect();
            assert_independent(&format!("{engine:?} aa {aa}: camera ox vs oy"), &pairs);
        }
    }
}

#[test]
fn camera_jitter_is_independent_across_samples_pixels_seeds_and_light_points() {
    let scene = corridor();
    let s = settings(LightSampler::Stratified, 4, 4, 21);
    for engine in ENGINES {
        let a = camera_offsets(engine, &scene, &s);
        let b = camera_offsets(
            engine,
            &scene,
            &RenderSettings {
                seed: 22,
                ..s.clone()
            },
        );
        let pair = |f: &dyn Fn(u32, u32) -> Option<DVec2>| -> Vec<(f64, f64)> {
            a.iter()
                .filter_map(|(&(p, smp), o)| f(p, smp).map(|q| [(o.x, q.x), (o.y, q.y)]))
                .flatten()
                .collect()
        };
        let next_sample = pair(&|p, smp| a.get(&(p, (smp + 1) % 4)).copied());
        assert_independent(
            &format!("{engine:?}: camera sample s vs s + 1"),
            &next_sample,
        );
        let next_pixel = pair(&|p, smp| a.get(&(p + 1, smp)).copied());
        assert_independent(&format!("{engine:?}: camera pixel p vs p + 1"), &next_pixel);
        let other_seed = pair(&|p, smp| b.get(&(p, smp)).copied());
        assert_independent(&format!("{engine:?}: camera seed 21 vs 22"), &other_seed);
        // The camera's stream must not be a light's: its jitter against the first point of
        // light 0 at the camera hit.
        let d = draws(engine, &scene, &s);
        let light = pair(&|p, smp| {
            let st = Stream {
                pixel: p,
                sample: smp,
                bounce: 0,
                light: 0,
            };
            d.points.get(&st).map(|pts| in_stratum(pts[0], 0, 4, true))
        });
        assert!(light.len() > 1000, "only {} pairs", light.len());
        assert_independent(&format!("{engine:?}: camera vs light 0 point 0"), &light);
    }
}
