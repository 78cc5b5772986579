//! The wavefront engine against its whole-image twin, the reference renderer: same scene, same
//! seed, same samples → the same image (within 1e-4 per channel on ≥ 99.9% of pixels) and the
//! same ray counts, for every scene in scenes/ and every mode. Also: the image does not depend
//! on the thread count or the batch size.
// `!(d <= 1e-4)` is on purpose: a NaN difference counts as a difference.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::common;

use common::bundled_scenes;
use glam::Vec3;
use raywave::render::film::Film;
use raywave::render::per_kind::RayCounts;
use raywave::render::progress::Progress;
use raywave::render::reference::Reference;
use raywave::render::sampling::LightSampler;
use raywave::render::scene::{Scene, parse_scene_str};
use raywave::render::settings::{RenderSettings, ShadowMode};
use raywave::render::wavefront::Wavefront;

/// The lab's modes, on a small image.
fn modes() -> Vec<RenderSettings> {
    let base = RenderSettings {
        width: 20,
        height: 16,
        bounces: 2,
        shadows: ShadowMode::Hard,
        shadow_samples: 1,
        sampler: LightSampler::Stratified,
        aa_samples: 1,
        background: [0.2, 0.1, 0.6],
        seed: 3,
        two_sided: false,
        ..RenderSettings::default()
    };
    let soft = |n, sampler| RenderSettings {
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        ..base.clone()
    };
    vec![
        RenderSettings {
            shadows: ShadowMode::Off,
            ..base.clone()
        },
        base.clone(),
        // 5 and 13 points: blocks of 8 with dead tail lanes.
        soft(5, LightSampler::Random),
        soft(13, LightSampler::Stratified),
        soft(16, LightSampler::Stratified),
        RenderSettings {
            bounces: 0,
            ..soft(8, LightSampler::Stratified)
        },
        RenderSettings {
            bounces: 10,
            ..soft(4, LightSampler::Random)
        },
        RenderSettings {
            aa_samples: 3,
            ..base.clone()
        },
        RenderSettings {
            two_sided: true,
            ..soft(9, LightSampler::Stratified)
        },
        // Samplers the 8-wide light sampler does not implement (the scalar path); lab at
        // N = 1 is the centroid, at N > 1 random points.
        soft(7, LightSampler::Sobol),
        soft(1, LightSampler::Lab),
        soft(6, LightSampler::Lab),
    ]
}

fn reference(scene: &Scene, s: &RenderSettings) -> (Film, RayCounts) {
    Reference::new(scene, s).render(&Progress::SILENT)
}

fn wavefront(scene: &Scene, s: &RenderSettings, batch: usize) -> (Film, RayCounts) {
    let (film, stats) = Wavefront::new(scene, s, batch).render(&Progress::SILENT);
    (film, stats.counts)
}

/// Pixels with some channel more than 1e-4 away.
fn differing_pixels(a: &Film, b: &Film) -> usize {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| !((**p - **q).abs().max_element() <= 1e-4))
        .count()
}

fn assert_equivalent(scene: &Scene, s: &RenderSettings, batch: usize) {
    let (want, want_counts) = reference(scene, s);
    let (got, got_counts) = wavefront(scene, s, batch);
    let bad = differing_pixels(&want, &got);
    // ≥ 99.9% within 1e-4; on these small images that means every pixel.
    assert!(
        bad * 1000 <= want.pixels.len(),
        "{}: {bad} of {} pixels differ by more than 1e-4 with {s:?}",
        scene.source,
        want.pixels.len()
    );
    assert_eq!(
        got_counts, want_counts,
        "{}: ray counts differ with {s:?}",
        scene.source
    );
    assert!(want.pixels.iter().any(|p| *p != Vec3::ZERO), "blank image");
}

#[test]
fn every_scene_and_mode_matches_the_reference() {
    for (_, scene) in bundled_scenes() {
        for s in modes() {
            assert_equivalent(&scene, &s, 64);
        }
    }
}

#[test]
fn a_mesh_scene_through_the_bvh_matches_the_reference() {
    let scene = parse_scene_str(
        &raywave::render::scene::meshgen::cornell_box_mesh_spheres(4),
        "mesh",
    )
    .expect("generated scene parses");
    assert!(scene.triangles.len() >= raywave::render::wavefront::context::BVH_MIN_TRIANGLES);
    let s = &modes()[4];
    assert!(Wavefront::new(&scene, s, 64).context().accel.is_some());
    assert_equivalent(&scene, s, 64);
}

#[test]
fn batch_size_does_not_change_the_image() {
    let scene = Scene::builtin_default();
    let s = RenderSettings {
        aa_samples: 2,
        ..modes()[3].clone()
    };
    let (want, want_counts) = wavefront(&scene, &s, 4096);
    for batch in [1, 7, 8, 9, 65] {
        let (got, counts) = wavefront(&scene, &s, batch);
        assert!(got == want, "batch size {batch} changed the image");
        assert_eq!(counts, want_counts);
    }
}

#[test]
fn one_and_two_threads_give_identical_bytes() {
    let scene = Scene::builtin_default();
    let s = RenderSettings {
        width: 33,
        height: 17,
        ..modes()[4].clone()
    };
    let render = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        // Small batches so both threads get many tiles.
        pool.install(|| wavefront(&scene, &s, 16))
    };
    let (one, c1) = render(1);
    let (two, c2) = render(2);
    let bytes = |f: &Film| -> Vec<u32> {
        f.pixels
            .iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect()
    };
    assert_eq!(bytes(&one), bytes(&two));
    assert_eq!(c1, c2);
}

/// The film's bits, channel by channel (so −0.0 vs 0.0 or NaN payloads count as differences).
fn film_bits(f: &Film) -> Vec<u32> {
    f.pixels
        .iter()
        .flat_map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

/// The 16-lane path against the 8-lane path: the same bytes and the same ray counts on every
/// bundled scene, for no, hard and soft shadows (every sampler, point counts around both lane
/// widths), with bounces, antialiasing and odd batch sizes. Runs anywhere: without AVX-512 the
/// 16 lanes are two 256-bit halves.
#[test]
fn sixteen_and_eight_lanes_give_the_same_bytes_on_every_scene() {
    use raywave::render::wavefront::lanes::LaneWidth;
    let mut settings = modes();
    let soft = |n, sampler| RenderSettings {
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        ..modes()[1].clone()
    };
    for sampler in LightSampler::ALL {
        // 15, 17 and 33 points: 16-lane blocks with dead tail lanes; 64 the lab benchmark's.
        for n in [15, 17, 33, 64] {
            settings.push(soft(n, sampler));
        }
    }
    settings.push(RenderSettings {
        aa_samples: 2,
        bounces: 4,
        ..soft(24, LightSampler::Stratified)
    });
    for (name, scene) in bundled_scenes() {
        for (m, s) in settings.iter().enumerate() {
            // Odd batch sizes on some modes: tiles that end mid-vector, queues of one hit.
            let batches: &[usize] = if m % 4 == 0 { &[1, 7, 17] } else { &[64] };
            for &batch in batches {
                let render = |width| {
                    let w = Wavefront::new(&scene, s, batch).with_lane_width(width);
                    assert_eq!(w.lane_width(), width);
                    let (film, stats) = w.render(&Progress::SILENT);
                    (film_bits(&film), stats.counts)
                };
                let (eight, c8) = render(LaneWidth::Eight);
                let (sixteen, c16) = render(LaneWidth::Sixteen);
                assert!(
                    eight == sixteen,
                    "{name}: 16 lanes changed the image with batch {batch} and {s:?}"
                );
                assert_eq!(c8, c16, "{name}: ray counts differ with {s:?}");
            }
        }
    }
}

/// Every shadow path a render admits (`shadow::ShadowPath`: soft shadows fused block by block
/// in registers, hard shadows (and the unshadowed centroid rays of `--shadows off`) fused N hits
/// at a time) gives the bytes and counts of `QueuedPerHit`, which sends every ray through the
/// queue hit by hit, on every bundled scene (on the mesh scene, through the BVH, the same
/// traversal counts per pixel too): every sampler, point counts with dead
/// tail lanes at 8 and 16 lanes, both light models (the RPI model's fall-off is computed from
/// each block's distances), bounces, antialiasing, two-sided faces and odd batch sizes (groups
/// of hits that end mid-vector). Every path is taken somewhere, and the path a render chooses
/// is among those held.
#[test]
fn every_shadow_path_gives_the_per_hit_path_s_bytes() {
    use raywave::render::settings::LightModel;
    use raywave::render::wavefront::lanes::LaneWidth;
    use raywave::render::wavefront::shadow::ShadowPath;
    let soft = |n, sampler, light_model| RenderSettings {
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        light_model,
        ..modes()[1].clone()
    };
    let mut settings = Vec::new();
    for sampler in LightSampler::ALL {
        for n in [1, 7, 17, 64] {
            settings.push(soft(n, sampler, LightModel::Lab));
        }
        settings.push(soft(9, sampler, LightModel::Rpi));
    }
    settings.push(RenderSettings {
        aa_samples: 2,
        bounces: 4,
        two_sided: true,
        ..soft(24, LightSampler::Stratified, LightModel::Lab)
    });
    for shadows in [ShadowMode::Hard, ShadowMode::Off] {
        for light_model in LightModel::ALL {
            settings.push(RenderSettings {
                shadows,
                light_model,
                ..soft(1, LightSampler::Stratified, light_model)
            });
        }
    }
    let mut taken = std::collections::BTreeSet::new();
    for (name, scene) in bundled_scenes() {
        for (m, s) in settings.iter().enumerate() {
            // Odd batches for every mode without soft shadows too: groups of hits that end
            // mid-vector.
            let batches: &[usize] = if m % 4 == 0 || s.shadows != ShadowMode::Soft {
                &[1, 7, 64]
            } else {
                &[64]
            };
            for &batch in batches {
                for width in [LaneWidth::Eight, LaneWidth::Sixteen] {
                    let engine = || Wavefront::new(&scene, s, batch).with_lane_width(width);
                    let render = |path| {
                        let (film, stats) =
                            engine().with_shadow_path(path).render(&Progress::SILENT);
                        (film_bits(&film), stats.counts)
                    };
                    let (per_hit, cp) = render(ShadowPath::QueuedPerHit);
                    let admitted: Vec<ShadowPath> = ShadowPath::ALL
                        .into_iter()
                        .filter(|p| p.admits(engine().context()))
                        .collect();
                    assert!(admitted.contains(&engine().shadow_path()), "{name}: {s:?}");
                    for path in admitted {
                        taken.insert(format!("{path:?}"));
                        let (fast, cf) = render(path);
                        assert!(
                            per_hit == fast,
                            "{name}: {path:?} changed the image at {width:?}, batch {batch}, \
                             {s:?}"
                        );
                        assert_eq!(cp, cf, "{name}: {path:?}'s ray counts differ with {s:?}");
                        // Through a BVH every ray's walk is its own, so each pixel's counted
                        // work is the same whichever path queued or fused its rays.
                        if engine().context().accel.is_some() && batch == 64 {
                            let costs = |path| {
                                let e = engine().with_shadow_path(path);
                                e.render_counted(&Progress::SILENT, true).2.pixels
                            };
                            assert!(
                                costs(ShadowPath::QueuedPerHit) == costs(path),
                                "{name}: {path:?} changed the traversal counts at {width:?}, \
                                 {s:?}"
                            );
                        }
                    }
                }
            }
        }
    }
    let every: std::collections::BTreeSet<String> =
        ShadowPath::ALL.iter().map(|p| format!("{p:?}")).collect();
    assert_eq!(
        taken, every,
        "some shadow path was never held to the per-hit one"
    );
}

/// `LaneWidth::Auto` is the build's native width: 16 lanes when built for AVX-512, else 8.
#[test]
fn auto_lanes_follow_the_build() {
    use raywave::render::wavefront::lanes::LaneWidth;
    let scene = Scene::builtin_default();
    let native = if cfg!(target_feature = "avx512f") {
        LaneWidth::Sixteen
    } else {
        LaneWidth::Eight
    };
    // The build's native width where a light has more than 8 points, or no shadow rays are
    // cast; 8 lanes for hard shadows and for 8 points or fewer, where a 16-lane block would be
    // mostly dead lanes.
    for (shadows, points, want) in [
        (ShadowMode::Soft, 16, native),
        (ShadowMode::Soft, 9, native),
        (ShadowMode::Off, 1, native),
        (ShadowMode::Soft, 8, LaneWidth::Eight),
        (ShadowMode::Soft, 4, LaneWidth::Eight),
        (ShadowMode::Hard, 1, LaneWidth::Eight),
    ] {
        let s = RenderSettings {
            shadows,
            shadow_samples: points,
            ..modes()[0].clone()
        };
        assert_eq!(
            Wavefront::new(&scene, &s, 64).lane_width(),
            want,
            "{shadows:?} {points}"
        );
        let auto = Wavefront::new(&scene, &s, 64).with_lane_width(LaneWidth::Auto);
        assert_eq!(auto.lane_width(), want, "{shadows:?} {points}");
        let forced = Wavefront::new(&scene, &s, 64).with_lane_width(LaneWidth::Sixteen);
        assert_eq!(forced.lane_width(), LaneWidth::Sixteen);
    }
}
