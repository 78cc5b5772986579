//! The point sets pbrt-v4 offers and the blue-noise tables, as the renderers draw them
//! (`PointSet::point`): each keeps the stratification its construction promises, and each
//! sampler's limits are checked with a message that names it.

use raywave::render::sampling::{LightSampler, PointSet, SampleKey, check};
use raywave::render::settings::{RenderSettings, ShadowMode};

fn key(pixel: u32, seed: u32) -> SampleKey {
    SampleKey {
        pixel,
        sample: 0,
        bounce: 1,
        light: 0,
        seed,
    }
}

/// A coordinate in [0, 1) as the 24-bit integer it is (every sampler's points are multiples
/// of 2^-24).
fn bits24(x: f32) -> u32 {
    let b = x * 16_777_216.0;
    assert_eq!(b.fract(), 0.0, "{x} is not a multiple of 2^-24");
    b as u32
}

/// The cell of (u, v) in the elementary interval grid of shape 2^k × 2^(m−k).
fn cell(u: f32, v: f32, m: u32, k: u32) -> usize {
    let top = |x: u32, b: u32| if b == 0 { 0 } else { x >> (24 - b) };
    ((top(bits24(u), k) << (m - k)) | top(bits24(v), m - k)) as usize
}

/// At most `most` of `points` in any elementary interval of area 2^-m, of every shape.
fn assert_intervals(what: &str, points: &[(f32, f32)], m: u32, most: u32) {
    for k in 0..=m {
        let mut counts = vec![0u32; 1 << m];
        for &(u, v) in points {
            counts[cell(u, v, m, k)] += 1;
        }
        assert!(
            counts.iter().all(|&c| c <= most),
            "{what}: shape 2^{k} × 2^{}: {counts:?}",
            m - k
        );
    }
}

#[test]
fn pmj02_points_are_02_nets_at_16_64_and_256_and_stratified_in_between() {
    for n in [16u32, 64, 256] {
        let m = n.trailing_zeros();
        let set = PointSet::of(LightSampler::Pmj02, n);
        for pixel in 0..64 {
            let k = key(pixel, 5);
            let points: Vec<(f32, f32)> = (0..n).map(|j| set.point(&k, j)).collect();
            // n points, 2^m intervals of each shape, at most one each: exactly one each.
            assert_intervals(&format!("pmj02 N={n}, pixel {pixel}"), &points, m, 1);
            // Progressive: every prefix has at most one point per interval of its level.
            for len in [3usize, 5, 11, 37, 100] {
                if len < n as usize {
                    let level = usize::BITS - (len - 1).leading_zeros();
                    assert_intervals(
                        &format!("pmj02 prefix {len} of {n}, pixel {pixel}"),
                        &points[..len],
                        level,
                        1,
                    );
                }
            }
        }
    }
    // A stream of a non-power-of-two N reads the next table: still one point per interval.
    let set = PointSet::of(LightSampler::Pmj02, 100);
    let points: Vec<(f32, f32)> = (0..100).map(|j| set.point(&key(3, 1), j)).collect();
    assert_intervals("pmj02 N=100", &points, 7, 1);
}

#[test]
fn halton_points_fill_every_box_of_their_bases() {
    // 72 = 2^3 · 3^2 points: one in each of the 8 × 9 boxes.
    let set = PointSet::of(LightSampler::Halton, 72);
    for pixel in 0..50 {
        let k = key(pixel, 2);
        let mut boxes = [0u32; 72];
        for j in 0..72 {
            let (u, v) = set.point(&k, j);
            boxes[(v * 9.0) as usize * 8 + (u * 8.0) as usize] += 1;
        }
        assert!(boxes.iter().all(|&c| c == 1), "pixel {pixel}: {boxes:?}");
    }
}

/// ZSobol's screen-space trick: with one point per pixel, the 4 pixels of an aligned 2 × 2
/// quad (4 consecutive Morton indices, permuted within their block) take one (0,2,2)-net of
/// the stream's Sobol sequence, and 4 × 4 pixels a (0,4,2)-net: neighbours' points avoid each
/// other, which is what makes their errors cancel.
#[test]
fn zsobol_pixel_blocks_take_one_net_between_them() {
    let (w, h) = (64u32, 32u32);
    let set = PointSet::with(LightSampler::Zsobol, 1, (w, h), 1);
    for (side, m) in [(2u32, 2u32), (4, 4)] {
        for by in (0..h).step_by(side as usize) {
            for bx in (0..w).step_by(side as usize) {
                let points: Vec<(f32, f32)> = (0..side * side)
                    .map(|i| {
                        let (x, y) = (bx + i % side, by + i / side);
                        set.point(&key(y * w + x, 9), 0)
                    })
                    .collect();
                assert_intervals(
                    &format!("{side}×{side} pixels at ({bx}, {by})"),
                    &points,
                    m,
                    1,
                );
            }
        }
    }
    // Not the same net for every seed, bounce or light: the stream's seed moves it.
    let p = |k: SampleKey| set.point(&k, 0);
    let base = key(5, 9);
    assert_ne!(p(base), p(SampleKey { seed: 10, ..base }));
    assert_ne!(p(base), p(SampleKey { bounce: 2, ..base }));
    assert_ne!(p(base), p(SampleKey { light: 1, ..base }));
}

/// The blue-noise tables as the sampler reads them: a pixel's N points lie on the tables'
/// 1/256 lattice, moved by one rotation for the whole stream, and are N distinct points
/// (the tables' stratification itself is tested in `render/sampling/bluenoise.rs`);
/// neighbouring pixels draw different points; another seed moves every point.
#[test]
fn bluenoise_points_keep_the_tables_lattice_and_differ_from_their_neighbours() {
    let (w, h) = (32u32, 32u32);
    for n in [4u32, 16, 64] {
        let set = PointSet::with(LightSampler::Bluenoise, n, (w, h), 1);
        for pixel in [0u32, 17, 500, 1023] {
            let k = key(pixel, 3);
            let points: Vec<(f32, f32)> = (0..n).map(|j| set.point(&k, j)).collect();
            let (u0, v0) = points[0];
            for &(u, v) in &points {
                for d in [(u - u0) * 256.0, (v - v0) * 256.0] {
                    assert!(
                        (d - d.round()).abs() < 1e-3,
                        "N={n}, pixel {pixel}: off the lattice"
                    );
                }
            }
            let mut cells: Vec<(u32, u32)> = points
                .iter()
                .map(|&(u, v)| (bits24(u), bits24(v)))
                .collect();
            cells.sort_unstable();
            cells.dedup();
            assert_eq!(
                cells.len(),
                n as usize,
                "N={n}, pixel {pixel}: repeated points"
            );
            assert_ne!(
                points[0],
                set.point(&key(pixel, 4), 0),
                "the seed moves nothing"
            );
        }
        let a = set.point(&key(40, 3), 0);
        let b = set.point(&key(41, 3), 0);
        assert_ne!(a, b, "N={n}: neighbours share a point");
    }
}

fn soft(sampler: LightSampler, n: u32, size: (u32, u32), aa: u32) -> RenderSettings {
    RenderSettings {
        width: size.0,
        height: size.1,
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        aa_samples: aa,
        ..RenderSettings::default()
    }
}

#[test]
fn every_sampler_s_limits_are_checked_and_named() {
    let ok = |s: RenderSettings| check(&s).expect("within the limits");
    let err = |s: RenderSettings| check(&s).expect_err("past a limit").to_string();
    for sampler in LightSampler::ALL {
        ok(soft(sampler, 1, (512, 512), 1));
        ok(soft(sampler, 256, (512, 512), 1));
        let e = err(soft(sampler, 0, (512, 512), 1));
        assert!(
            e.contains("--shadow-samples 0") && e.contains(sampler.name()),
            "{e}"
        );
        // No points is an error with any shadows: it is never a setting.
        let hard = RenderSettings {
            shadows: ShadowMode::Hard,
            ..soft(sampler, 0, (64, 64), 1)
        };
        assert!(check(&hard).is_err());
    }
    for sampler in [
        LightSampler::Random,
        LightSampler::Stratified,
        LightSampler::Sobol,
        LightSampler::Lab,
        LightSampler::Halton,
    ] {
        ok(soft(sampler, 65536, (512, 512), 4));
    }
    ok(soft(LightSampler::Pmj02, 4096, (512, 512), 1));
    let e = err(soft(LightSampler::Pmj02, 4097, (512, 512), 1));
    assert!(e.contains("pmj02") && e.contains("4096"), "{e}");
    ok(soft(LightSampler::Bluenoise, 64, (512, 512), 4));
    let e = err(soft(LightSampler::Bluenoise, 257, (512, 512), 1));
    assert!(e.contains("bluenoise") && e.contains("256"), "{e}");
    let e = err(soft(LightSampler::Bluenoise, 64, (512, 512), 8));
    assert!(e.contains("512 per pixel") && e.contains("256"), "{e}");
    // 16384² is 28 index bits, 16 samples 4 more: 32, the most.
    ok(soft(LightSampler::Zsobol, 16, (16384, 16384), 1));
    let e = err(soft(LightSampler::Zsobol, 17, (16384, 16384), 1));
    assert!(
        e.contains("zsobol") && e.contains("33-bit") && e.contains("32"),
        "{e}"
    );
    // Hard shadows count one point per light.
    let hard = RenderSettings {
        shadows: ShadowMode::Hard,
        ..soft(LightSampler::Bluenoise, 4096, (512, 512), 1)
    };
    ok(hard);
}
