//! The scene's geometry as plain serde types, for drawing it beside a ray tree (the OBJ and
//! PLY exports, the browser viewer): triangles with their corners, spheres, lights, materials
//! and the camera.

use super::tree::CameraInfo;
use crate::render::scene::Scene;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Everything needed to draw a scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SceneGeometry {
    /// Where the scene came from.
    pub source: String,
    /// Materials in declaration order.
    pub materials: Vec<MaterialView>,
    /// Every triangle, in primitive-id order (primitive id = index).
    pub triangles: Vec<TriangleView>,
    /// Every sphere (primitive id = triangles + index).
    pub spheres: Vec<SphereView>,
    /// Emissive faces, in light-index order.
    pub lights: Vec<LightView>,
    /// The render camera.
    pub camera: CameraInfo,
    /// The axis-aligned box around every vertex and sphere: [min, max].
    pub bounds: [[f32; 3]; 2],
}

/// A material's colours.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct MaterialView {
    /// Diffuse colour kd.
    pub diffuse: [f32; 3],
    /// Mirror colour kr.
    pub reflective: [f32; 3],
    /// Emitted colour ke.
    pub emitted: [f32; 3],
    /// The lab's glossiness.
    pub glossiness: f32,
}

/// One triangle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TriangleView {
    /// Corners, counter-clockwise seen from the front.
    pub vertices: [[f32; 3]; 3],
    /// Unit front normal.
    pub normal: [f32; 3],
    /// Material index.
    pub material: u32,
    /// The file's face (0-based) it came from.
    pub face: u32,
    /// The light index when its face is an area light.
    pub light: Option<u32>,
}

/// One sphere.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SphereView {
    /// Centre.
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
    /// Material index.
    pub material: u32,
}

/// One area light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct LightView {
    /// The file's face (0-based).
    pub face: u32,
    /// Its corners (a parallelogram's four: a, b, d, b + d − a; or the fan triangles' corners).
    pub corners: Vec<[f32; 3]>,
    /// Area centroid (the hard-shadow point).
    pub centroid: [f32; 3],
    /// Unit normal of its emitting side.
    pub normal: [f32; 3],
    /// Area.
    pub area: f32,
    /// The lab's light colour Lc = 0.2 · ke · area.
    pub color: [f32; 3],
}

impl CameraInfo {
    /// The scene camera as plain values.
    pub fn of(camera: &crate::render::scene::Camera) -> CameraInfo {
        CameraInfo {
            position: camera.position.to_array(),
            look_at: camera.point_of_interest.to_array(),
            up: camera.up.to_array(),
            fov_degrees: camera.fov.to_degrees(),
        }
    }
}

/// The axis-aligned bounds of every triangle corner and sphere: (min, max); the origin for an
/// empty scene.
pub fn scene_bounds(scene: &Scene) -> (glam::Vec3, glam::Vec3) {
    let mut lo = glam::Vec3::splat(f32::INFINITY);
    let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
    for t in &scene.triangles {
        for c in [t.v0, t.v0 + t.e1, t.v0 + t.e2] {
            lo = lo.min(c);
            hi = hi.max(c);
        }
    }
    for s in &scene.spheres {
        lo = lo.min(s.center - s.radius);
        hi = hi.max(s.center + s.radius);
    }
    if lo.cmple(hi).all() {
        (lo, hi)
    } else {
        (glam::Vec3::ZERO, glam::Vec3::ZERO)
    }
}

/// The scene's geometry for display.
pub fn scene_geometry(scene: &Scene) -> SceneGeometry {
    let light_of_face = |face: u32| {
        scene
            .lights
            .iter()
            .position(|l| l.face == face)
            .map(|i| i as u32)
    };
    let (lo, hi) = scene_bounds(scene);
    SceneGeometry {
        source: scene.source.clone(),
        materials: scene
            .materials
            .iter()
            .map(|m| MaterialView {
                diffuse: m.diffuse.to_array(),
                reflective: m.reflective.to_array(),
                emitted: m.emitted.to_array(),
                glossiness: m.glossiness,
            })
            .collect(),
        triangles: scene
            .triangles
            .iter()
            .map(|t| TriangleView {
                vertices: [
                    t.v0.to_array(),
                    (t.v0 + t.e1).to_array(),
                    (t.v0 + t.e2).to_array(),
                ],
                normal: t.normal.to_array(),
                material: t.material,
                face: t.face,
                light: light_of_face(t.face),
            })
            .collect(),
        spheres: scene
            .spheres
            .iter()
            .map(|s| SphereView {
                center: s.center.to_array(),
                radius: s.radius,
                material: s.material,
            })
            .collect(),
        lights: scene
            .lights
            .iter()
            .map(|l| LightView {
                face: l.face,
                corners: l.corners().iter().map(|c| c.to_array()).collect(),
                centroid: l.centroid.to_array(),
                normal: l.normal.to_array(),
                area: l.area,
                color: l.color.to_array(),
            })
            .collect(),
        camera: CameraInfo::of(&scene.camera),
        bounds: [lo.to_array(), hi.to_array()],
    }
}
