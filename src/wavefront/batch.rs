//! Structure-of-arrays batches: one `Vec` per field, named like the scalar code's fields
//! (`Ray::origin` → `origin_x/y/z`, `Hit::t`, `Hit::prim`, ...). A lane is index `i` across
//! the columns of one batch; stages load 8 lanes at a time, compute, and store.
//!
//! Buffers are allocated once per worker and reused (`clear` keeps the capacity), so the memory
//! of a render is bounded by the batch size, not by the image.

use crate::spawn::{ShadowRay, SurfaceHit};
use glam::Vec3;

/// Paths in flight at one depth: their current ray and what they carry.
#[derive(Clone, Debug, Default)]
pub struct RayBatch {
    /// Ray origin x.
    pub origin_x: Vec<f32>,
    /// Ray origin y.
    pub origin_y: Vec<f32>,
    /// Ray origin z.
    pub origin_z: Vec<f32>,
    /// Unit direction x.
    pub direction_x: Vec<f32>,
    /// Unit direction y.
    pub direction_y: Vec<f32>,
    /// Unit direction z.
    pub direction_z: Vec<f32>,
    /// End of the ray interval (T_MIN, tmax): infinity for camera and mirror rays.
    pub tmax: Vec<f32>,
    /// Product of the mirror colours kr along the path, red.
    pub throughput_r: Vec<f32>,
    /// ... green.
    pub throughput_g: Vec<f32>,
    /// ... blue.
    pub throughput_b: Vec<f32>,
    /// Pixel index (row-major from the top-left), for the SampleKey.
    pub pixel: Vec<u32>,
    /// Antialiasing sample index, for the SampleKey.
    pub sample: Vec<u32>,
    /// Index of the camera sample this path started as, within the tile (its radiance slot).
    pub slot: Vec<u32>,
    /// Path depth shared by every ray of the batch: 0 for camera rays (the SampleKey's bounce).
    pub bounce: u32,
}

impl RayBatch {
    /// Number of rays.
    pub fn len(&self) -> usize {
        self.tmax.len()
    }

    /// True without rays.
    pub fn is_empty(&self) -> bool {
        self.tmax.is_empty()
    }

    /// Drops every ray, keeping the capacity.
    pub fn clear(&mut self, bounce: u32) {
        self.origin_x.clear();
        self.origin_y.clear();
        self.origin_z.clear();
        self.direction_x.clear();
        self.direction_y.clear();
        self.direction_z.clear();
        self.tmax.clear();
        self.throughput_r.clear();
        self.throughput_g.clear();
        self.throughput_b.clear();
        self.pixel.clear();
        self.sample.clear();
        self.slot.clear();
        self.bounce = bounce;
    }

    /// Appends one ray.
    #[inline(always)]
    pub fn push(&mut self, origin: Vec3, direction: Vec3, throughput: Vec3, path: PathId) {
        self.origin_x.push(origin.x);
        self.origin_y.push(origin.y);
        self.origin_z.push(origin.z);
        self.direction_x.push(direction.x);
        self.direction_y.push(direction.y);
        self.direction_z.push(direction.z);
        self.tmax.push(f32::INFINITY);
        self.throughput_r.push(throughput.x);
        self.throughput_g.push(throughput.y);
        self.throughput_b.push(throughput.z);
        self.pixel.push(path.pixel);
        self.sample.push(path.sample);
        self.slot.push(path.slot);
    }

    /// Origin of ray `i`.
    #[inline]
    pub fn origin(&self, i: usize) -> Vec3 {
        Vec3::new(self.origin_x[i], self.origin_y[i], self.origin_z[i])
    }

    /// Direction of ray `i`.
    #[inline]
    pub fn direction(&self, i: usize) -> Vec3 {
        Vec3::new(
            self.direction_x[i],
            self.direction_y[i],
            self.direction_z[i],
        )
    }

    /// Throughput of ray `i`.
    #[inline]
    pub fn throughput(&self, i: usize) -> Vec3 {
        Vec3::new(
            self.throughput_r[i],
            self.throughput_g[i],
            self.throughput_b[i],
        )
    }

    /// Which camera sample ray `i` belongs to.
    #[inline]
    pub fn path(&self, i: usize) -> PathId {
        PathId {
            pixel: self.pixel[i],
            sample: self.sample[i],
            slot: self.slot[i],
        }
    }
}

/// The identity of a path: its camera sample and where its radiance goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathId {
    /// Pixel index.
    pub pixel: u32,
    /// Antialiasing sample.
    pub sample: u32,
    /// Radiance slot within the tile.
    pub slot: u32,
}

/// The closest hit of every ray of a `RayBatch` (same indices) and what shading needs.
#[derive(Clone, Debug, Default)]
pub struct HitBatch {
    /// Hit distance; `f32::INFINITY` for a miss.
    pub t: Vec<f32>,
    /// Global primitive id; `NO_HIT` for a miss.
    pub prim: Vec<u32>,
    /// Hit point x (origin + t·direction, put back on the surface: `spawn::surface_hit`).
    pub point_x: Vec<f32>,
    /// Hit point y.
    pub point_y: Vec<f32>,
    /// Hit point z.
    pub point_z: Vec<f32>,
    /// Unit shading normal x (flipped towards the ray for two-sided faces).
    pub normal_x: Vec<f32>,
    /// Normal y.
    pub normal_y: Vec<f32>,
    /// Normal z.
    pub normal_z: Vec<f32>,
    /// How far off the surface secondary rays start (`spawn::SurfaceHit::offset`).
    pub offset: Vec<f32>,
    /// Material index (0 for a miss, unused).
    pub material: Vec<u32>,
    /// Σ lights Σ points Shade/N of the visible light points, red.
    pub direct_r: Vec<f32>,
    /// ... green.
    pub direct_g: Vec<f32>,
    /// ... blue.
    pub direct_b: Vec<f32>,
}

impl HitBatch {
    /// Resizes every column to `n` entries (contents are overwritten by the intersect stage).
    pub fn resize(&mut self, n: usize) {
        self.t.resize(n, f32::INFINITY);
        self.prim.resize(n, 0);
        self.point_x.resize(n, 0.0);
        self.point_y.resize(n, 0.0);
        self.point_z.resize(n, 0.0);
        self.normal_x.resize(n, 0.0);
        self.normal_y.resize(n, 0.0);
        self.normal_z.resize(n, 0.0);
        self.offset.resize(n, 0.0);
        self.material.resize(n, 0);
        self.direct_r.resize(n, 0.0);
        self.direct_g.resize(n, 0.0);
        self.direct_b.resize(n, 0.0);
    }

    /// Hit point of ray `i`.
    #[inline]
    pub fn point(&self, i: usize) -> Vec3 {
        Vec3::new(self.point_x[i], self.point_y[i], self.point_z[i])
    }

    /// Shading normal at hit `i`.
    #[inline]
    pub fn normal(&self, i: usize) -> Vec3 {
        Vec3::new(self.normal_x[i], self.normal_y[i], self.normal_z[i])
    }

    /// Hit `i` as the spawn functions take it.
    #[inline]
    pub fn surface(&self, i: usize) -> SurfaceHit {
        SurfaceHit {
            point: self.point(i),
            normal: self.normal(i),
            offset: self.offset[i],
        }
    }

    /// Direct light gathered at hit `i`.
    #[inline]
    pub fn direct(&self, i: usize) -> Vec3 {
        Vec3::new(self.direct_r[i], self.direct_g[i], self.direct_b[i])
    }
}

/// Shadow rays waiting for their occlusion test, in (path, light, point) order: the order in
/// which the reference adds their Shade, so accumulating them in queue order gives its sums.
///
/// The columns keep a fixed length (the capacity) and `len` says how many entries are in use,
/// so stages write 8 lanes at a time without growing vectors. An entry is a live ray only when
/// `n_dot_l > 0`: the SIMD spawn writes whole 8-lane blocks and marks the lanes that cast no
/// ray (the point not far enough above the surface, the hit not above the light's moved plane,
/// or past the last point) dead with `n_dot_l = 0` and `tmax = 0`. The spawn is bound by its
/// stores, so no column is kept that shading can do without (docs/TRIED.md).
#[derive(Clone, Debug, Default)]
pub struct ShadowQueue {
    /// Entries in use.
    pub len: usize,
    /// Origin x (the hit point, offset off its surface).
    pub origin_x: Vec<f32>,
    /// Origin y.
    pub origin_y: Vec<f32>,
    /// Origin z.
    pub origin_z: Vec<f32>,
    /// Unit direction to the light point x (the Shade formula's l, from the hit point itself).
    pub direction_x: Vec<f32>,
    /// Direction y.
    pub direction_y: Vec<f32>,
    /// Direction z.
    pub direction_z: Vec<f32>,
    /// Where the ray meets the light's moved plane (`spawn::ShadowRay::tmax`); 0 for a dead
    /// lane.
    pub tmax: Vec<f32>,
    /// Distance from the hit point to the light point, for the light model's fall-off: kept only
    /// under a model that has one (empty under the lab's: every column the spawn writes costs
    /// the store-bound shadow stage, 7% for this one).
    pub dist: Vec<f32>,
    /// n·l; the entry is a ray only when it is > 0. (Diffuse shading reads this column alone:
    /// recomputing it from l read three.)
    pub n_dot_l: Vec<f32>,
    /// Index of the hit (in the current `HitBatch`) that casts the ray.
    pub path: Vec<u32>,
    /// Light index.
    pub light: Vec<u32>,
    /// Output of the occlusion test.
    pub blocked: Vec<bool>,
}

impl ShadowQueue {
    /// Number of queued entries (live or not).
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Empties the queue and makes room for `capacity` entries, with the `dist` column only
    /// when `with_dist` (a light model with fall-off).
    pub fn reset(&mut self, capacity: usize, with_dist: bool) {
        self.len = 0;
        self.dist.resize(if with_dist { capacity } else { 0 }, 0.0);
        if self.tmax.len() != capacity {
            for c in [
                &mut self.origin_x,
                &mut self.origin_y,
                &mut self.origin_z,
                &mut self.direction_x,
                &mut self.direction_y,
                &mut self.direction_z,
                &mut self.tmax,
                &mut self.n_dot_l,
            ] {
                c.resize(capacity, 0.0);
            }
            self.path.resize(capacity, 0);
            self.light.resize(capacity, 0);
            self.blocked.resize(capacity, false);
        }
    }

    /// Free entries.
    pub fn room(&self) -> usize {
        self.tmax.len() - self.len
    }

    /// Queues one shadow ray.
    #[inline]
    pub fn push(&mut self, ray: &ShadowRay, path: u32, light: u32) {
        let i = self.len;
        self.origin_x[i] = ray.ray.origin.x;
        self.origin_y[i] = ray.ray.origin.y;
        self.origin_z[i] = ray.ray.origin.z;
        self.direction_x[i] = ray.ray.direction.x;
        self.direction_y[i] = ray.ray.direction.y;
        self.direction_z[i] = ray.ray.direction.z;
        self.tmax[i] = ray.tmax;
        self.n_dot_l[i] = ray.n_dot_l;
        if let Some(d) = self.dist.get_mut(i) {
            *d = ray.dist;
        }
        self.path[i] = path;
        self.light[i] = light;
        self.len = i + 1;
    }

    /// Queues a block of 8 or 16 lanes from one origin (`simd::shadow_rays`'s block: dead
    /// lanes already carry `n_dot_l = 0`, `tmax = 0`).
    #[inline]
    pub fn push_block<A: AsRef<[f32]>>(&mut self, block: &ShadowBlock<A>, path: u32, light: u32) {
        let width = block.tmax.as_ref().len();
        let r = self.len..self.len + width;
        self.origin_x[r.clone()].fill(block.origin.x);
        self.origin_y[r.clone()].fill(block.origin.y);
        self.origin_z[r.clone()].fill(block.origin.z);
        self.direction_x[r.clone()].copy_from_slice(block.l[0].as_ref());
        self.direction_y[r.clone()].copy_from_slice(block.l[1].as_ref());
        self.direction_z[r.clone()].copy_from_slice(block.l[2].as_ref());
        self.tmax[r.clone()].copy_from_slice(block.tmax.as_ref());
        self.n_dot_l[r.clone()].copy_from_slice(block.n_dot_l.as_ref());
        if !self.dist.is_empty() {
            self.dist[r.clone()].copy_from_slice(block.dist.as_ref());
        }
        self.path[r.clone()].fill(path);
        self.light[r].fill(light);
        self.len += width;
    }

    /// Direction (l) of ray `i`.
    #[inline]
    pub fn direction(&self, i: usize) -> Vec3 {
        Vec3::new(
            self.direction_x[i],
            self.direction_y[i],
            self.direction_z[i],
        )
    }
}

/// 8 (or 16: `A` is the lanes' array) shadow rays from one hit to one light, as
/// `simd::shadow_rays` makes them: lane k is `spawn::shadow_ray`'s answer for point k, or a
/// dead lane (tmax = 0, n·l = 0).
#[derive(Clone, Copy, Debug)]
pub struct ShadowBlock<A = [f32; 8]> {
    /// The rays' common origin, off the surface.
    pub origin: Vec3,
    /// l x, y, z per lane.
    pub l: [A; 3],
    /// tmax per lane, 0 for a dead one.
    pub tmax: A,
    /// n·l per lane, 0 for a dead one.
    pub n_dot_l: A,
    /// |target − point| per lane.
    pub dist: A,
    /// Live lanes as a bitmask.
    pub live: u32,
}

/// Per camera sample of a tile: the radiance gathered so far.
#[derive(Clone, Debug, Default)]
pub struct Radiance {
    /// Red.
    pub r: Vec<f32>,
    /// Green.
    pub g: Vec<f32>,
    /// Blue.
    pub b: Vec<f32>,
}

impl Radiance {
    /// `n` black slots.
    pub fn reset(&mut self, n: usize) {
        for c in [&mut self.r, &mut self.g, &mut self.b] {
            c.clear();
            c.resize(n, 0.0);
        }
    }

    /// Adds `c` to slot `i`.
    #[inline]
    pub fn add(&mut self, i: usize, c: Vec3) {
        self.r[i] += c.x;
        self.g[i] += c.y;
        self.b[i] += c.z;
    }

    /// Slot `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.r[i], self.g[i], self.b[i])
    }
}
