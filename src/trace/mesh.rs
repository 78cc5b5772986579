//! The scene and the tree as named groups of vertices, triangles and line segments: what the
//! OBJ and PLY exports write.
//!
//! ```text
//! scene          the triangles that are not lights (3 vertices each, coloured by kd)
//! light_K        light K's triangles (coloured by its emission)
//! sphere_K       sphere K as SPHERE_RINGS × SPHERE_SEGMENTS latitude-longitude triangles
//! rays_camera, rays_reflection, rays_shadow_visible, rays_shadow_blocked,
//! rays_shadow_untested   one line (2 vertices) per segment of that style (palette.rs)
//! main_camera    the render camera's marker (view::camera_marker), 9 lines
//! ```
//!
//! Groups with nothing in them are left out.

use super::draw::MARKER_SIZE;
use super::palette::{MAIN_CAMERA, Rgb, Style};
use super::tree::RayTree;
use super::view::camera_marker;
use crate::render::scene::Scene;
use glam::Vec3;
use std::f32::consts::PI;

/// Latitude bands of a tessellated sphere.
const SPHERE_RINGS: u32 = 12;
/// Longitude steps of a tessellated sphere.
const SPHERE_SEGMENTS: u32 = 24;

/// One named group.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Group {
    /// Object / group name.
    pub name: String,
    /// Vertices, each with its colour.
    pub vertices: Vec<(Vec3, Rgb)>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// Line segments as indices into `vertices`.
    pub lines: Vec<[u32; 2]>,
}

impl Group {
    fn new(name: &str) -> Group {
        Group {
            name: name.to_string(),
            ..Group::default()
        }
    }

    fn vertex(&mut self, p: Vec3, colour: Rgb) -> u32 {
        self.vertices.push((p, colour));
        self.vertices.len() as u32 - 1
    }

    fn line(&mut self, a: Vec3, b: Vec3, colour: Rgb) {
        let i = self.vertex(a, colour);
        let j = self.vertex(b, colour);
        self.lines.push([i, j]);
    }
}

/// A linear colour as 8 bits (clamped).
fn rgb8(c: Vec3) -> Rgb {
    let c = c.clamp(Vec3::ZERO, Vec3::ONE) * 255.0;
    [c.x.round() as u8, c.y.round() as u8, c.z.round() as u8]
}

/// The axis-aligned bounds of every triangle corner and sphere: (min, max); the origin for an
/// empty scene.
pub fn scene_bounds(scene: &Scene) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
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
        (Vec3::ZERO, Vec3::ZERO)
    }
}

/// The groups of a scene and a tree.
pub fn groups(scene: &Scene, tree: &RayTree) -> Vec<Group> {
    // The faces that are not lights, then light k's at k + 1.
    let mut out: Vec<Group> = std::iter::once(Group::new("scene"))
        .chain((0..scene.lights.len()).map(|k| Group::new(&format!("light_{k}"))))
        .collect();
    for t in &scene.triangles {
        let material = &scene.materials[t.material as usize];
        let (group, colour) = match scene.lights.iter().position(|l| l.face == t.face) {
            Some(k) => (&mut out[k + 1], rgb8(material.emitted)),
            None => (&mut out[0], rgb8(material.diffuse)),
        };
        let corners = [t.v0, t.v0 + t.e1, t.v0 + t.e2].map(|p| group.vertex(p, colour));
        group.triangles.push(corners);
    }
    for (k, s) in scene.spheres.iter().enumerate() {
        let material = &scene.materials[s.material as usize];
        let colour = rgb8(material.diffuse.max(material.reflective));
        out.push(sphere(&format!("sphere_{k}"), s.center, s.radius, colour));
    }
    for style in Style::ALL {
        let mut group = Group::new(&format!("rays_{}", style.name()));
        for s in tree.segments.iter().filter(|s| Style::of(s) == style) {
            group.line(
                Vec3::from_array(s.origin),
                Vec3::from_array(s.end),
                style.colour(),
            );
        }
        out.push(group);
    }
    let (lo, hi) = scene_bounds(scene);
    let aspect = tree.settings.width as f32 / tree.settings.height as f32;
    let mut marker = Group::new("main_camera");
    for (a, b) in camera_marker(&scene.camera, aspect, MARKER_SIZE * (hi - lo).length()) {
        marker.line(a, b, MAIN_CAMERA);
    }
    out.push(marker);
    out.retain(|g| !g.vertices.is_empty());
    out
}

/// A latitude-longitude sphere: two poles, `SPHERE_RINGS − 1` rings of `SPHERE_SEGMENTS`
/// vertices, 2·SPHERE_SEGMENTS·(SPHERE_RINGS − 1) triangles facing out.
fn sphere(name: &str, centre: Vec3, radius: f32, colour: Rgb) -> Group {
    let mut g = Group::new(name);
    let top = g.vertex(centre + radius * Vec3::Y, colour);
    for ring in 1..SPHERE_RINGS {
        let theta = PI * ring as f32 / SPHERE_RINGS as f32;
        for seg in 0..SPHERE_SEGMENTS {
            let phi = 2.0 * PI * seg as f32 / SPHERE_SEGMENTS as f32;
            let dir = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            g.vertex(centre + radius * dir, colour);
        }
    }
    let bottom = g.vertex(centre - radius * Vec3::Y, colour);
    let at = |ring: u32, seg: u32| 1 + (ring - 1) * SPHERE_SEGMENTS + seg % SPHERE_SEGMENTS;
    for seg in 0..SPHERE_SEGMENTS {
        g.triangles.push([top, at(1, seg), at(1, seg + 1)]);
        for ring in 1..SPHERE_RINGS - 1 {
            let (a, b) = (at(ring, seg), at(ring, seg + 1));
            let (c, d) = (at(ring + 1, seg), at(ring + 1, seg + 1));
            g.triangles.push([a, c, d]);
            g.triangles.push([a, d, b]);
        }
        g.triangles.push([
            bottom,
            at(SPHERE_RINGS - 1, seg + 1),
            at(SPHERE_RINGS - 1, seg),
        ]);
    }
    g
}
