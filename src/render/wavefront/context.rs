//! What every stage reads: the scene, the settings, and per-render tables derived from them
//! once (material and light terms, the strata grid, the acceleration choice).

use super::bvh::MeshBvh;
use super::lanes::LaneWidth;
use super::shade::MaterialTerms;
use super::shadow::ShadowPath;
use super::simd::BlockSampler;
use crate::render::camera::CameraRays;
use crate::render::geometry::shadow_casters;
use crate::render::sampling::{
    LightSampler, PointSet, SOBOL_SEED_DIM, SampleKey, hash, strata_grid,
};
use crate::render::scene::{LightShape, Scene, Triangle};
use crate::render::settings::{RenderSettings, ShadowMode};
use crate::render::spawn::{
    SurfaceHit, light_offset, sphere_hit, triangle_hit, triangle_offset, triangle_plane,
};
use glam::Vec3;

/// At or above this many triangles, rays go through the engine's 8-wide BVH (`bvh::MeshBvh`);
/// below it, the 8-wide kernels test every primitive. It equals the reference's `BVH_MIN_TRIANGLES`, so both
/// engines find hits the same way; see docs/TRIED.md for the measurements behind it.
pub const BVH_MIN_TRIANGLES: usize = crate::render::geometry::BVH_MIN_TRIANGLES;

/// A light's terms, with the parallelogram (all the lab's lights) kept apart for the SIMD path.
#[derive(Clone, Debug)]
pub struct LightTerms {
    /// Lc = 0.2 · ke · area.
    pub color: Vec3,
    /// Centroid (hard shadows).
    pub centroid: Vec3,
    /// (corner, edge_u, edge_v) when the light is a parallelogram.
    pub parallelogram: Option<(Vec3, Vec3, Vec3)>,
    /// `spawn::light_offset`: how far off the light shadow rays end.
    pub end_offset: f32,
}

/// What the intersect stage reads of a hit triangle: its normal, plane, offset and material,
/// 24 bytes where `Triangle` is 56, so a hit's lookup touches one cache line of a denser array.
#[derive(Clone, Copy, Debug)]
pub struct TriangleShading {
    /// `Triangle::normal`.
    pub normal: Vec3,
    /// `spawn::triangle_plane`: the hit point is put back on this plane.
    pub plane: f32,
    /// `spawn::triangle_offset`.
    pub offset: f32,
    /// `Triangle::material`.
    pub material: u32,
}

/// The width `LaneWidth::Auto` runs a render at: the build's native width, but 8 lanes where a
/// 16-lane block would be mostly dead lanes: hard shadows (one point per light: equal speed,
/// half the queue slots reserved per hit) and soft shadows of 8 points or fewer (the lab
/// benchmark's frame at 16 lanes: 0.72–0.79× of 8 at 4 points, 0.83–0.88× at 8;
/// docs/PERFORMANCE.md).
fn auto_width(settings: &RenderSettings, points_per_light: u32) -> LaneWidth {
    match settings.shadows {
        ShadowMode::Hard => LaneWidth::Eight,
        ShadowMode::Soft if points_per_light <= 8 => LaneWidth::Eight,
        _ => LaneWidth::NATIVE,
    }
}

/// Scene, settings and derived tables for one render.
pub struct Context<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The settings.
    pub settings: &'a RenderSettings,
    /// Camera set up for the image size.
    pub camera: CameraRays,
    /// The 8-wide mesh BVH when the scene has at least `BVH_MIN_TRIANGLES` triangles.
    pub accel: Option<MeshBvh>,
    /// Without a BVH, the triangles that can block a shadow ray when faces are one-sided
    /// (`geometry::shadow_casters`, the reference's list).
    pub shadow_casters: Vec<Triangle>,
    /// Normal and material of every triangle, in `Scene::triangles` order.
    pub triangle_shading: Vec<TriangleShading>,
    /// One entry per material.
    pub materials: Vec<MaterialTerms>,
    /// The ambient light (`RenderSettings::ambient`).
    pub ambient: Vec3,
    /// Some material has a texture: the texel stage runs (`texels::fill`).
    pub textured: bool,
    /// One entry per light.
    pub lights: Vec<LightTerms>,
    /// Points per light (N).
    pub points_per_light: u32,
    /// The lane width of the brute-force, light and shading kernels, resolved (`Eight` or
    /// `Sixteen`): [`auto_width`]'s choice unless [`Context::with_lane_width`] says otherwise.
    pub lane_width: LaneWidth,
    /// How the shadow stage runs: [`ShadowPath::choose`]'s choice unless
    /// [`Context::with_shadow_path`] says otherwise. Speed only.
    pub shadow_path: ShadowPath,
    /// Where soft shadows' points fall on a light (the reference's, for the scalar paths and
    /// the samplers without a lane formula of their own).
    pub points: PointSet,
    /// Stratum column of every point index (padded to a multiple of 16), as floats.
    pub cell_x: Vec<f32>,
    /// Stratum row of every point index.
    pub cell_y: Vec<f32>,
    /// The strata grid (nx, ny) as floats.
    pub grid: (f32, f32),
}

impl<'a> Context<'a> {
    /// Derives the tables and builds the BVH if the scene needs one.
    pub fn new(scene: &'a Scene, settings: &'a RenderSettings) -> Self {
        let accel = (scene.triangles.len() >= BVH_MIN_TRIANGLES).then(|| MeshBvh::new(scene));
        let ambient = Vec3::from_array(settings.ambient);
        let materials = scene
            .materials
            .iter()
            .map(|m| MaterialTerms::new(m, ambient))
            .collect();
        let lights = scene
            .lights
            .iter()
            .map(|l| LightTerms {
                color: l.color,
                centroid: l.centroid,
                parallelogram: match l.shape {
                    LightShape::Parallelogram {
                        origin,
                        edge_u,
                        edge_v,
                    } => Some((origin, edge_u, edge_v)),
                    LightShape::Fan { .. } => None,
                },
                end_offset: light_offset(l),
            })
            .collect();
        let points_per_light = settings.points_per_light();
        let (nx, ny) = strata_grid(points_per_light);
        // Padded to whole blocks of the widest lanes, so every block's load is one vector.
        let padded = (points_per_light as usize).div_ceil(16) * 16;
        let cell_x = (0..padded as u32).map(|j| (j % nx) as f32).collect();
        let cell_y = (0..padded as u32).map(|j| (j / nx) as f32).collect();
        let mut ctx = Context {
            scene,
            settings,
            camera: CameraRays::new(&scene.camera, settings.width, settings.height),
            shadow_casters: if accel.is_none() {
                shadow_casters(scene)
            } else {
                Vec::new()
            },
            accel,
            triangle_shading: scene
                .triangles
                .iter()
                .map(|t| TriangleShading {
                    normal: t.normal,
                    plane: triangle_plane(t),
                    offset: triangle_offset(t),
                    material: t.material,
                })
                .collect(),
            textured: scene.materials.iter().any(|m| m.texture.is_some()),
            materials,
            ambient,
            lights,
            points_per_light,
            lane_width: auto_width(settings, points_per_light),
            shadow_path: ShadowPath::QueuedPerHit,
            points: settings.point_set(),
            cell_x,
            cell_y,
            grid: (nx as f32, ny as f32),
        };
        ctx.shadow_path = ShadowPath::choose(&ctx);
        ctx
    }

    /// The same context with the kernels run `width` lanes wide (`Auto`: [`auto_width`]).
    /// Speed only: every width gives the same image.
    pub fn with_lane_width(mut self, width: LaneWidth) -> Self {
        self.lane_width = match width {
            LaneWidth::Auto => auto_width(self.settings, self.points_per_light),
            w => w,
        };
        self
    }

    /// The same context with its shadow stage run by `path`, which it must admit
    /// ([`ShadowPath::admits`]): how tests hold every path to `QueuedPerHit`. Speed only: the
    /// image is the same.
    pub fn with_shadow_path(mut self, path: ShadowPath) -> Self {
        assert!(
            path.admits(&self),
            "{path:?} does not give this scene and these settings their shadows"
        );
        self.shadow_path = path;
        self
    }

    /// True when shadow rays are cast (hard or soft shadows).
    pub fn casts_shadow_rays(&self) -> bool {
        self.settings.shadows != ShadowMode::Off
    }

    /// True when light points are sampled (soft shadows) rather than the centroid.
    pub fn samples_lights(&self) -> bool {
        self.settings.shadows == ShadowMode::Soft
    }

    /// True when the N-lane light sampler (`simd::light_points`) takes the chosen sampler: all
    /// of them, except the lab's strategy at N = 1 (the centroid), which goes through the
    /// scalar `PointSet::point`.
    pub fn simd_light_sampling(&self) -> bool {
        self.settings.sampler != LightSampler::Lab || self.points_per_light > 1
    }

    /// The N-lane sampler for the stream of `key` (when `simd_light_sampling()`).
    pub fn block_sampler(&self, key: &SampleKey) -> BlockSampler<'_> {
        match self.settings.sampler {
            LightSampler::Stratified => BlockSampler::Stratified {
                cell_x: &self.cell_x,
                cell_y: &self.cell_y,
                nx: self.grid.0,
                ny: self.grid.1,
            },
            LightSampler::Sobol => BlockSampler::Sobol {
                scramble: hash(key, SOBOL_SEED_DIM),
            },
            LightSampler::Random | LightSampler::Lab => BlockSampler::Random,
            LightSampler::Halton
            | LightSampler::Pmj02
            | LightSampler::Zsobol
            | LightSampler::Bluenoise => BlockSampler::Stream {
                stream: self
                    .points
                    .stream(key)
                    .expect("the table samplers have a stream"),
                count: self.points_per_light,
            },
        }
    }

    /// The hit on primitive `prim` at `p0` (origin + t·direction), put back on its surface,
    /// and its material index: `spawn::surface_hit` from this context's tables.
    #[inline]
    pub fn surface(&self, prim: u32, p0: Vec3) -> (SurfaceHit, u32) {
        let p = prim as usize;
        match self.triangle_shading.get(p) {
            Some(t) => (triangle_hit(p0, t.normal, t.plane, t.offset), t.material),
            None => {
                let s = &self.scene.spheres[p - self.triangle_shading.len()];
                (sphere_hit(p0, s), s.material)
            }
        }
    }
}
