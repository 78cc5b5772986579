//! The SIMD kernels of the stages, by idea: ray–primitive tests (`geometry.rs`), light
//! sampling with shadow-ray spawning (`light.rs`, the per-stream point sets in
//! `point_sets.rs`) and camera rays (`camera.rs`); the shading kernel sits with its scalar twin
//! in `wavefront/shade.rs`, and the mesh BVH's node and leaf tests in `wavefront/bvh/`.
//!
//! The brute-force, light and shading kernels are written once over `lanes::Lanes` and take
//! the width (8 or 16) as a type parameter (`closest_hits::<V>`; a width chosen at run time
//! becomes that type in `lanes::at_width!`) or from their operands (`triangle8`, `sphere8`,
//! `moller_trumbore8`: names from the 8-wide days). The kernels that count their work take the
//! count's sink too, which `cost::NoCount` compiles away. The mesh BVH's kernels stay 8-wide.
//!
//! Every kernel is a lane-by-lane copy of a scalar twin, with the same operations in the
//! same order, so that with IEEE arithmetic (no FMA contraction: Rust never fuses `a * b + c`,
//! and neither does `wide`) each lane gives the same bits as the twin:
//!
//! | kernel               | scalar twin                                              |
//! |----------------------|----------------------------------------------------------|
//! | `moller_trumbore8` | `geometry::intersect_triangle` (8 rays × 1 triangle in [`triangle8`], 1 ray × 8 triangles in `bvh/`) |
//! | [`sphere8`]          | `geometry::intersect_sphere`                             |
//! | [`closest_hits`]     | `Accel::closest` without a BVH                           |
//! | [`occluded`]         | `Accel::occluded` without a BVH                          |
//! | [`light_points`]     | `sampling::PointSet::point` then `Light::point`          |
//! | `point_sets::{halton, zsobol, pmj02}` | `sampling::Stream::point` of those samplers |
//! | [`shadow_rays`]      | the start of `Reference::direct` (l, dist, n·l)          |
//! | `shade::shade_lanes` | `shade::shade_terms`, twin of `shading::shade`           |
//! | [`camera_directions`] | `CameraRays::rays_of` at one sample per pixel           |
//!
//! Branches become masks: a lane that misses gets `f32::INFINITY`, exactly like the twins'
//! sentinel. Batches whose length is not a multiple of the width are padded with lanes that
//! cannot hit (tmax = 0, NaN directions), and the padding is never stored back.

mod camera;
mod geometry;
mod hit_rays;
mod light;
mod point_sets;

pub use camera::camera_directions;
pub(crate) use geometry::{TriangleLanes, moller_trumbore8, moller_trumbore8_blocks};
pub use geometry::{block_occluded, closest_hits, hit_rays_occluded, occluded, sphere8, triangle8};
pub use hit_rays::{HitLanes, hit_shadow_rays};
pub use light::{BlockSampler, LightBlock, light_points, shadow_rays};

use super::lanes::{Lanes, f32x8};
use crate::render::geometry::Ray;
use crate::render::scene::{Sphere, Triangle};
use glam::Vec3;

/// Ray columns of a batch, borrowed: origin, direction and tmax.
#[derive(Clone, Copy)]
pub struct RayColumns<'a> {
    /// origin x, y, z.
    pub origin: [&'a [f32]; 3],
    /// direction x, y, z.
    pub direction: [&'a [f32]; 3],
    /// End of the interval (T_MIN, tmax).
    pub tmax: &'a [f32],
}

impl RayColumns<'_> {
    /// Number of rays.
    pub fn len(&self) -> usize {
        self.tmax.len()
    }
    /// True without rays.
    pub fn is_empty(&self) -> bool {
        self.tmax.is_empty()
    }
    /// Ray `i`.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        let (o, d) = (self.origin, self.direction);
        Ray {
            origin: Vec3::new(o[0][i], o[1][i], o[2][i]),
            direction: Vec3::new(d[0][i], d[1][i], d[2][i]),
        }
    }
}

/// N rays in registers (8 or 16, the width of `V`).
#[derive(Clone, Copy)]
pub struct Rays<V = f32x8> {
    ox: V,
    oy: V,
    oz: V,
    dx: V,
    dy: V,
    dz: V,
}

impl<V: Lanes> Rays<V> {
    /// Loads rays `i..i + N` (padding past the end with NaN directions).
    #[inline(always)]
    fn load(r: &RayColumns, i: usize) -> Rays<V> {
        Rays {
            ox: V::load(r.origin[0], i, 0.0),
            oy: V::load(r.origin[1], i, 0.0),
            oz: V::load(r.origin[2], i, 0.0),
            dx: V::load(r.direction[0], i, f32::NAN),
            dy: V::load(r.direction[1], i, f32::NAN),
            dz: V::load(r.direction[2], i, f32::NAN),
        }
    }

    /// N rays given as a slice of `N` rays.
    fn from_rays(rays: &[Ray]) -> Rays<V> {
        let col = |f: fn(&Ray) -> f32| V::from_fn(|k| f(&rays[k]));
        Rays {
            ox: col(|r| r.origin.x),
            oy: col(|r| r.origin.y),
            oz: col(|r| r.origin.z),
            dx: col(|r| r.direction.x),
            dy: col(|r| r.direction.y),
            dz: col(|r| r.direction.z),
        }
    }
}

/// Lane-level entry points for tests: N rays given as slices, the kernels' answers as arrays.
pub mod arrays {
    use super::*;

    /// [`triangle8`] at the width of `V`, on `V::N` rays and tmaxes.
    pub fn triangle_lanes<V: Lanes>(
        tri: &Triangle,
        rays: &[Ray],
        tmax: &[f32],
        two_sided: bool,
    ) -> V::Array {
        assert!(rays.len() == V::N && tmax.len() == V::N);
        triangle8(
            tri,
            &Rays::<V>::from_rays(rays),
            V::load(tmax, 0, 0.0),
            two_sided,
        )
        .to_array()
    }

    /// [`sphere8`] at the width of `V`, on `V::N` rays and tmaxes.
    pub fn sphere_lanes<V: Lanes>(s: &Sphere, rays: &[Ray], tmax: &[f32]) -> V::Array {
        assert!(rays.len() == V::N && tmax.len() == V::N);
        sphere8(s, &Rays::<V>::from_rays(rays), V::load(tmax, 0, 0.0)).to_array()
    }
}
