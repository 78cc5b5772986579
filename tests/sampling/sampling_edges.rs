//! Sampling at its edges: the strata's upper border when the jitter rounds up, and the lab's
//! strategy, which must equal `random` for every N but 1.

use raywave::render::sampling::{
    CAMERA_LIGHT, LightSampler, PointSet, SampleKey, pixel_offset, strata_grid, uniform,
};

/// The first pixel whose stream draws, in dimension `dim`, one of the two largest values
/// (1 − 2⁻²⁴ or 1 − 2⁻²³): with those, c + ξ rounds up to c + 1 in f32 for c ≥ 2. About one
/// stream in 8 million; the search takes a few tens of milliseconds in release.
fn key_with_top_jitter(light: u32, dim: u32) -> SampleKey {
    let top = 1.0 - 1.0 / (1u32 << 23) as f32;
    (0..u32::MAX)
        .map(|pixel| SampleKey {
            pixel,
            sample: 0,
            bounce: 0,
            light,
            seed: 1,
        })
        .find(|k| uniform(k, dim) >= top)
        .expect("some stream draws the top values")
}

#[test]
fn strata_stay_below_one_when_the_jitter_rounds_up() {
    // N = 3: 3 × 1 strata; point 2 is in the last column, u = (2 + ξ)/3, and ξ = 1 − 2⁻²³
    // gives 2 + ξ = 3.0 in f32, so u would be exactly 1 without the clamp to the float below 1.
    let (nx, _) = strata_grid(3);
    assert_eq!(nx, 3);
    let key = key_with_top_jitter(0, 2 * 2);
    let (u, _) = PointSet::of(LightSampler::Stratified, 3).point(&key, 2);
    assert!(u < 1.0, "{key:?}: u = {u}");
    assert!(
        u > 0.999_999,
        "{key:?}: u = {u}, not at the top of its stratum"
    );
    // N = 9: 3 × 3; point 6 is in the top row, v = (2 + ξ)/3 from dimension 2·6 + 1.
    let key = key_with_top_jitter(0, 2 * 6 + 1);
    let (_, v) = PointSet::of(LightSampler::Stratified, 9).point(&key, 6);
    assert!(v < 1.0 && v > 0.999_999, "{key:?}: v = {v}");
    // The camera's strata: 9 antialiasing samples, sample 8 in the top-right stratum, its
    // jitter from dimensions 0 and 1 of the camera stream.
    let key = key_with_top_jitter(CAMERA_LIGHT, 0);
    let (ox, _) = pixel_offset(&key, 8, 9);
    assert!(ox < 1.0 && ox > 0.999_999, "{key:?}: ox = {ox}");
    let key = key_with_top_jitter(CAMERA_LIGHT, 1);
    let (_, oy) = pixel_offset(&key, 8, 9);
    assert!(oy < 1.0 && oy > 0.999_999, "{key:?}: oy = {oy}");
}

#[test]
fn the_lab_strategy_is_random_except_at_one_point() {
    for n in 1..=12u32 {
        for pixel in 0..40 {
            let key = SampleKey {
                pixel,
                sample: 1,
                bounce: 2,
                light: 1,
                seed: 6,
            };
            for j in 0..n {
                let lab = PointSet::of(LightSampler::Lab, n).point(&key, j);
                let want = if n == 1 {
                    (0.5, 0.5)
                } else {
                    PointSet::of(LightSampler::Random, n).point(&key, j)
                };
                assert_eq!(lab, want, "N = {n}, pixel {pixel}, point {j}");
            }
        }
    }
}
