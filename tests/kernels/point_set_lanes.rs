//! The per-stream point sets on lanes (Halton, ZSobol, PMJ02; `simd/point_sets.rs`) against
//! their scalar twins, `PointSet::point`, over the whole range of each sampler's limits: the
//! proptest of `wavefront_kernels` covers fewer than 80 points per light, while a Halton
//! stream of 65536 points runs 16 and 11 digits, a PMJ02 stream reads its table's last rows,
//! and ZSobol's index reaches 32 bits on large images, with odd and even lengths.

use glam::Vec3;
use raywave::render::sampling::{LightSampler, PointSet, SampleKey};
use raywave::render::scene::{Light, LightShape};
use raywave::render::wavefront::lanes::{Lanes, f32x8, f32x16};
use raywave::render::wavefront::shadow::key_prefix;
use raywave::render::wavefront::simd::{self, BlockSampler, LightBlock};

/// The unit square as a light, so that a light point's x and z are the sample's (u, v) scaled.
fn lamp() -> Light {
    Light {
        face: 0,
        shape: LightShape::Parallelogram {
            origin: Vec3::new(-1.0, 2.0, 0.5),
            edge_u: Vec3::X * 2.0,
            edge_v: Vec3::Z * 0.5,
        },
        centroid: Vec3::ZERO,
        area: 1.0,
        normal: Vec3::Y,
        color: Vec3::ONE,
    }
}

/// Blocks of `V::N` points from `starts` of `key`'s stream in `set`, lane by lane against the
/// twin; returns how many points were compared.
fn check_blocks<V: Lanes>(set: &PointSet, key: &SampleKey, starts: &[u32]) -> usize
where
    V::Array: AsRef<[f32]>,
{
    let lamp = lamp();
    let LightShape::Parallelogram {
        origin,
        edge_u,
        edge_v,
    } = lamp.shape
    else {
        unreachable!("a parallelogram")
    };
    let stream = set.stream(key).expect("a per-stream sampler");
    let mut compared = 0;
    for &j0 in starts {
        let pts = simd::light_points::<V>(&LightBlock {
            prefix: key_prefix(key),
            j0,
            sampler: BlockSampler::Stream {
                stream,
                count: set.count,
            },
            origin,
            edge_u,
            edge_v,
        });
        for k in 0..V::N {
            let j = j0 + k as u32;
            if j >= set.count {
                break;
            }
            let (u, v) = set.point(key, j);
            let want = lamp.point(u, v).to_array().map(f32::to_bits);
            let got = [0, 1, 2].map(|a| pts[a].as_ref()[k].to_bits());
            assert_eq!(
                got,
                want,
                "{:?}, {} lanes, key {key:?}, point {j}",
                set.sampler,
                V::N
            );
            compared += 1;
        }
    }
    compared
}

/// Block starts spread over 0..count, and the last blocks.
fn starts(count: u32, stride: u32) -> Vec<u32> {
    let mut s: Vec<u32> = (0..count).step_by(stride as usize).collect();
    s.extend([
        count.saturating_sub(16),
        count.saturating_sub(9),
        count.saturating_sub(8),
    ]);
    s
}

fn keys() -> Vec<SampleKey> {
    [(0, 0, 0), (12_345, 7, u32::MAX), (u32::MAX, 1, 3)]
        .into_iter()
        .map(|(pixel, sample, seed)| SampleKey {
            pixel,
            sample,
            bounce: 2,
            light: 1,
            seed,
        })
        .collect()
}

#[test]
fn halton_lanes_equal_the_twin_up_to_65536_points() {
    for count in [1, 2, 3, 9, 27, 28, 100, 4096, 65_536] {
        let set = PointSet::of(LightSampler::Halton, count);
        for key in keys() {
            let at = starts(count, 8 * 97);
            assert!(check_blocks::<f32x8>(&set, &key, &at) > 0);
            assert!(check_blocks::<f32x16>(&set, &key, &at) > 0);
        }
    }
}

#[test]
fn pmj02_lanes_equal_the_twin_to_the_tables_end() {
    for count in [1, 5, 16, 100, 4096] {
        let set = PointSet::of(LightSampler::Pmj02, count);
        for key in keys() {
            // Every block, so the tables' last rows (and a block past them) are read.
            let at: Vec<u32> = (0..count).step_by(8).collect();
            assert!(check_blocks::<f32x8>(&set, &key, &at) > 0);
            assert!(check_blocks::<f32x16>(&set, &key, &at) > 0);
        }
    }
}

#[test]
fn zsobol_lanes_equal_the_twin_for_odd_and_even_index_lengths() {
    // (image, aa, points): index lengths 0, 1, 9, 22, 23, 31 and 32 bits.
    for (size, aa, count) in [
        ((1, 1), 1, 1),
        ((1, 1), 1, 2),
        ((5, 5), 2, 3),
        ((640, 480), 1, 4),
        ((640, 480), 2, 4),
        ((1024, 1024), 2, 1024),
        ((16_384, 16_384), 4, 4),
        ((1024, 1024), 1, 4096),
    ] {
        let set = PointSet::with(LightSampler::Zsobol, count, size, aa);
        for key in keys() {
            let key = SampleKey {
                pixel: key.pixel % (size.0 * size.1),
                sample: key.sample % aa,
                ..key
            };
            let at = starts(count, 8 * 13);
            assert!(check_blocks::<f32x8>(&set, &key, &at) > 0);
            assert!(check_blocks::<f32x16>(&set, &key, &at) > 0);
        }
    }
}
