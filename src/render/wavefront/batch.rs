//! Structure-of-arrays batches: one `Vec` per field, named like the scalar code's fields
//! (`Ray::origin` → `origin`, `Hit::t`, `Hit::prim`, ...); a vector field is a [`Vec3Column`]
//! of three, so `rays.origin.x[i]` reads like `ray.origin.x`. A lane is index `i` across the
//! columns of one batch; stages load 8 lanes at a time, compute, and store.
//!
//! Buffers are allocated once per worker and reused (`clear` keeps the capacity), so the memory
//! of a render is bounded by the batch size, not by the image.

use super::shade::MaterialTerms;
use crate::render::geometry::Ray;
use crate::render::spawn::{ShadowRay, SurfaceHit};
use glam::Vec3;
use std::ops::Range;

/// A column of 3-vectors stored as three columns of f32: vector `i` is `(x[i], y[i], z[i])`
/// (red, green, blue for a colour), so a stage loads 8 x, 8 y and 8 z at a time.
#[derive(Clone, Debug, Default)]
pub struct Vec3Column {
    /// First components.
    pub x: Vec<f32>,
    /// Second components.
    pub y: Vec<f32>,
    /// Third components.
    pub z: Vec<f32>,
}

impl Vec3Column {
    /// Vector `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// Sets vector `i`.
    #[inline]
    pub fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }

    /// Adds `v` to vector `i`, component by component.
    #[inline]
    pub fn add(&mut self, i: usize, v: Vec3) {
        self.x[i] += v.x;
        self.y[i] += v.y;
        self.z[i] += v.z;
    }

    /// Appends a vector.
    #[inline(always)]
    pub fn push(&mut self, v: Vec3) {
        self.x.push(v.x);
        self.y.push(v.y);
        self.z.push(v.z);
    }

    /// Drops every vector, keeping the capacity.
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
    }

    /// `n` vectors of zeros (the radiance of a new tile).
    pub fn reset(&mut self, n: usize) {
        self.clear();
        self.resize(n, 0.0);
    }

    /// Resizes the three columns to `n`, new entries `value`.
    pub fn resize(&mut self, n: usize, value: f32) {
        self.x.resize(n, value);
        self.y.resize(n, value);
        self.z.resize(n, value);
    }

    /// Sets every vector in `range` to `v`.
    #[inline]
    pub fn fill(&mut self, range: Range<usize>, v: Vec3) {
        self.x[range.clone()].fill(v.x);
        self.y[range.clone()].fill(v.y);
        self.z[range].fill(v.z);
    }

    /// The three columns over `range` (each cut to it, so that indexing below its length needs
    /// no bounds checks).
    #[inline]
    pub fn slices(&self, range: Range<usize>) -> [&[f32]; 3] {
        [
            &self.x[range.clone()],
            &self.y[range.clone()],
            &self.z[range],
        ]
    }

    /// [`Self::slices`], writable.
    #[inline]
    pub fn slices_mut(&mut self, range: Range<usize>) -> [&mut [f32]; 3] {
        [
            &mut self.x[range.clone()],
            &mut self.y[range.clone()],
            &mut self.z[range],
        ]
    }
}

/// Paths in flight at one depth: their current ray and what they carry.
#[derive(Clone, Debug, Default)]
pub struct RayBatch {
    /// Ray origin.
    pub origin: Vec3Column,
    /// Unit direction.
    pub direction: Vec3Column,
    /// End of the ray interval (T_MIN, tmax): infinity for camera and mirror rays.
    pub tmax: Vec<f32>,
    /// Product of the mirror colours kr along the path (red, green, blue).
    pub throughput: Vec3Column,
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
        self.origin.clear();
        self.direction.clear();
        self.tmax.clear();
        self.throughput.clear();
        self.pixel.clear();
        self.sample.clear();
        self.slot.clear();
        self.bounce = bounce;
    }

    /// Appends one ray.
    #[inline(always)]
    pub fn push(&mut self, origin: Vec3, direction: Vec3, throughput: Vec3, path: PathId) {
        self.origin.push(origin);
        self.direction.push(direction);
        self.tmax.push(f32::INFINITY);
        self.throughput.push(throughput);
        self.pixel.push(path.pixel);
        self.sample.push(path.sample);
        self.slot.push(path.slot);
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
    /// Hit point (origin + t·direction, put back on the surface: `spawn::surface_hit`).
    pub point: Vec3Column,
    /// Unit shading normal (flipped towards the ray for two-sided faces).
    pub normal: Vec3Column,
    /// How far off the surface secondary rays start (`spawn::SurfaceHit::offset`).
    pub offset: Vec<f32>,
    /// Index into `terms` of the hit's shading terms (0 for a miss, unused): its material's
    /// index, or on a textured material the entry made for this hit.
    pub material: Vec<u32>,
    /// The shading terms `material` indexes: the context's materials (`Context::materials`), then
    /// one entry per hit on a textured material, with kd the texel there (`texels::fill`). Every
    /// stage reads a hit's material through this table, so untextured scenes pay nothing per
    /// hit for textures.
    pub terms: Vec<MaterialTerms>,
    /// Σ lights Σ points Shade/N of the visible light points (red, green, blue).
    pub direct: Vec3Column,
}

impl HitBatch {
    /// Resizes every column to `n` entries (contents are overwritten by the intersect stage).
    pub fn resize(&mut self, n: usize) {
        self.t.resize(n, f32::INFINITY);
        self.prim.resize(n, 0);
        self.point.resize(n, 0.0);
        self.normal.resize(n, 0.0);
        self.offset.resize(n, 0.0);
        self.material.resize(n, 0);
        self.direct.resize(n, 0.0);
    }

    /// Hit `i` as the spawn functions take it.
    #[inline]
    pub fn surface(&self, i: usize) -> SurfaceHit {
        SurfaceHit {
            point: self.point.get(i),
            normal: self.normal.get(i),
            offset: self.offset[i],
        }
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
    /// Origin (the hit point, offset off its surface).
    pub origin: Vec3Column,
    /// Unit direction to the light point (the Shade formula's l, from the hit point itself).
    pub direction: Vec3Column,
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
    /// Empties the queue and makes room for `capacity` entries, with the `dist` column only
    /// when `with_dist` (a light model with fall-off).
    pub fn reset(&mut self, capacity: usize, with_dist: bool) {
        self.len = 0;
        self.dist.resize(if with_dist { capacity } else { 0 }, 0.0);
        if self.tmax.len() != capacity {
            self.origin.resize(capacity, 0.0);
            self.direction.resize(capacity, 0.0);
            self.tmax.resize(capacity, 0.0);
            self.n_dot_l.resize(capacity, 0.0);
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
        self.origin.set(i, ray.ray.origin);
        self.direction.set(i, ray.ray.direction);
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
        self.origin.fill(r.clone(), block.origin);
        for (column, l) in self
            .direction
            .slices_mut(r.clone())
            .into_iter()
            .zip(&block.l)
        {
            column.copy_from_slice(l.as_ref());
        }
        self.tmax[r.clone()].copy_from_slice(block.tmax.as_ref());
        self.n_dot_l[r.clone()].copy_from_slice(block.n_dot_l.as_ref());
        if !self.dist.is_empty() {
            self.dist[r.clone()].copy_from_slice(block.dist.as_ref());
        }
        self.path[r.clone()].fill(path);
        self.light[r].fill(light);
        self.len += width;
    }
}

/// 8 (or 16: `A` is the lanes' array) shadow rays towards one light, as the SIMD spawns make
/// them: from one hit to N light points (`simd::shadow_rays`: `O` is their common origin, and
/// a dead lane has tmax = 0, n·l = 0), or from N hits to one point ([`HitRays`]). Lane k is
/// `spawn::shadow_ray`'s answer for point (or hit) k where `live` is set.
#[derive(Clone, Copy, Debug)]
pub struct ShadowBlock<A = [f32; 8], O = Vec3> {
    /// The rays' origin off the surface: one for all, or x, y, z per lane.
    pub origin: O,
    /// l x, y, z per lane: each ray's unit direction.
    pub l: [A; 3],
    /// Where each ray meets the light's moved plane; 0 for a dead lane of one hit's block.
    pub tmax: A,
    /// n·l per lane; 0 for a dead lane of one hit's block.
    pub n_dot_l: A,
    /// |target − point| per lane, for the light model's fall-off.
    pub dist: A,
    /// The lanes with a ray, as a bit mask.
    pub live: u32,
}

/// One shadow ray from each of N hits towards one light point (`simd::hit_shadow_rays`): each
/// ray's origin is its hit's leaving point, and a lane without a ray (`live` clear) holds
/// entries that mean nothing.
pub type HitRays<A> = ShadowBlock<A, [A; 3]>;

impl<A: AsRef<[f32]>> HitRays<A> {
    /// Lane `k` as the scalar spawn gives it (meaningful for a live lane).
    #[inline]
    pub fn lane(&self, k: usize) -> ShadowRay {
        let at = |c: &A| c.as_ref()[k];
        let v = |c: &[A; 3]| Vec3::new(at(&c[0]), at(&c[1]), at(&c[2]));
        ShadowRay {
            ray: Ray {
                origin: v(&self.origin),
                direction: v(&self.l),
            },
            tmax: at(&self.tmax),
            dist: at(&self.dist),
            n_dot_l: at(&self.n_dot_l),
        }
    }
}

/// Per camera sample of a tile: the radiance gathered so far (red, green, blue per slot).
pub type Radiance = Vec3Column;
