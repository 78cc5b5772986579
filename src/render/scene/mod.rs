//! The scene: materials, triangles (from the lab's quads and from polygons), analytic spheres,
//! area lights and the camera. Every engine reads this one description; the wavefront engine
//! builds its own structure-of-arrays copy of the geometry from it.
//!
//! Primitive ids are global: triangles first (`0..triangles.len()`), then spheres. A miss is
//! `u32::MAX`, never an `Option`, so the same sentinel works in SIMD columns.

pub mod meshgen;
mod parse;
mod read;
pub mod texture;
mod texture_file;

pub use parse::{
    ParseError, ParseOptions, RPI_RING_SEGMENTS, SceneError, Warning, beyond_range, parse_scene_in,
    parse_scene_str,
};
pub use read::{MAX_SCENE_BYTES, STDIN_NAME, read_scene_bytes};
pub use texture::Texture;
pub use texture_file::MAX_TEXTURE_TEXELS;

use glam::Vec3;
use std::path::Path;

/// The sentinel primitive id for "no hit".
pub const NO_HIT: u32 = u32::MAX;

/// The lab's material: diffuse, reflective and emitted colours plus a glossiness that narrows
/// (g = 0) or widens (g = 1) the highlight through the exponent 5 / (g + 0.01); RPI's may take
/// its diffuse colour from a texture.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Material {
    /// Diffuse colour kd (also scales the fixed 0.2 ambient term). With a texture, the texture's
    /// average colour, which stands for it where one colour must (shading reads the texture:
    /// [`Scene::diffuse_at`]).
    pub diffuse: Vec3,
    /// Index into `Scene::textures` of the texture that gives kd point by point (RPI's
    /// `texture_file`), if any.
    pub texture: Option<u32>,
    /// Mirror colour kr; non-zero spawns reflection rays.
    pub reflective: Vec3,
    /// Emitted colour ke; a face with non-zero emission is an area light.
    pub emitted: Vec3,
    /// The lab's glossiness g (an RPI file's `roughness` maps here too).
    pub glossiness: f32,
}

impl Material {
    /// True when the material spawns reflection rays (any channel of kr non-zero).
    pub fn is_reflective(&self) -> bool {
        self.reflective != Vec3::ZERO
    }
    /// The specular exponent 5 / (g + 0.01) of the lab's Shade formula.
    pub fn shininess(&self) -> f32 {
        5.0 / (self.glossiness + 0.01)
    }
}

/// One triangle, stored the way Möller–Trumbore wants it: a corner and two edges.
/// The front is the side from which the corners run counter-clockwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// First corner.
    pub v0: Vec3,
    /// Second corner minus the first.
    pub e1: Vec3,
    /// Third corner minus the first.
    pub e2: Vec3,
    /// Unit geometric normal, normalize(e1 × e2): the front side.
    pub normal: Vec3,
    /// Index into `Scene::materials`.
    pub material: u32,
    /// Which face (polygon) of the file this triangle came from.
    pub face: u32,
}

/// An analytic sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (> 0, checked by the parser).
    pub radius: f32,
    /// Index into `Scene::materials`.
    pub material: u32,
}

/// How points are placed on a light: uniform by area, from a point (u, v) of the unit square.
#[derive(Clone, Debug, PartialEq)]
pub enum LightShape {
    /// p = origin + u·edge_u + v·edge_v: every lab light is one of these. Strata in (u, v) stay
    /// rectangles on the light.
    Parallelogram {
        /// Corner a of the quad.
        origin: Vec3,
        /// b − a.
        edge_u: Vec3,
        /// d − a.
        edge_v: Vec3,
    },
    /// Any other convex polygon: u picks a fan triangle in proportion to its area (and is
    /// rescaled), then (u, v) maps uniformly into that triangle.
    Fan {
        /// The fan's triangles as (corner, edge1, edge2).
        triangles: Vec<(Vec3, Vec3, Vec3)>,
        /// Cumulative area fractions, last = 1.
        cdf: Vec<f32>,
    },
}

/// An emissive face: the lab's area light.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Face index in the file's order of faces.
    pub face: u32,
    /// Shape used to place sample points.
    pub shape: LightShape,
    /// Area centroid: the single point used for hard shadows.
    pub centroid: Vec3,
    /// Area of the face.
    pub area: f32,
    /// Unit normal of the face (its emitting side).
    pub normal: Vec3,
    /// The lab's light colour Lc = 0.2 · ke · area.
    pub color: Vec3,
}

impl Light {
    /// The light's corners: a parallelogram's four, or every corner of its fan triangles.
    pub fn corners(&self) -> Vec<Vec3> {
        match &self.shape {
            LightShape::Parallelogram {
                origin,
                edge_u,
                edge_v,
            } => vec![
                *origin,
                *origin + *edge_u,
                *origin + *edge_v,
                *origin + *edge_u + *edge_v,
            ],
            LightShape::Fan { triangles, .. } => triangles
                .iter()
                .flat_map(|&(a, e1, e2)| [a, a + e1, a + e2])
                .collect(),
        }
    }

    /// Maps (u, v) in [0, 1)² to a point on the light, uniformly by area.
    #[inline]
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        match &self.shape {
            LightShape::Parallelogram {
                origin,
                edge_u,
                edge_v,
            } => *origin + u * *edge_u + v * *edge_v,
            LightShape::Fan { triangles, cdf } => {
                let k = cdf.iter().position(|&c| u < c).unwrap_or(cdf.len() - 1);
                let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
                let u = ((u - lo) / (cdf[k] - lo)).clamp(0.0, 1.0);
                let (a, e1, e2) = triangles[k];
                // Shirley's square-to-triangle map: continuous, so strata stay compact.
                let s = u.sqrt();
                a + (s * (1.0 - v)) * e1 + (s * v) * e2
            }
        }
    }
}

/// The camera: a pinhole looking at `point_of_interest` with a square field of view of
/// `fov_y` radians (full angle), cropped by non-square images.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// The point the camera looks at.
    pub point_of_interest: Vec3,
    /// Up hint.
    pub up: Vec3,
    /// Full field-of-view angle in radians.
    pub fov: f32,
}

impl Default for Camera {
    /// The lab's camera for a unit box at the origin.
    fn default() -> Self {
        Camera {
            position: Vec3::new(0.0, 0.0, 8.0),
            point_of_interest: Vec3::ZERO,
            up: Vec3::Y,
            fov: 20f32.to_radians(),
        }
    }
}

/// A parsed scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Where it came from (a path, or `<built-in>`), for messages.
    pub source: String,
    /// Materials in declaration order.
    pub materials: Vec<Material>,
    /// Textures (RPI's `texture_file`), read when the scene was parsed.
    pub textures: Vec<Texture>,
    /// All triangles (quads and polygons fan-triangulated; a quad a b c d splits along a–c).
    pub triangles: Vec<Triangle>,
    /// The texture coordinates (s, t) of each triangle's corners v0, v0 + e1, v0 + e2, in
    /// `triangles` order: empty when no face has any (`vt`), and (0, 0) for a corner without.
    pub texcoords: Vec<[[f32; 2]; 3]>,
    /// Analytic spheres.
    pub spheres: Vec<Sphere>,
    /// Emissive faces.
    pub lights: Vec<Light>,
    /// Number of faces in the file (polygons, before triangulation).
    pub face_count: usize,
    /// Number of faces that were quads.
    pub quad_count: usize,
    /// Number of RPI cylinder rings (`r` lines), each cut into quads counted in `face_count`.
    pub ring_count: usize,
    /// The camera from the file, or the lab's automatic one.
    pub camera: Camera,
    /// True when the file had a camera block.
    pub camera_from_file: bool,
    /// `background_color` from the file, if any.
    pub background: Option<Vec3>,
    /// Non-fatal findings (unknown keywords, textured faces without coordinates), each naming
    /// file:line.
    pub warnings: Vec<Warning>,
}

impl Scene {
    /// Reads and parses a scene file with the default [`ParseOptions`]; errors name the file
    /// and line.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Ok(load_scene(Some(path), &ParseOptions::default())?.scene)
    }

    /// The built-in default: the lab's Cornell box with three mirror spheres.
    pub fn builtin_default() -> Scene {
        parse_scene_str(
            BUILTIN_CORNELL_BOX,
            "<built-in cornell_box_reflective_spheres>",
        )
        .expect("the built-in scene parses")
    }

    /// Total primitive count (triangles + spheres).
    pub fn primitive_count(&self) -> usize {
        self.triangles.len() + self.spheres.len()
    }

    /// The material of a primitive id.
    pub fn material_of(&self, prim: u32) -> &Material {
        let p = prim as usize;
        let m = if p < self.triangles.len() {
            self.triangles[p].material
        } else {
            self.spheres[p - self.triangles.len()].material
        };
        &self.materials[m as usize]
    }
}

/// A scene and the bytes it was made from (what caches and bench records key on).
#[derive(Clone, Debug)]
pub struct SceneFile {
    /// The parsed scene, its warnings included.
    pub scene: Scene,
    /// The file's bytes, or [`BUILTIN_CORNELL_BOX`]'s, followed by each texture's name and
    /// digest (`Texture::digest`), so that a changed texture changes every key made from them.
    pub bytes: Vec<u8>,
}

/// Reads the scene file once (the built-in scene without a path; `-` is standard input) and
/// parses it; errors name the file and line. Directories, devices and sockets are refused, and
/// no more than [`MAX_SCENE_BYTES`] is read (see [`read_scene_bytes`]). The scene's warnings
/// are kept in `Scene::warnings` for the caller to print.
pub fn load_scene(path: Option<&Path>, options: &ParseOptions) -> Result<SceneFile, SceneError> {
    let Some(path) = path else {
        return Ok(SceneFile {
            scene: Scene::builtin_default(),
            bytes: BUILTIN_CORNELL_BOX.as_bytes().to_vec(),
        });
    };
    let (mut bytes, file) = read_scene_bytes(path)?;
    // Texture names are relative to the scene file's folder (the current one for stdin).
    let base = (path.as_os_str() != "-").then(|| path.parent()).flatten();
    let text = std::str::from_utf8(&bytes).map_err(|e| ParseError {
        line: 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
        message: "expected UTF-8 text, found a byte that is not UTF-8".into(),
        file: file.clone(),
    })?;
    let scene = parse_scene_in(text, &file, options, base)?;
    for texture in &scene.textures {
        bytes.extend_from_slice(b"\0texture\0");
        bytes.extend_from_slice(texture.name.as_bytes());
        bytes.push(0);
        bytes.extend_from_slice(&texture.digest.to_le_bytes());
    }
    Ok(SceneFile { scene, bytes })
}

/// The lab's `cornell_box_reflective_spheres.obj`, compiled in, with the background of the lab's
/// run line for it (`-background_color 0.2 0.1 0.6`), so that `raywave` with no arguments
/// renders what the lab's third run line rendered.
pub const BUILTIN_CORNELL_BOX: &str = concat!(
    include_str!("../../../scenes/cornell_box_reflective_spheres.obj"),
    "\n# The lab's run line for this scene passes -background_color 0.2 0.1 0.6\nbackground_color 0.2 0.1 0.6\n"
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn load_scene_returns_the_bytes_it_parsed() {
        let builtin = load_scene(None, &ParseOptions::default()).unwrap();
        assert_eq!(builtin.bytes, BUILTIN_CORNELL_BOX.as_bytes());
        assert_eq!(builtin.scene.triangles, Scene::builtin_default().triangles);

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("box.obj");
        std::fs::write(&path, BUILTIN_CORNELL_BOX).unwrap();
        let file = load_scene(Some(&path), &ParseOptions::default()).unwrap();
        assert_eq!(file.bytes, BUILTIN_CORNELL_BOX.as_bytes());
        assert_eq!(file.scene.triangles, builtin.scene.triangles);
        assert_eq!(file.scene.source, path.display().to_string());
    }

    #[test]
    fn load_scene_names_the_file_it_cannot_read_or_decode() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.obj");
        let e = load_scene(Some(&missing), &ParseOptions::default()).unwrap_err();
        assert!(e.to_string().contains("missing.obj"), "{e}");

        let binary = dir.path().join("binary.obj");
        std::fs::write(&binary, b"v 0 0 0\n\xff\n").unwrap();
        let e = load_scene(Some(&binary), &ParseOptions::default()).unwrap_err();
        assert!(e.to_string().contains("binary.obj"), "{e}");
        assert!(e.to_string().contains("UTF-8"), "{e}");
    }
}
