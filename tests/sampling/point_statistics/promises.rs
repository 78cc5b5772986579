//! Each point set's own construction, through the stream API: what its paper promises of the
//! points of one stream (or of a few pixels' streams), checked exactly on many streams.
//!
//! - stratified: one point in each stratum of the `strata_grid(N)` grid;
//! - sobol: a (0,2)-sequence: every aligned block of 2^k points (k ≤ m, N = 2^m) is a
//!   (0,k,2)-net, one point in every elementary interval of area 2^-k of every shape, after the
//!   scramble (up to its 65536 points);
//! - pmj02: progressive: its first 2^k points are a (0,k,2)-net after the digital shift, so
//!   every prefix is stratified at its level;
//! - zsobol: a stream of 2^m points is a (0,m,2)-net, and so are its first 4^a points; with one
//!   point per pixel, a Morton quad's pixels take one net between them;
//! - halton: every aligned block of 2^a · 3^b indices fills the 2^a × 3^b boxes, and every
//!   block of b^k indices takes one b^-k interval each on its axis;
//! - bluenoise: a stream's points lie on the tables' 1/256 lattice, moved by one rotation, and
//!   each axis is stratified at every power of two as far as a rotation lets one see.

use super::{COUNTS, IMAGE, point_set, points, stream_key};
use raywave::render::sampling::{LightSampler, PointSet, SampleKey, strata_grid};

/// Streams checked per sampler and N.
const STREAMS: u32 = 200;

/// A coordinate in [0, 1) as the 24-bit integer it is (every sampler's points are multiples
/// of 2^-24).
fn bits24(x: f64) -> u32 {
    let b = x * 16_777_216.0;
    assert_eq!(b.fract(), 0.0, "{x} is not a multiple of 2^-24");
    b as u32
}

/// The cell of (u, v) in the elementary-interval grid of shape 2^k × 2^(m−k).
fn cell(u: f64, v: f64, m: u32, k: u32) -> usize {
    let top = |x: u32, b: u32| if b == 0 { 0 } else { x >> (24 - b) };
    ((top(bits24(u), k) << (m - k)) | top(bits24(v), m - k)) as usize
}

/// At most `most` of `points` in any elementary interval of area 2^-m, of every shape.
fn assert_intervals(what: &str, points: &[(f64, f64)], m: u32, most: u32) {
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

/// Every aligned block of 2^k of `points` (2^m of them) is a (0,k,2)-net, k = 0..=m.
fn assert_02_sequence(what: &str, points: &[(f64, f64)]) {
    let m = points.len().trailing_zeros();
    assert_eq!(points.len(), 1 << m);
    for k in 0..=m {
        for (b, block) in points.chunks(1 << k).enumerate() {
            assert_intervals(&format!("{what}, block {b} of 2^{k}"), block, k, 1);
        }
    }
}

fn key(pixel: u32, seed: u32) -> SampleKey {
    SampleKey {
        pixel,
        sample: 0,
        bounce: 1,
        light: 0,
        seed,
    }
}

#[test]
fn a_stream_s_points_are_the_point_sets_points() {
    // The reference reads a stream's points through `PointSet::stream`, the wavefront engine
    // also through `PointSet::point`: the same points.
    for sampler in LightSampler::ALL {
        for n in COUNTS {
            let set = point_set(sampler, n);
            for t in 0..20 {
                let k = stream_key(t);
                let via_stream = points(&set, &k);
                for (j, &p) in via_stream.iter().enumerate() {
                    let (u, v) = set.point(&k, j as u32);
                    assert_eq!(
                        (f64::from(u), f64::from(v)),
                        p,
                        "{} N = {n}",
                        sampler.name()
                    );
                    assert!((0.0..1.0).contains(&p.0) && (0.0..1.0).contains(&p.1));
                }
            }
        }
    }
}

#[test]
fn stratified_streams_put_one_point_in_every_stratum() {
    for n in COUNTS.into_iter().chain([10, 7]) {
        let set = PointSet::of(LightSampler::Stratified, n);
        let (nx, ny) = strata_grid(n);
        for t in 0..STREAMS {
            let mut seen = vec![0u32; n as usize];
            for (u, v) in points(&set, &stream_key(t)) {
                seen[(v * f64::from(ny)) as usize * nx as usize + (u * f64::from(nx)) as usize] +=
                    1;
            }
            assert!(
                seen.iter().all(|&c| c == 1),
                "N = {n}, stream {t}: {seen:?}"
            );
        }
    }
}

#[test]
fn sobol_streams_are_02_sequences_at_every_power_of_two() {
    for n in COUNTS {
        let set = point_set(LightSampler::Sobol, n);
        for t in 0..STREAMS {
            assert_02_sequence(
                &format!("sobol N = {n}, stream {t}"),
                &points(&set, &stream_key(t)),
            );
        }
    }
    // Sobol's indices are 16 bits: the whole range is one (0,16,2)-net of (0,2) blocks.
    let set = PointSet::of(LightSampler::Sobol, 65_536);
    for t in 0..2 {
        assert_02_sequence("sobol N = 65536", &points(&set, &stream_key(t)));
    }
}

#[test]
fn pmj02_prefixes_are_nets_at_every_power_of_two() {
    // Progressive: the first 2^k points are a (0,k,2)-net, so every prefix of n points,
    // 2^(k−1) < n ≤ 2^k, has at most one point in each elementary interval of area 2^-k.
    // (Later aligned blocks need not be nets: the tables are built prefix by prefix.)
    for n in COUNTS {
        let set = point_set(LightSampler::Pmj02, n);
        for t in 0..STREAMS {
            let p = points(&set, &stream_key(t));
            for k in 0..=n.trailing_zeros() {
                let what = format!("pmj02 N = {n}, stream {t}, first 2^{k}");
                assert_intervals(&what, &p[..1 << k], k, 1);
            }
        }
    }
    // A stream of N that is no power of two reads the next table's first N points.
    let set = PointSet::of(LightSampler::Pmj02, 100);
    for t in 0..STREAMS {
        assert_intervals("pmj02 N = 100", &points(&set, &stream_key(t)), 7, 1);
    }
}

#[test]
fn zsobol_streams_are_nets_and_so_are_their_first_powers_of_four() {
    // The stream's Sobol indices are one aligned block, their base-4 digits permuted within
    // it: the whole stream is a net, and the first 4^a points (whose index digits above the
    // a lowest are the stream's own) are one too.
    for n in COUNTS {
        let set = point_set(LightSampler::Zsobol, n);
        let m = n.trailing_zeros();
        for t in 0..STREAMS {
            let p = points(&set, &stream_key(t));
            for a in (0..=m).step_by(2) {
                assert_intervals(
                    &format!("zsobol N = {n}, stream {t}, first 2^{a}"),
                    &p[..1 << a],
                    a,
                    1,
                );
            }
        }
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
                let points: Vec<(f64, f64)> = (0..side * side)
                    .map(|i| {
                        let (x, y) = (bx + i % side, by + i / side);
                        let (u, v) = set.stream(&key(y * w + x, 9)).expect("a stream").point(0);
                        (f64::from(u), f64::from(v))
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
    let p = |k: SampleKey| set.stream(&k).expect("a stream").point(0);
    let base = key(5, 9);
    assert_ne!(p(base), p(SampleKey { seed: 10, ..base }));
    assert_ne!(p(base), p(SampleKey { bounce: 2, ..base }));
    assert_ne!(p(base), p(SampleKey { light: 1, ..base }));
}

/// The cell of x among `size` (of [0, 1)), and whether x sits on that cell's lower edge (within
/// 2^-22, a few float steps): where `halton::radical_inverse` puts a point whose digits below
/// the permuted ones are within about 2^-15 of a whole unit, because `kept + rest` rounds up in
/// f32 to the next cell's edge (about 1 point in 10^5 at N = 256).
fn cell_on_edge(x: f64, size: usize) -> (usize, bool) {
    let s = x * size as f64;
    let c = (s as usize).min(size - 1);
    (c, c > 0 && s - (c as f64) < size as f64 * 2f64.powi(-22))
}

/// Whether `points` put exactly one point in each of the nx × ny boxes, a point on a box's
/// lower edge counting in the box below it if its own is taken; the number of points so
/// counted.
fn fill_once(points: &[(f64, f64)], nx: usize, ny: usize) -> Result<usize, Vec<u32>> {
    let mut boxes = vec![0u32; nx * ny];
    let mut on_edge = Vec::new();
    for &(u, v) in points {
        let ((cx, ex), (cy, ey)) = (cell_on_edge(u, nx), cell_on_edge(v, ny));
        if ex || ey {
            on_edge.push((cx, ex, cy, ey));
        } else {
            boxes[cy * nx + cx] += 1;
        }
    }
    let mut moved = 0;
    for (cx, ex, cy, ey) in on_edge {
        let below = |c: usize, e: bool| if e { vec![c, c - 1] } else { vec![c] };
        let free = below(cy, ey)
            .into_iter()
            .flat_map(|y| below(cx, ex).into_iter().map(move |x| y * nx + x))
            .find(|&b| boxes[b] == 0)
            .unwrap_or(cy * nx + cx);
        moved += usize::from(free != cy * nx + cx);
        boxes[free] += 1;
    }
    if boxes.iter().all(|&c| c == 1) {
        Ok(moved)
    } else {
        Err(boxes)
    }
}

#[test]
fn halton_blocks_fill_their_boxes_and_each_axis_its_intervals() {
    let mut moved = 0;
    for n in COUNTS.into_iter().chain([72]) {
        let set = point_set(LightSampler::Halton, n);
        for t in 0..STREAMS {
            let p = points(&set, &stream_key(t));
            let mut check = |what: &str, block: &[(f64, f64)], nx: usize, ny: usize| match fill_once(
                block, nx, ny,
            ) {
                Ok(m) => moved += m,
                Err(boxes) => panic!("halton N = {n}, stream {t}: {what}: {boxes:?}"),
            };
            // Every aligned block of 2^a · 3^b indices: one point in each of the 2^a × 3^b boxes.
            for (a, b) in [(1u32, 1u32), (2, 1), (1, 2), (3, 1), (2, 2), (3, 2), (4, 3)] {
                let (nx, ny) = (1usize << a, 3usize.pow(b));
                for (i, block) in p.chunks_exact(nx * ny).enumerate() {
                    check(&format!("block {i} of {nx}×{ny}"), block, nx, ny);
                }
            }
            // Each axis on its own, at every power of its base up to N: the radical inverse of
            // any b^k consecutive aligned indices takes each interval of b^-k once.
            for size in
                std::iter::successors(Some(2), |s| Some(s * 2)).take_while(|&s| s <= n as usize)
            {
                for (i, block) in p.chunks_exact(size).enumerate() {
                    check(&format!("u, block {i} of {size}"), block, size, 1);
                }
            }
            for size in
                std::iter::successors(Some(3), |s| Some(s * 3)).take_while(|&s| s <= n as usize)
            {
                for (i, block) in p.chunks_exact(size).enumerate() {
                    check(&format!("v, block {i} of {size}"), block, 1, size);
                }
            }
        }
    }
    // A point rounded onto the next cell's edge is a float effect, not a misplaced digit: rare.
    println!("halton: {moved} points counted in the cell below their edge");
    assert!(
        moved < 50,
        "{moved} points on their cell's edge: more than float rounding gives"
    );
}

/// The lattice steps of `points` from the first one, per axis: integers in 0..256.
fn lattice_steps(what: &str, points: &[(f64, f64)]) -> Vec<(u32, u32)> {
    let (u0, v0) = points[0];
    points
        .iter()
        .map(|&(u, v)| {
            let step = |d: f64| {
                let s = (d * 256.0).rem_euclid(256.0);
                let r = s.round();
                assert!((s - r).abs() < 1e-3, "{what}: off the 1/256 lattice");
                r as u32 % 256
            };
            (step(u - u0), step(v - v0))
        })
        .collect()
}

/// The blue-noise tables as the sampler reads them: a pixel's N points lie on the tables'
/// 1/256 lattice, moved by one rotation for the whole stream, and are N distinct points; each
/// axis is stratified (the first 2^k of a pixel's samples take 2^k distinct strata of the
/// tables, which a rotation shows as no cyclic gap of 2 strata or more between them);
/// neighbouring pixels draw different points; another seed moves every point.
#[test]
fn bluenoise_points_keep_the_tables_lattice_and_strata() {
    for n in COUNTS {
        let set = point_set(LightSampler::Bluenoise, n);
        for t in 0..STREAMS {
            let k = stream_key(t);
            let p = points(&set, &k);
            let what = format!("bluenoise N = {n}, stream {t}");
            let steps = lattice_steps(&what, &p);
            let mut distinct = steps.clone();
            distinct.sort_unstable();
            distinct.dedup();
            assert_eq!(distinct.len(), n as usize, "{what}: repeated points");
            for axis in 0..2 {
                let mut len = 2;
                while len <= n as usize {
                    let mut s: Vec<u32> = steps[..len]
                        .iter()
                        .map(|&(a, b)| if axis == 0 { a } else { b })
                        .collect();
                    s.sort_unstable();
                    let stratum = 256 / len as u32;
                    let gaps = s
                        .windows(2)
                        .map(|w| w[1] - w[0])
                        .chain([s[0] + 256 - s[len - 1]]);
                    let widest = gaps.max().expect("two or more points");
                    assert!(
                        widest < 2 * stratum,
                        "{what}: axis {axis}, the first {len} leave a gap of {widest}/256"
                    );
                    len *= 2;
                }
            }
            let other = points(
                &set,
                &SampleKey {
                    seed: k.seed + 1,
                    ..k
                },
            );
            assert!(
                p.iter().zip(&other).all(|(a, b)| a != b),
                "{what}: the seed moves nothing"
            );
            let right = points(
                &set,
                &SampleKey {
                    pixel: k.pixel ^ 1,
                    ..k
                },
            );
            assert_ne!(p, right, "{what}: neighbours share their points");
        }
    }
    assert!(IMAGE.0.is_multiple_of(2), "pixel ^ 1 stays on the row");
}
