//! Sample placement: the pixel centre for one camera ray, one jittered point per stratum for
//! more; uniform light points for both samplers; streams that depend on every key field.

use glam::Vec3;
use raywave::render::per_kind::RayCounts;
use raywave::render::reference::Reference;
use raywave::render::sampling::{LightSampler, PointSet, SampleKey, pixel_offset, strata_grid};
use raywave::render::scene::parse_scene_str;
use raywave::render::settings::{RenderSettings, ShadowMode};

fn key(pixel: u32, sample: u32) -> SampleKey {
    SampleKey {
        pixel,
        sample,
        bounce: 0,
        light: 0,
        seed: 3,
    }
}

#[test]
fn one_camera_ray_goes_through_the_pixel_centre() {
    for p in 0..100 {
        assert_eq!(pixel_offset(&key(p, 0), 0, 1), (0.5, 0.5));
    }
}

#[test]
fn antialiasing_puts_one_jittered_point_in_every_stratum() {
    for n in [2u32, 3, 4, 6, 9, 10, 16, 25] {
        let (nx, ny) = strata_grid(n);
        for pixel in 0..50 {
            let mut seen = vec![0; n as usize];
            for s in 0..n {
                let (u, v) = pixel_offset(&key(pixel, s), s, n);
                assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                let cell = (v * ny as f32) as u32 * nx + (u * nx as f32) as u32;
                seen[cell as usize] += 1;
            }
            assert!(seen.iter().all(|&c| c == 1), "n = {n}: {seen:?}");
        }
    }
}

/// Pearson's χ² of `counts` against a uniform expectation.
fn chi2(counts: &[u32]) -> f64 {
    let total: u32 = counts.iter().sum();
    let e = total as f64 / counts.len() as f64;
    counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum()
}

#[test]
fn light_points_are_uniform_for_both_samplers() {
    // 8 × 8 bins over the unit square, 64 000 points: χ² with 63 degrees of freedom has mean 63
    // and sd ≈ 11; 130 is beyond 6 sd.
    for sampler in [LightSampler::Random, LightSampler::Stratified] {
        for n in [1u32, 4, 5, 16] {
            let mut bins = vec![0u32; 64];
            let keys = 64_000 / n;
            for p in 0..keys {
                let k = SampleKey {
                    pixel: p,
                    sample: 0,
                    bounce: 1,
                    light: 2,
                    seed: 9,
                };
                for j in 0..n {
                    let (u, v) = PointSet::of(sampler, n).point(&k, j);
                    assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                    bins[(v * 8.0) as usize * 8 + (u * 8.0) as usize] += 1;
                }
            }
            let x = chi2(&bins);
            assert!(x < 130.0, "{sampler:?} N = {n}: χ² = {x}");
        }
    }
}

#[test]
fn streams_for_different_lights_and_bounces_are_uncorrelated() {
    // The first coordinate of light 0 and light 1 (and bounce 0 and 1) for the same pixel:
    // their correlation over many pixels must be near 0 (|r| < 5/√n).
    let n = 20_000;
    for (a, b) in [((0u32, 0u32), (0u32, 1u32)), ((0, 0), (1, 0))] {
        let (mut sx, mut sy, mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for p in 0..n {
            let ka = SampleKey {
                pixel: p,
                sample: 0,
                bounce: a.0,
                light: a.1,
                seed: 0,
            };
            let kb = SampleKey {
                bounce: b.0,
                light: b.1,
                ..ka
            };
            let x = PointSet::of(LightSampler::Random, 1).point(&ka, 0).0 as f64;
            let y = PointSet::of(LightSampler::Random, 1).point(&kb, 0).0 as f64;
            sx += x;
            sy += y;
            sxy += x * y;
            sxx += x * x;
            syy += y * y;
        }
        let nf = n as f64;
        let cov = sxy / nf - sx * sy / nf / nf;
        let r = cov / ((sxx / nf - (sx / nf).powi(2)) * (syy / nf - (sy / nf).powi(2))).sqrt();
        assert!(r.abs() < 5.0 / nf.sqrt(), "{a:?} vs {b:?}: r = {r}");
    }
}

#[test]
fn antialiased_pixel_over_an_edge_is_the_area_mix() {
    // No lights: a quad covering the left half of the view shows 0.2·kd everywhere, the right
    // half is background. A 1 × 1 image spans the whole view; with 4 × 4 strata the edge x = 0.5
    // lies on a stratum boundary, so exactly half the camera rays hit: the pixel is the mean.
    let text = "material\ndiffuse 1 0.5 0\nm 0\nv -10 -10 0\nv 0 -10 0\nv 0 10 0\nv -10 10 0\nf 1 2 3 4\n\
        PerspectiveCamera {\ncamera_position 0 0 5\npoint_of_interest 0 0 0\nangle 20\n}\n";
    let scene = parse_scene_str(text, "edge.obj").unwrap();
    let bg = Vec3::new(0.0, 0.0, 1.0);
    for (aa, want) in [
        (1, bg), // the centre ray runs along the edge x = 0: checked below
        (16, 0.5 * Vec3::new(0.2, 0.1, 0.0) + 0.5 * bg),
        (4, 0.5 * Vec3::new(0.2, 0.1, 0.0) + 0.5 * bg),
    ] {
        let settings = RenderSettings {
            width: 1,
            height: 1,
            bounces: 0,
            shadows: ShadowMode::Hard,
            shadow_samples: 1,
            sampler: LightSampler::Stratified,
            aa_samples: aa,
            background: bg.to_array(),
            seed: 5,
            two_sided: false,
            ..RenderSettings::default()
        };
        let got = Reference::new(&scene, &settings).pixel(0, &mut RayCounts::default(), &mut ());
        if aa == 1 {
            // The single ray goes exactly along x = 0, the quad's edge: either answer is fine.
            let hit = Vec3::new(0.2, 0.1, 0.0);
            assert!(
                (got - want).abs().max_element() < 1e-6 || (got - hit).abs().max_element() < 1e-6,
                "{got}"
            );
        } else {
            assert!(
                (got - want).abs().max_element() < 1e-6,
                "aa {aa}: {got} vs {want}"
            );
        }
    }
}

/// The Sobol sampler takes dimensions 0 and 1 from `sobol_burley::sample_4d`; the crate tests
/// that against `sample` for indices below 256 only, so check the whole range N allows (2^16).
#[test]
fn sobol_4d_equals_one_dimension_at_a_time() {
    for seed in [0, 1, 0x9e37_79b9, u32::MAX] {
        for index in (0..1u32 << 16).step_by(7).chain([(1 << 16) - 1]) {
            let [u, v, _, _] = sobol_burley::sample_4d(index, 0, seed);
            assert_eq!(u.to_bits(), sobol_burley::sample(index, 0, seed).to_bits());
            assert_eq!(v.to_bits(), sobol_burley::sample(index, 1, seed).to_bits());
        }
    }
}
