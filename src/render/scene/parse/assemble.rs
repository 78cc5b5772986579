//! From the statements read to a `Scene`: material indices checked, polygons triangulated,
//! emissive faces made lights, and the lab's automatic camera when the file has none.

use super::{ParseError, Parser, Warning};
use crate::render::scene::{Camera, Light, LightShape, Scene, Sphere, Triangle};
use glam::Vec3;

impl Parser<'_> {
    pub(super) fn finish(self, last_line: usize) -> Result<Scene, ParseError> {
        for &(index, line) in &self.material_refs {
            if index as usize >= self.materials.len() {
                return Err(self.error(
                    line,
                    format!(
                        "expected a material index below {} (materials declared in the file), found {index}",
                        self.materials.len()
                    ),
                ));
            }
        }
        if self.faces.is_empty() && self.spheres.is_empty() {
            return Err(self.error(
                last_line,
                "expected at least one face (`f`), sphere (`s`) or ring (`r`), found none",
            ));
        }
        let mut scene = Scene {
            source: self.file.to_string(),
            materials: self.materials,
            textures: self.textures,
            background: self.background,
            camera_from_file: self.camera.is_some(),
            face_count: self.faces.len(),
            ring_count: self.rings,
            ..Scene::default()
        };
        let mut warnings = self.warnings;
        // One entry per triangle once any face has texture coordinates; none before.
        let textured_faces = self.faces.iter().any(|f| !f.st.is_empty());
        // Textured materials already warned about a primitive (face or sphere) without
        // coordinates: the warning comes once per material.
        let mut warned = vec![false; scene.materials.len()];
        let file = self.file;
        let mut untextured =
            |warnings: &mut Vec<Warning>, material: u32, line: usize, what: &str| {
                let m = material as usize;
                if scene.materials[m].texture.is_some() && !std::mem::replace(&mut warned[m], true)
                {
                    warnings.push(Warning {
                        file: file.to_string(),
                        line,
                        message: format!(
                            "material {m} has a texture but this {what} has no texture \
                             coordinates (`vt` after its vertices): it takes the texel at \
                             (0, 0), as in RPI (reported once per material)"
                        ),
                    });
                }
            };
        for (face_index, face) in self.faces.iter().enumerate() {
            let face_id = face_index as u32;
            if face.corners.len() == 4 {
                scene.quad_count += 1;
            }
            if face.st.is_empty() {
                untextured(&mut warnings, face.material, face.line, "face");
            }
            let st = |k: usize| face.st.get(k).copied().flatten().unwrap_or([0.0, 0.0]);
            let polygon_normal = newell_normal(&face.corners).normalize();
            let a = face.corners[0];
            let mut fan = Vec::new();
            for k in 1..face.corners.len() - 1 {
                let (e1, e2) = (face.corners[k] - a, face.corners[k + 1] - a);
                let n = e1.cross(e2);
                if n.length_squared() == 0.0 {
                    continue; // three collinear corners: the rest of the polygon has the area
                }
                if n.dot(polygon_normal) < 0.0 {
                    warnings.push(Warning {
                        file: self.file.to_string(),
                        line: face.line,
                        message: "non-convex polygon: its fan triangulation overlaps itself".into(),
                    });
                }
                fan.push((a, e1, e2));
                if textured_faces {
                    scene.texcoords.push([st(0), st(k), st(k + 1)]);
                }
                scene.triangles.push(Triangle {
                    v0: a,
                    e1,
                    e2,
                    normal: n.normalize(),
                    material: face.material,
                    face: face_id,
                });
            }
            let emitted = scene.materials[face.material as usize].emitted;
            if emitted != Vec3::ZERO {
                let light = make_light(face_id, &face.corners, fan, polygon_normal, emitted);
                scene.lights.push(light);
            }
        }
        for (sphere, line) in &self.spheres {
            untextured(&mut warnings, sphere.material, *line, "sphere");
        }
        scene.spheres = self.spheres.iter().map(|(s, _)| *s).collect();
        scene.warnings = warnings;
        let mut points = self.vertices;
        points.extend_from_slice(&self.ring_points);
        scene.camera = self
            .camera
            .unwrap_or_else(|| lab_camera(&points, &scene.spheres));
        Ok(scene)
    }
}

/// The polygon's area-weighted normal (twice the area in length), robust for any planar polygon.
pub(super) fn newell_normal(corners: &[Vec3]) -> Vec3 {
    let next = corners.iter().cycle().skip(1);
    corners.iter().zip(next).map(|(a, b)| a.cross(*b)).sum()
}

fn make_light(
    face: u32,
    corners: &[Vec3],
    fan: Vec<(Vec3, Vec3, Vec3)>,
    normal: Vec3,
    emitted: Vec3,
) -> Light {
    let areas: Vec<f32> = fan
        .iter()
        .map(|(_, e1, e2)| 0.5 * e1.cross(*e2).length())
        .collect();
    let area: f32 = areas.iter().sum();
    let centroid = fan
        .iter()
        .zip(&areas)
        .map(|((a, e1, e2), w)| (*a + (*e1 + *e2) / 3.0) * *w)
        .sum::<Vec3>()
        / area;
    let is_parallelogram = corners.len() == 4 && {
        let scale = corners
            .iter()
            .fold(0.0f32, |m, c| m.max(c.abs().max_element()))
            .max(1.0);
        ((corners[0] + corners[2]) - (corners[1] + corners[3]))
            .abs()
            .max_element()
            <= 1e-5 * scale
    };
    let shape = if is_parallelogram {
        LightShape::Parallelogram {
            origin: corners[0],
            edge_u: corners[1] - corners[0],
            edge_v: corners[3] - corners[0],
        }
    } else {
        let mut running = 0.0;
        let mut cdf: Vec<f32> = areas
            .iter()
            .map(|w| {
                running += w / area;
                running
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        LightShape::Fan {
            triangles: fan,
            cdf,
        }
    };
    Light {
        face,
        shape,
        centroid,
        area,
        normal,
        color: 0.2 * emitted * area,
    }
}

/// The lab's camera for files without one: look at the centre of the bounding box of all
/// vertices and spheres from 4 × its largest extent along +z, 20° field of view.
fn lab_camera(vertices: &[Vec3], spheres: &[Sphere]) -> Camera {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for &v in vertices {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    for s in spheres {
        lo = lo.min(s.center - s.radius);
        hi = hi.max(s.center + s.radius);
    }
    let poi = (lo + hi) * 0.5;
    let extent = (hi - lo).max_element();
    Camera {
        position: poi + Vec3::new(0.0, 0.0, 4.0 * extent),
        point_of_interest: poi,
        ..Camera::default()
    }
}
