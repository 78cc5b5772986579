//! Soft shadows are unbiased, with the converged value taken from the f64 oracle
//! (`tests/oracle/mod.rs`) rather than from the engine under test.
//!
//! The scene is the closed-form penumbra of `tests/common/analytic.rs`: a floor at y = 0, a
//! light at y = 2 over x, z ∈ [−0.5, 0.5] (a square, or a pentagon for the fan map), and a
//! blocker at y = 1 covering x + z < 0, so a floor point (x, z) sees the light point (lx, lz)
//! exactly when lx + lz ≥ −(x + z). A pixel in the penumbra is rendered by the reference engine with N = 4
//! points per light for `SEEDS` seeds; its mean must match the oracle's converged value (the
//! mean over `TRUTH_SEEDS` seeds of N = 4096 stratified points, in f64) within
//! `K` = 5 standard errors of the difference, each standard error being the sample standard
//! deviation over seeds divided by √seeds. The oracle's converged value is itself checked
//! against a midpoint-rule integral of the closed form. The lab's own N = 1 strategy (the
//! light's centre) must miss the converged value by more than 50 such standard errors.

use crate::common;
use crate::oracle;

use common::analytic::{KD, KE, SIZE, floor_point, scene, settings};
use common::{PENTAGON, SQUARE};

use glam::DVec3;
use oracle::Oracle;
use raywave::render::per_kind::RayCounts;
use raywave::render::reference::Reference;
use raywave::render::sampling::LightSampler;
use raywave::render::scene::Scene;

/// Seeds averaged for the engine's N = 4 estimate.
const SEEDS: u32 = 100_000;
/// Seeds averaged for the oracle's converged value.
const TRUTH_SEEDS: u32 = 64;
/// Points per light for the converged value.
const TRUTH_N: u32 = 4096;
/// Standard errors allowed between an unbiased sampler's mean and the converged value.
const K: f64 = 5.0;

/// (mean, standard error of the mean) of `values`.
fn mean_and_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// The reference engine's pixel (red channel; the scene is grey) over `seeds` seeds.
fn engine(scene: &Scene, sampler: LightSampler, n: u32, seeds: u32, pixel: u32) -> (f64, f64) {
    let values: Vec<f64> = (0..seeds)
        .map(|seed| {
            let s = settings(sampler, n, seed);
            let c = Reference::new(scene, &s).pixel(pixel, &mut RayCounts::default(), &mut ());
            c.x as f64
        })
        .collect();
    mean_and_se(&values)
}

/// The oracle's converged value: N = 4096 stratified points, over `TRUTH_SEEDS` seeds.
fn converged(scene: &Scene, pixel: u32) -> (f64, f64) {
    let values: Vec<f64> = (0..TRUTH_SEEDS)
        .map(|seed| {
            let s = settings(LightSampler::Stratified, TRUTH_N, seed);
            Oracle::new(scene, &s).pixel(pixel).x
        })
        .collect();
    mean_and_se(&values)
}

/// The closed form, integrated by the midpoint rule on a 1000² grid over the light's square:
/// 0.2·kd + Lc·kd·(mean of n·l over visible light points), Lc = 0.2·ke·area.
fn closed_form(light: &[(f64, f64)], p: DVec3) -> f64 {
    let on_light = |x: f64, z: f64| {
        // Inside the convex polygon: on the left of every edge, the corners running
        // counter-clockwise in the (x, z) plane.
        (0..light.len()).all(|k| {
            let (a, b) = (light[k], light[(k + 1) % light.len()]);
            (b.0 - a.0) * (z - a.1) - (b.1 - a.1) * (x - a.0) >= 0.0
        })
    };
    let n = 1000;
    let (mut sum, mut count) = (0.0, 0usize);
    for a in 0..n {
        for b in 0..n {
            let x = -0.5 + (a as f64 + 0.5) / n as f64;
            let z = -0.5 + (b as f64 + 0.5) / n as f64;
            if !on_light(x, z) {
                continue;
            }
            count += 1;
            if x + z >= -(p.x + p.z) {
                sum += (DVec3::new(x, 2.0, z) - p).normalize().y;
            }
        }
    }
    let area = count as f64 / (n * n) as f64;
    0.2 * KD + 0.2 * KE * area * KD * sum / count as f64
}

/// Checks every sampler at the penumbra pixel (35, 36) of the scene with `light`.
fn check_samplers(light: &[(f64, f64)]) {
    let scene = scene(light);
    let (column, row) = (35, 36);
    let pixel = row * SIZE + column;
    let p = floor_point(column, row);
    assert!(
        (p.x + p.z - 0.375).abs() < 0.01,
        "pixel sees {p}: not in the penumbra"
    );
    let truth = converged(&scene, pixel);
    let exact = closed_form(light, p);
    eprintln!("converged {truth:?}, closed form {exact:.6}");
    // The grid's own error is about 1e-4 (its cells straddle the shadow edge).
    assert!(
        (truth.0 - exact).abs() <= K * truth.1 + 2e-4,
        "the oracle's converged {truth:?} is not the closed form {exact}"
    );
    // Every sampler but the lab's, which is random points at N = 4 (its N = 1 is below).
    for sampler in LightSampler::ALL
        .into_iter()
        .filter(|&s| s != LightSampler::Lab)
    {
        let (mean, se) = engine(&scene, sampler, 4, SEEDS, pixel);
        let bound = K * (se * se + truth.1 * truth.1).sqrt();
        eprintln!(
            "{}: mean {mean:.6} ± {se:.6} vs {:.6} (bound {bound:.6})",
            sampler.name(),
            truth.0
        );
        assert!(
            se > 0.0,
            "{}: no noise at all in a penumbra?",
            sampler.name()
        );
        assert!(
            (mean - truth.0).abs() <= bound,
            "{}: mean {mean} ± {se} over {SEEDS} seeds vs the oracle's {} ± {}: differ by {} > \
             {K} standard errors ({bound})",
            sampler.name(),
            truth.0,
            truth.1,
            (mean - truth.0).abs()
        );
    }
    // The lab's strategy at N = 1 is the light's centre every time: a hard shadow, biased by
    // design. Its spread over seeds is zero, so the bound is the converged value's alone.
    let (lab, lab_se) = engine(&scene, LightSampler::Lab, 1, 4, pixel);
    assert_eq!(lab_se, 0.0, "lab N = 1 does not depend on the seed");
    let random_se = engine(&scene, LightSampler::Random, 4, SEEDS, pixel).1;
    eprintln!("lab N=1: {lab:.6} vs {:.6}", truth.0);
    assert!(
        (lab - truth.0).abs() > 50.0 * (random_se * random_se + truth.1 * truth.1).sqrt(),
        "lab N=1 {lab} is not clearly biased against {}",
        truth.0
    );
}

#[test]
fn soft_shadow_samplers_converge_to_the_oracle_under_a_square_light() {
    check_samplers(SQUARE);
}

#[test]
fn soft_shadow_samplers_converge_to_the_oracle_under_a_pentagonal_light() {
    check_samplers(PENTAGON);
}
