//! RPI's additions to the lab's format: cylinder rings (`r` lines), cut into quads as RPI's
//! framework does, and the `PerspectiveCamera { ... }` block, the one construct that spans lines.

use super::{CameraBlock, ParseError, Parser};
use crate::render::quote::quote;
use crate::render::scene::Camera;
use glam::Vec3;
use std::f32::consts::PI;

impl Parser<'_> {
    /// An RPI cylinder ring, `r cx cy cz height inner_radius outer_radius`: a tube about the
    /// vertical axis through the centre, cut into quads the way RPI's
    /// `CylinderRing::addRasterizedFaces` does. Around the axis there are `ring_segments`
    /// steps; each step gives four quads (outer wall, top, inner wall, bottom), all facing out
    /// of the solid. An inner radius of 0 makes a solid cylinder: no inner wall, and the top
    /// and bottom steps are triangles.
    pub(super) fn ring(&mut self, line: usize, args: &[&str]) -> Result<(), ParseError> {
        if args.len() != 6 {
            return Err(self.error(
                line,
                format!(
                    "expected `r cx cy cz height inner_radius outer_radius` (6 numbers), found {} value(s)",
                    args.len()
                ),
            ));
        }
        let center = self.vec3(line, "r", &args[..3])?;
        let height = self.number(line, "the height of `r`", Some(args[3]))?;
        let inner = self.number(line, "the inner radius of `r`", Some(args[4]))?;
        let outer = self.number(line, "the outer radius of `r`", Some(args[5]))?;
        if height <= 0.0 {
            return Err(self.error(
                line,
                format!("expected a positive ring height, found {height}"),
            ));
        }
        if inner < 0.0 || outer <= inner {
            return Err(self.error(
                line,
                format!(
                    "expected ring radii with 0 <= inner < outer, found inner {inner} and outer {outer}"
                ),
            ));
        }
        let material = self.active_material(line, "ring")?;
        let n = self.options.ring_segments.max(3);
        // Per step i, four corners in RPI's order: outer bottom, outer top, inner top, inner
        // bottom. x = r·cos θ, z = −r·sin θ, as in RPI's ComputeCylinderRingPoint.
        let corner = |i: u32, k: usize| -> Vec3 {
            let theta = std::f64::consts::TAU * f64::from(i % n) / f64::from(n);
            let (radius, dy) = match k {
                0 => (outer, -0.5 * height),
                1 => (outer, 0.5 * height),
                2 => (inner, 0.5 * height),
                _ => (inner, -0.5 * height),
            };
            let r = f64::from(radius);
            center + Vec3::new((r * theta.cos()) as f32, dy, (-r * theta.sin()) as f32)
        };
        for i in 0..n {
            for k in 0..4 {
                if inner == 0.0 && k == 2 {
                    continue; // the inner wall of a solid cylinder has no area
                }
                let mut corners = vec![
                    corner(i, k),
                    corner(i + 1, k),
                    corner(i + 1, (k + 1) % 4),
                    corner(i, (k + 1) % 4),
                ];
                // With inner radius 0 the top and bottom quads meet the axis in one point.
                corners.dedup();
                if corners.len() > 2 && corners.first() == corners.last() {
                    corners.pop();
                }
                self.ring_points.extend_from_slice(&corners);
                self.push_face(line, corners, Vec::new(), material)?;
            }
        }
        self.rings += 1;
        Ok(())
    }

    /// Gathers camera-block tokens (`<`, `>` and `,` are separators there) until `}`.
    pub(super) fn camera_line(&mut self, text: &str, line: usize) -> Result<(), ParseError> {
        let cleaned: String = text
            .chars()
            .map(|c| if matches!(c, '<' | '>' | ',') { ' ' } else { c })
            .collect();
        let mut closed = false;
        for token in cleaned.split_whitespace() {
            if closed {
                return Err(self.error(
                    line,
                    format!(
                        "expected the end of the line after `}}`, found `{}`",
                        quote(token)
                    ),
                ));
            }
            let block = self.camera_block.as_mut().expect("in a camera block");
            match token {
                "{" if block.tokens.is_empty() => {}
                "}" => closed = true,
                _ => block.tokens.push((token.to_string(), line)),
            }
        }
        if closed {
            let block = self.camera_block.take().expect("in a camera block");
            self.camera = Some(self.camera_from(block)?);
        }
        Ok(())
    }

    fn camera_from(&self, block: CameraBlock) -> Result<Camera, ParseError> {
        let mut position = None;
        let mut poi = None;
        let mut direction = None;
        let mut up = Vec3::Y;
        let mut angle = None;
        let mut tokens = block.tokens.iter();
        while let Some((key, line)) = tokens.next() {
            let line = *line;
            // The next `n` tokens; fewer at the end of the block, which `vec3` and `number` report.
            let mut take =
                |n: usize| -> Vec<&str> { tokens.by_ref().take(n).map(|t| t.0.as_str()).collect() };
            match key.as_str() {
                "camera_position" | "center" | "point_of_interest" | "direction" | "up" => {
                    let v = self.vec3(line, key, &take(3))?;
                    match key.as_str() {
                        "camera_position" | "center" => position = Some(v),
                        "point_of_interest" => poi = Some(v),
                        "direction" => direction = Some(v),
                        _ => up = v,
                    }
                }
                "angle" => {
                    let a = self.number(line, "the camera `angle`", take(1).first().copied())?;
                    // The older RPI dialect gives radians, the newer degrees. No field of view
                    // reaches π radians, and none in these scenes is as narrow as π degrees, so
                    // a value above π is degrees.
                    let radians = if a > PI { a.to_radians() } else { a };
                    if radians <= 0.0 || radians >= PI {
                        return Err(self.error(line, format!("expected a field-of-view angle between 0 and 180 degrees, found {a}")));
                    }
                    angle = Some(radians);
                }
                other => {
                    return Err(self.error(
                        line,
                        format!("expected camera_position, point_of_interest, up or angle in the camera block, found `{}`", quote(other)),
                    ));
                }
            }
        }
        let start = block.start_line;
        let missing = |key: &str| {
            self.error(
                start,
                format!("expected `{key}` in the camera block, found none"),
            )
        };
        let position = position.ok_or_else(|| missing("camera_position"))?;
        let point_of_interest = match (poi, direction) {
            (Some(p), _) => p,
            (None, Some(d)) => position + d,
            (None, None) => return Err(missing("point_of_interest")),
        };
        let fov = angle.ok_or_else(|| missing("angle"))?;
        let forward = point_of_interest - position;
        if forward.length_squared() == 0.0 || forward.cross(up).length_squared() == 0.0 {
            return Err(self.error(
                start,
                "expected a camera whose point_of_interest differs from its position and whose up is not parallel to the view direction",
            ));
        }
        Ok(Camera {
            position,
            point_of_interest,
            up,
            fov,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::scene::Scene;
    use crate::render::scene::parse::{
        ParseOptions, RPI_RING_SEGMENTS, parse_scene_in, parse_scene_str,
    };

    const HEAD: &str = "material\ndiffuse 1 1 1\nm 0\n";

    fn ring_scene(ring: &str, segments: u32) -> Result<Scene, ParseError> {
        parse_scene_in(
            &format!("{HEAD}{ring}\n"),
            "ring.obj",
            &ParseOptions {
                ring_segments: segments,
            },
            None,
        )
    }

    #[test]
    fn a_ring_is_four_quads_per_segment_facing_out_of_the_solid() {
        let (center, height, inner, outer) = (Vec3::new(1.0, 2.0, -1.0), 0.5, 0.8, 1.2);
        for segments in [3, 8, RPI_RING_SEGMENTS] {
            let scene = ring_scene("r 1 2 -1 0.5 0.8 1.2", segments).unwrap();
            assert_eq!(scene.ring_count, 1);
            assert_eq!(scene.face_count, 4 * segments as usize);
            assert_eq!(scene.quad_count, scene.face_count);
            assert_eq!(scene.triangles.len(), 2 * scene.face_count);
            for t in &scene.triangles {
                let c = t.v0 + (t.e1 + t.e2) / 3.0 - center;
                let radial = Vec3::new(c.x, 0.0, c.z).normalize();
                let n = t.normal;
                let corners = [t.v0, t.v0 + t.e1, t.v0 + t.e2].map(|v| v - center);
                let widest = corners
                    .iter()
                    .map(|v| Vec3::new(v.x, 0.0, v.z).length())
                    .fold(0.0, f32::max);
                let out = if (c.y.abs() - 0.5 * height).abs() < 1e-5 {
                    Vec3::new(0.0, c.y.signum(), 0.0) // top or bottom
                } else if widest > 0.5 * (inner + outer) {
                    radial // outer wall
                } else {
                    -radial // inner wall: faces the hole
                };
                assert!(n.dot(out) > 0.7, "{n} should face {out} at {c}");
            }
        }
    }

    #[test]
    fn a_solid_ring_has_no_inner_wall() {
        let scene = ring_scene("r 0 0 0 1 0 1", 6).unwrap();
        // Per segment: outer wall (quad), top and bottom (triangles at the axis).
        assert_eq!(scene.face_count, 3 * 6);
        assert_eq!(scene.quad_count, 6);
    }

    #[test]
    fn ring_errors_name_the_line() {
        for (ring, needle) in [
            ("r 0 0 0 1 1", "6 numbers"),
            ("r 0 0 0 0 1 2", "positive ring height"),
            ("r 0 0 0 1 2 1", "inner < outer"),
            ("r 0 0 0 1 -1 1", "inner < outer"),
            ("r 0 0 x 1 0 1", "3rd number of `r`"),
        ] {
            let e = ring_scene(ring, 20).unwrap_err().to_string();
            assert!(
                e.starts_with("ring.obj:4:") && e.contains(needle),
                "{ring}: {e}"
            );
        }
        let e = parse_scene_str("r 0 0 0 1 0 1\n", "ring.obj")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("ring.obj:1:") && e.contains("ring"), "{e}");
    }
}
