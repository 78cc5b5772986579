//! Every sampler is unbiased and keeps its points on the light; the penumbra mask matches a
//! scene whose penumbra is known in closed form (`tests/common/analytic.rs`, with the 1 × 1
//! light: lit for s = x + z > 1, umbra for s < −1, penumbra between); the study's budget
//! matching.

use crate::common;
use crate::oracle;

use common::SQUARE;
use common::analytic::{self, SIZE, floor_point, settings};

use glam::{DVec3, Vec3};
use oracle::Oracle;
use raywave::render::per_kind::RayCounts;
use raywave::render::progress::Progress;
use raywave::render::reference::Reference;
use raywave::render::sampling::{LightSampler, PointSet, SampleKey, strata_grid};
use raywave::render::scene::{Scene, parse_scene_str};
use raywave::render::settings::RenderSettings;
use raywave::variance::{Region, penumbra_mask};

#[test]
fn penumbra_mask_matches_the_closed_form() {
    let scene = analytic::scene(SQUARE);
    let regions = penumbra_mask(&scene, &settings(LightSampler::Stratified, 1, 0), 1024);
    let mut checked = [0; 3];
    for row in 0..SIZE {
        for column in 0..SIZE {
            let p = (row * SIZE + column) as usize;
            let DVec3 { x, z, .. } = floor_point(column, row);
            let s = x + z;
            // Stay a pixel and a stratum away from the two edges, where the answer is a tie.
            if (s.abs() - 1.0).abs() < 0.1 {
                continue;
            }
            let (penumbra, lit) = (regions.penumbra[p], regions.lit[p]);
            let expected = if s.abs() < 1.0 {
                (true, false)
            } else if s > 1.0 {
                (false, true)
            } else {
                (false, false)
            };
            assert_eq!(
                (penumbra, lit),
                expected,
                "floor point ({x}, {z}): (penumbra, lit)"
            );
            checked[if s.abs() < 1.0 {
                0
            } else if s > 1.0 {
                1
            } else {
                2
            }] += 1;
        }
    }
    assert!(
        checked.iter().all(|&c| c > 100),
        "too few pixels checked: {checked:?}"
    );
}

/// Mean and standard error of one pixel over `seeds` renders.
fn pixel_mean(scene: &Scene, sampler: LightSampler, n: u32, seeds: u32, pixel: u32) -> (f64, f64) {
    let values: Vec<f64> = (0..seeds)
        .map(|seed| {
            let s = settings(sampler, n, seed);
            let r = Reference::new(scene, &s);
            r.pixel(pixel, &mut RayCounts::default(), &mut ()).x as f64
        })
        .collect();
    let mean = values.iter().sum::<f64>() / seeds as f64;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64;
    (mean, (var / seeds as f64).sqrt())
}

/// The f64 oracle's converged value of one pixel, stratified with `n` points: mean and standard
/// error of the mean over `seeds` seeds (an evaluator independent of the engine under test).
fn oracle_mean(scene: &Scene, n: u32, seeds: u32, pixel: u32) -> (f64, f64) {
    let values: Vec<f64> = (0..seeds)
        .map(|seed| {
            let s = settings(LightSampler::Stratified, n, seed);
            Oracle::new(scene, &s).pixel(pixel).x
        })
        .collect();
    let mean = values.iter().sum::<f64>() / seeds as f64;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64;
    (mean, (var / seeds as f64).sqrt())
}

#[test]
fn every_sampler_is_unbiased_on_a_penumbra_pixel() {
    let scene = analytic::scene(SQUARE);
    // Pixel (35, 36) sees (0.164, 0.211), s = x + z ≈ 0.375: well inside the penumbra.
    let pixel = 36 * SIZE + 35;
    let DVec3 { x, z, .. } = floor_point(35, 36);
    assert!((x + z - 0.375).abs() < 0.01, "{x} {z}");
    let (truth, truth_se) = oracle_mean(&scene, 4096, 8, pixel);
    for sampler in LightSampler::ALL {
        let (mean, se) = pixel_mean(&scene, sampler, 4, 600, pixel);
        let bound = 5.0 * (se * se + truth_se * truth_se).sqrt();
        assert!(
            (mean - truth).abs() < bound,
            "{}: mean {mean} vs converged {truth} (bound {bound})",
            sampler.name()
        );
        assert!(
            se > 0.0,
            "{}: no noise at all in a penumbra?",
            sampler.name()
        );
    }
}

#[test]
fn the_lab_strategy_is_biased_at_one_sample_and_says_so() {
    // N = 1 puts the single point at the light's centre: a hard shadow, not the soft one.
    let scene = analytic::scene(SQUARE);
    let pixel = 36 * SIZE + 35;
    let (truth, truth_se) = oracle_mean(&scene, 4096, 8, pixel);
    let (lab, _) = pixel_mean(&scene, LightSampler::Lab, 1, 2, pixel);
    assert!(
        (lab - truth).abs() > 20.0 * truth_se + 0.05,
        "lab N=1 {lab} vs {truth}"
    );
}

#[test]
fn points_stay_on_the_unit_square_and_cover_it() {
    for sampler in LightSampler::ALL {
        for n in [1u32, 2, 3, 7, 16, 64, 256] {
            for pixel in 0..20 {
                let key = SampleKey {
                    pixel,
                    sample: 0,
                    bounce: 1,
                    light: 2,
                    seed: 9,
                };
                for j in 0..n {
                    let (u, v) = PointSet::of(sampler, n).point(&key, j);
                    assert!(
                        (0.0..1.0).contains(&u) && (0.0..1.0).contains(&v),
                        "{} n={n}: ({u}, {v})",
                        sampler.name()
                    );
                }
            }
        }
    }
    // Stratified and Sobol put exactly one point in every cell of an nx × ny grid (Sobol for
    // powers of two, where its net property holds for every 2^a × 2^b grid).
    for sampler in [LightSampler::Stratified, LightSampler::Sobol] {
        for n in [4u32, 16, 64, 256] {
            assert_one_point_per_stratum(sampler, n, 3, 0);
        }
    }
    // Random points (and the lab's, for N > 1) fill a 4 × 4 grid evenly: 4096 points, 256
    // expected per cell, standard deviation 15.5; 6 deviations either way.
    for sampler in [LightSampler::Random, LightSampler::Lab] {
        let key = SampleKey {
            pixel: 5,
            sample: 0,
            bounce: 0,
            light: 0,
            seed: 4,
        };
        let mut cells = [0i32; 16];
        for j in 0..4096 {
            let (u, v) = PointSet::of(sampler, 4096).point(&key, j);
            cells[((v * 4.0) as usize) * 4 + (u * 4.0) as usize] += 1;
        }
        assert!(
            cells.iter().all(|&c| (c - 256).abs() < 93),
            "{}: {cells:?}",
            sampler.name()
        );
    }
}

#[test]
fn light_points_stay_on_the_light() {
    // A parallelogram, a triangle and a trapezoid (not a parallelogram: the fan path).
    let scene = parse_scene_str(
        "material
         emitted 1 1 1
         v 0 0 0
         v 2 0 0
         v 3 1 0
         v 1 1 0
         v 5 0 0
         v 6 0 0
         v 5 1 0
         v 8 0 0
         v 12 0 0
         v 11 1 0
         v 9 1 0
         m 0
         f 1 2 3 4
         f 5 6 7
         f 8 9 10 11",
        "lights.obj",
    )
    .unwrap();
    assert_eq!(scene.lights.len(), 3);
    let inside = |light: usize, p: Vec3| -> bool {
        let tol = 1e-5;
        if p.z.abs() > tol || p.y < -tol || p.y > 1.0 + tol {
            return false;
        }
        match light {
            0 => p.x >= p.y - tol && p.x <= 2.0 + p.y + tol,
            1 => p.x >= 5.0 - tol && p.x + p.y <= 6.0 + tol,
            _ => p.x >= 8.0 + p.y - tol && p.x <= 12.0 - p.y + tol,
        }
    };
    for (li, light) in scene.lights.iter().enumerate() {
        let mut sum = Vec3::ZERO;
        let count = 20_000;
        for j in 0..count {
            let key = SampleKey {
                pixel: 1,
                sample: 0,
                bounce: 0,
                light: li as u32,
                seed: 2,
            };
            let (u, v) = PointSet::of(LightSampler::Random, count).point(&key, j);
            let p = light.point(u, v);
            assert!(inside(li, p), "light {li}: {p} is off the light");
            sum += p;
        }
        // Uniform by area: the mean point is the area centroid.
        let mean = sum / count as f32;
        assert!(
            (mean - light.centroid).length() < 0.02,
            "light {li}: mean {mean} vs centroid {}",
            light.centroid
        );
    }
    // Centroids computed independently: trapezoid (8,0) (12,0) (11,1) (9,1): area 3,
    // centroid y = (1/3)(b + 2a)/(a + b) with bottom b = 4, top a = 2: (4 + 4)/(3·6) = 4/9.
    assert!((scene.lights[2].centroid - Vec3::new(10.0, 4.0 / 9.0, 0.0)).length() < 1e-5);
    assert!((scene.lights[1].centroid - Vec3::new(16.0 / 3.0, 1.0 / 3.0, 0.0)).length() < 1e-5);
}

#[test]
fn matching_budget_inverts_the_fits() {
    use raywave::stats::LogLogFit;
    use raywave::variance::match_budget;
    // random: MSE = 1/N; stratified: MSE = N^-1.5. Random at 150 gives 1/150; stratified
    // matches it at N = 150^(1/1.5) = 28.2.
    let random = LogLogFit {
        slope: -1.0,
        intercept: 0.0,
    };
    let stratified = LogLogFit {
        slope: -1.5,
        intercept: 0.0,
    };
    let n = match_budget(random, stratified, 150.0);
    assert!((n - 150f64.powf(1.0 / 1.5)).abs() < 1e-6, "{n}");
    // Random against itself matches at 150; an error that does not fall never matches.
    assert!((match_budget(random, random, 150.0) - 150.0).abs() < 1e-9);
    let flat = LogLogFit {
        slope: 0.0,
        intercept: -3.0,
    };
    assert_eq!(match_budget(random, flat, 150.0), f64::INFINITY);
}

/// The whole study, end to end, on the lab's scene at a small size with the wavefront engine:
/// the study's floor (random's penumbra slope −1 ± 0.1, stratified's at most −1.35, stratified
/// MSE at most 1/3 of random's at N = 64, no unbiased sampler flagged) and the output files.
/// Deterministic for fixed seeds, and it fails if stratification breaks (slope → −1).
#[test]
fn the_study_meets_its_floor_and_writes_its_outputs() {
    use raywave::render::engine::Engine;
    use raywave::variance::{StudyConfig, run_study};
    let scene = Scene::builtin_default();
    let base = RenderSettings {
        width: 48,
        height: 48,
        ..RenderSettings::default()
    };
    let config = StudyConfig {
        budgets: vec![4, 16, 64],
        samplers: vec![LightSampler::Random, LightSampler::Stratified],
        seeds: 4,
        reference_samples: 1024,
        mask_samples: 256,
        heatmap_n: 16,
        ..StudyConfig::standard(base)
    };
    let render = |scene: &Scene, s: &RenderSettings| Engine::Wavefront.image(scene, s);
    let result = run_study(
        &scene,
        b"test",
        &config,
        "wavefront",
        &render,
        None,
        &Progress::SILENT,
    )
    .unwrap();
    let slope = |sampler: &str| {
        result
            .slopes
            .iter()
            .find(|s| s.sampler == sampler && s.region == Region::Penumbra)
            .and_then(|s| s.fit)
            .unwrap()
            .slope
    };
    let mse = |sampler: &str, n: u32| {
        result
            .rows
            .iter()
            .find(|r| r.sampler == sampler && r.n == n && r.region == Region::Penumbra)
            .unwrap()
            .stats
            .mse
    };
    println!(
        "penumbra slopes: random {:.3}, stratified {:.3}; MSE ratio at N = 64: {:.3}",
        slope("random"),
        slope("stratified"),
        mse("stratified", 64) / mse("random", 64)
    );
    assert!(
        (slope("random") + 1.0).abs() <= 0.1,
        "random slope {}",
        slope("random")
    );
    assert!(
        slope("stratified") <= -1.35,
        "stratified slope {}",
        slope("stratified")
    );
    let ratio = mse("stratified", 64) / mse("random", 64);
    assert!(
        ratio <= 1.0 / 3.0,
        "stratified/random MSE at N = 64: {ratio}"
    );
    for row in &result.rows {
        assert!(
            row.stats.bias.abs() <= row.stats.bias_bound,
            "{} N={} {:?}: bias {} beyond its bound {}",
            row.sampler,
            row.n,
            row.region,
            row.stats.bias,
            row.stats.bias_bound
        );
    }
    assert!(
        result.facts.region_pixels[1] > 100,
        "penumbra too small: {:?}",
        result.facts.region_pixels
    );

    let dir = tempfile::tempdir().unwrap();
    let written = result.write(dir.path()).unwrap();
    let names: Vec<String> = written
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for name in [
        "table.txt",
        "results.csv",
        "results.json",
        "mse.png",
        "heat_random_N16.png",
        "heat_stratified_N16.png",
    ] {
        assert!(
            names.contains(&name.to_string()),
            "{name} missing from {names:?}"
        );
    }
    let csv = std::fs::read_to_string(dir.path().join("results.csv")).unwrap();
    // Header plus one row per (sampler, N, region).
    assert_eq!(csv.lines().count(), 1 + 2 * 3 * 3);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("results.json")).unwrap())
            .unwrap();
    assert_eq!(json["rows"].as_array().unwrap().len(), 18);
    let png = image::open(dir.path().join("mse.png")).unwrap();
    assert!(png.width() > 100 && png.height() > 100);
}

#[test]
fn stratified_covers_every_stratum_for_non_square_n() {
    for n in [2u32, 3, 6, 7, 8, 10, 12, 15, 18, 100] {
        assert_one_point_per_stratum(LightSampler::Stratified, n, 1, 2);
    }
}

/// Exactly one of the n points of `sampler` in each cell of the `strata_grid(n)` grid, for ten
/// pixels' streams.
fn assert_one_point_per_stratum(sampler: LightSampler, n: u32, sample: u32, bounce: u32) {
    let (nx, ny) = strata_grid(n);
    for pixel in 0..10 {
        let key = SampleKey {
            pixel,
            sample,
            bounce,
            light: 0,
            seed: 5,
        };
        let mut cells = vec![0; n as usize];
        for j in 0..n {
            let (u, v) = PointSet::of(sampler, n).point(&key, j);
            cells[((v * ny as f32) as u32 * nx + (u * nx as f32) as u32) as usize] += 1;
        }
        assert!(
            cells.iter().all(|&c| c == 1),
            "{} n={n} ({nx}x{ny}): {cells:?}",
            sampler.name()
        );
    }
}
