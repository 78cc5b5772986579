//! The lab's extended `.obj` reader. One logical line at a time (a trailing `\` joins the next
//! line, `#` starts a comment anywhere); the first token picks the line type. The only construct
//! that spans lines is the RPI `PerspectiveCamera { ... }` block, whose tokens are gathered
//! until the closing brace. Every error names `file:line`, what was expected and what was found.
//!
//! Geometry is assembled after the whole file is read, so that `m i` may name a material that is
//! declared further down; the error for a bad index still points at the `m` line.
//!
//! The few choices the command line makes about geometry (how finely an RPI ring is cut into
//! quads) come in as [`ParseOptions`], since the file is read before the render settings exist.

use super::{Camera, Light, LightShape, Material, Scene, Sphere, Triangle};
use crate::quote::quote;
use glam::Vec3;
use std::fmt;

/// A fatal problem in a scene file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}: {message}")]
pub struct ParseError {
    /// The file (or `<built-in ...>`).
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    /// What was expected and what was found.
    pub message: String,
}

/// Loading a scene failed: the file could not be read, or it is malformed.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be opened or read.
    #[error("cannot read scene file {path}")]
    Io {
        /// The path as given.
        path: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The input is not something raywave reads as a scene (a directory, a device, a socket),
    /// or is larger than the limit.
    #[error("{path}: {message}")]
    Input {
        /// The path as given (escaped).
        path: String,
        /// What was expected and what was found.
        message: String,
    },
    /// The file was read but is not a valid scene.
    #[error(transparent)]
    Parse(#[from] ParseError),
}

/// A non-fatal finding: the line was skipped or a fallback was used.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// The file.
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    /// What happened.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: warning: {}", self.file, self.line, self.message)
    }
}

/// What the command line decides about the geometry of a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParseOptions {
    /// Quads around an RPI cylinder ring (`r` line), per side: RPI's
    /// `-cylinder_ring_rasterization`.
    pub ring_segments: u32,
}

/// RPI's ArgParser default for `-cylinder_ring_rasterization`.
pub const RPI_RING_SEGMENTS: u32 = 20;

impl Default for ParseOptions {
    /// RPI's defaults.
    fn default() -> Self {
        ParseOptions {
            ring_segments: RPI_RING_SEGMENTS,
        }
    }
}

/// A polygon as read, before triangulation.
struct Face {
    corners: Vec<Vec3>,
    material: u32,
    line: usize,
}

/// Camera keys gathered from a `PerspectiveCamera { ... }` block.
#[derive(Default)]
struct CameraBlock {
    start_line: usize,
    tokens: Vec<(String, usize)>,
}

struct Parser<'a> {
    file: &'a str,
    options: ParseOptions,
    vertices: Vec<Vec3>,
    materials: Vec<Material>,
    /// The `m i` selection and the line it was made on (checked against the materials at the end).
    active_material: Option<(u32, usize)>,
    material_refs: Vec<(u32, usize)>,
    faces: Vec<Face>,
    spheres: Vec<(Sphere, usize)>,
    /// Corners of ring quads: not numbered vertices (an `f` line cannot name them), but part
    /// of the bounding box the lab's automatic camera frames.
    ring_points: Vec<Vec3>,
    rings: usize,
    camera: Option<Camera>,
    background: Option<Vec3>,
    warnings: Vec<Warning>,
    camera_block: Option<CameraBlock>,
}

/// Parses scene text with the default [`ParseOptions`]; `file` is used in messages only.
pub fn parse_scene_str(text: &str, file: &str) -> Result<Scene, ParseError> {
    parse_scene_str_with(text, file, &ParseOptions::default())
}

/// Parses scene text; `file` is used in messages only.
pub fn parse_scene_str_with(
    text: &str,
    file: &str,
    options: &ParseOptions,
) -> Result<Scene, ParseError> {
    // Editors on Windows start UTF-8 files with a byte-order mark; it is not part of the first
    // keyword (left in, it turned the first `material` into an unknown keyword).
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut p = Parser {
        file,
        options: *options,
        vertices: Vec::new(),
        materials: Vec::new(),
        active_material: None,
        material_refs: Vec::new(),
        faces: Vec::new(),
        spheres: Vec::new(),
        ring_points: Vec::new(),
        rings: 0,
        camera: None,
        background: None,
        warnings: Vec::new(),
        camera_block: None,
    };
    let mut pending = String::new();
    let mut pending_line = 0;
    let mut last_line = 0;
    for (index, raw) in text.lines().enumerate() {
        let number = index + 1;
        last_line = number;
        let content = match raw.find('#') {
            Some(at) => &raw[..at],
            None => raw,
        };
        if pending.is_empty() {
            pending_line = number;
        }
        let trimmed = content.trim_end();
        if let Some(head) = trimmed.strip_suffix('\\') {
            pending.push_str(head);
            pending.push(' ');
            continue;
        }
        pending.push_str(trimmed);
        let line = std::mem::take(&mut pending);
        p.logical_line(&line, pending_line)?;
    }
    if !pending.is_empty() {
        let line = std::mem::take(&mut pending);
        p.logical_line(&line, pending_line)?;
    }
    if let Some(block) = &p.camera_block {
        return Err(p.error(
            block.start_line,
            "expected `}` to close the PerspectiveCamera block, found the end of the file".into(),
        ));
    }
    p.finish(last_line.max(1))
}

/// The largest magnitude of any number in a scene file. Squared lengths, areas and the light
/// colour 0.2·ke·area multiply up to four of them, which stays finite in f32 (1e36 < 3.4e38)
/// below 1e9; larger values overflowed to infinity and came out as "degenerate" faces or
/// infinite lights.
pub const MAX_NUMBER: f32 = 1e9;

fn number(file: &str, line: usize, what: &str, token: Option<&str>) -> Result<f32, ParseError> {
    let error = |message: String| ParseError {
        file: file.to_string(),
        line,
        message,
    };
    let token =
        token.ok_or_else(|| error(format!("expected {what}, found the end of the line")))?;
    let parsed = token.parse::<f32>();
    let token = quote(token);
    match parsed {
        Ok(x) if x.is_finite() && x.abs() <= MAX_NUMBER => Ok(x),
        Ok(x) if x.is_finite() => Err(error(format!(
            "expected {what} of magnitude at most 1e9, found `{token}`"
        ))),
        Ok(_) => Err(error(format!(
            "expected {what} (a finite number), found `{token}`"
        ))),
        Err(_) => Err(error(format!(
            "expected {what} (a number), found `{token}`"
        ))),
    }
}

impl Parser<'_> {
    fn error(&self, line: usize, message: String) -> ParseError {
        ParseError {
            file: self.file.to_string(),
            line,
            message,
        }
    }

    fn warn(&mut self, line: usize, message: String) {
        self.warnings.push(Warning {
            file: self.file.to_string(),
            line,
            message,
        });
    }

    /// Reads exactly three numbers after the keyword and nothing else.
    fn vec3(&self, line: usize, keyword: &str, args: &[&str]) -> Result<Vec3, ParseError> {
        let what = |axis: &str| format!("{axis} of `{keyword}`");
        let x = number(self.file, line, &what("1st number"), args.first().copied())?;
        let y = number(self.file, line, &what("2nd number"), args.get(1).copied())?;
        let z = number(self.file, line, &what("3rd number"), args.get(2).copied())?;
        self.no_more(line, keyword, args, 3)?;
        Ok(Vec3::new(x, y, z))
    }

    fn no_more(
        &self,
        line: usize,
        keyword: &str,
        args: &[&str],
        count: usize,
    ) -> Result<(), ParseError> {
        match args.get(count) {
            None => Ok(()),
            Some(extra) => Err(self.error(
                line,
                format!(
                    "expected {count} value(s) after `{keyword}`, found extra `{}`",
                    quote(extra)
                ),
            )),
        }
    }

    fn colour(&self, line: usize, keyword: &str, args: &[&str]) -> Result<Vec3, ParseError> {
        let c = self.vec3(line, keyword, args)?;
        if c.min_element() < 0.0 {
            return Err(self.error(
                line,
                format!(
                    "expected a non-negative colour after `{keyword}`, found {} {} {}",
                    c.x, c.y, c.z
                ),
            ));
        }
        Ok(c)
    }

    fn current_material(
        &mut self,
        line: usize,
        keyword: &str,
    ) -> Result<&mut Material, ParseError> {
        if self.materials.is_empty() {
            return Err(self.error(
                line,
                format!("expected a `material` line before `{keyword}`, found `{keyword}` outside any material"),
            ));
        }
        Ok(self.materials.last_mut().expect("checked non-empty"))
    }

    fn active_material(&self, line: usize, what: &str) -> Result<u32, ParseError> {
        match self.active_material {
            Some((m, _)) => Ok(m),
            None => Err(self.error(
                line,
                format!("expected `m <material index>` before this {what}, found a {what} before any material was selected"),
            )),
        }
    }

    fn logical_line(&mut self, line_text: &str, line: usize) -> Result<(), ParseError> {
        if self.camera_block.is_some() {
            return self.camera_line(line_text, line);
        }
        let tokens: Vec<&str> = line_text.split_whitespace().collect();
        let Some((&keyword, args)) = tokens.split_first() else {
            return Ok(());
        };
        match keyword {
            "v" => {
                let v = self.vec3(line, "v", args)?;
                self.vertices.push(v);
            }
            "f" => self.face(line, args)?,
            "s" if args.len() <= 1 => {} // OBJ smoothing group (`s off`, `s 1`): no meaning here.
            "s" => {
                if args.len() != 4 {
                    return Err(self.error(
                        line,
                        format!(
                            "expected `s cx cy cz r` (4 numbers), found {} value(s)",
                            args.len()
                        ),
                    ));
                }
                let center = self.vec3(line, "s", &args[..3])?;
                let radius = number(self.file, line, "the radius of `s`", Some(args[3]))?;
                if radius <= 0.0 {
                    return Err(self.error(
                        line,
                        format!("expected a positive sphere radius, found {radius}"),
                    ));
                }
                let material = self.active_material(line, "sphere")?;
                self.spheres.push((
                    Sphere {
                        center,
                        radius,
                        material,
                    },
                    line,
                ));
            }
            "r" => self.ring(line, args)?,
            "m" => {
                let token = args.first().copied().unwrap_or("the end of the line");
                let index: u32 = token.parse().map_err(|_| {
                    self.error(
                        line,
                        format!(
                            "expected a material index (0, 1, 2, ...) after `m`, found `{}`",
                            quote(token)
                        ),
                    )
                })?;
                self.no_more(line, "m", args, 1)?;
                self.active_material = Some((index, line));
                self.material_refs.push((index, line));
            }
            "material" => self.materials.push(Material::default()),
            "diffuse" => {
                let c = self.colour(line, keyword, args)?;
                self.current_material(line, keyword)?.diffuse = c;
            }
            "reflective" => {
                let c = self.colour(line, keyword, args)?;
                self.current_material(line, keyword)?.reflective = c;
            }
            "emitted" => {
                let c = self.colour(line, keyword, args)?;
                self.current_material(line, keyword)?.emitted = c;
            }
            "glossiness" | "roughness" => {
                let g = number(
                    self.file,
                    line,
                    &format!("the value of `{keyword}`"),
                    args.first().copied(),
                )?;
                self.no_more(line, keyword, args, 1)?;
                if g < 0.0 {
                    return Err(self.error(
                        line,
                        format!("expected a non-negative `{keyword}`, found {g}"),
                    ));
                }
                self.current_material(line, keyword)?.glossiness = g;
            }
            "texture_file" => {
                let name = quote(args.first().copied().unwrap_or(""));
                self.current_material(line, keyword)?.diffuse = Vec3::splat(0.5);
                self.warn(line, format!("textures are not supported: `{name}` replaced by a neutral grey diffuse 0.5"));
            }
            "background_color" => {
                self.background = Some(self.colour(line, keyword, args)?);
            }
            "PerspectiveCamera" => {
                if self.camera.is_some() {
                    return Err(self.error(
                        line,
                        "expected one camera block, found a second `PerspectiveCamera`".into(),
                    ));
                }
                self.camera_block = Some(CameraBlock {
                    start_line: line,
                    tokens: Vec::new(),
                });
                let rest = args.join(" ");
                self.camera_line(&rest, line)?;
            }
            "vt" | "vn" | "vp" | "g" | "o" | "usemtl" | "mtllib" => {}
            other => self.warn(
                line,
                format!("unknown keyword `{}`: line skipped", quote(other)),
            ),
        }
        Ok(())
    }

    fn face(&mut self, line: usize, args: &[&str]) -> Result<(), ParseError> {
        if args.len() < 3 {
            return Err(self.error(
                line,
                format!(
                    "expected a face of at least 3 vertex indices, found {}",
                    args.len()
                ),
            ));
        }
        let mut corners = Vec::with_capacity(args.len());
        for token in args {
            let first = token.split('/').next().unwrap_or("");
            let index: i64 = first.parse().map_err(|_| {
                self.error(
                    line,
                    format!(
                        "expected a vertex index (1-based, or negative relative), found `{}`",
                        quote(token)
                    ),
                )
            })?;
            let count = self.vertices.len() as i64;
            let resolved = if index > 0 { index } else { count + index + 1 };
            if index == 0 || resolved < 1 || resolved > count {
                return Err(self.error(
                    line,
                    format!("expected a vertex index between 1 and {count} (or -1 to -{count}), found {index}"),
                ));
            }
            corners.push(self.vertices[(resolved - 1) as usize]);
        }
        let material = self.active_material(line, "face")?;
        self.push_face(line, corners, material)
    }

    /// Adds a polygon, refusing one without area.
    fn push_face(
        &mut self,
        line: usize,
        corners: Vec<Vec3>,
        material: u32,
    ) -> Result<(), ParseError> {
        // Relative to the face's own size, so that a scene scaled by 1e-6 or 1e6 keeps its faces:
        // degenerate means thinner than 1e-10 of its longest edge, or too small for a normal.
        let normal = newell_normal(&corners);
        let area = normal.length() * 0.5;
        let longest_squared = corners
            .iter()
            .zip(corners.iter().cycle().skip(1))
            .fold(0.0f32, |m, (a, b)| m.max((*b - *a).length_squared()));
        if area <= 1e-10 * longest_squared || !normal.normalize().is_finite() {
            return Err(self.error(
                line,
                format!(
                    "expected a face with non-zero area, found a degenerate face (area {area})"
                ),
            ));
        }
        self.faces.push(Face {
            corners,
            material,
            line,
        });
        Ok(())
    }

    /// An RPI cylinder ring, `r cx cy cz height inner_radius outer_radius`: a tube about the
    /// vertical axis through the centre, cut into quads the way RPI's
    /// `CylinderRing::addRasterizedFaces` does. Around the axis there are `ring_segments`
    /// steps; each step gives four quads (outer wall, top, inner wall, bottom), all facing out
    /// of the solid. An inner radius of 0 makes a solid cylinder: no inner wall, and the top
    /// and bottom steps are triangles.
    fn ring(&mut self, line: usize, args: &[&str]) -> Result<(), ParseError> {
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
        let height = number(self.file, line, "the height of `r`", Some(args[3]))?;
        let inner = number(self.file, line, "the inner radius of `r`", Some(args[4]))?;
        let outer = number(self.file, line, "the outer radius of `r`", Some(args[5]))?;
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
                self.push_face(line, corners, material)?;
            }
        }
        self.rings += 1;
        Ok(())
    }

    /// Gathers camera-block tokens (`<`, `>` and `,` are separators there) until `}`.
    fn camera_line(&mut self, text: &str, line: usize) -> Result<(), ParseError> {
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

    fn camera_from(&mut self, block: CameraBlock) -> Result<Camera, ParseError> {
        let mut position = None;
        let mut poi = None;
        let mut direction = None;
        let mut up = Vec3::Y;
        let mut angle = None;
        let mut i = 0;
        let tokens = &block.tokens;
        while i < tokens.len() {
            let (key, line) = (&tokens[i].0, tokens[i].1);
            let take = |n: usize| -> Vec<&str> {
                tokens[i + 1..(i + 1 + n).min(tokens.len())]
                    .iter()
                    .map(|t| t.0.as_str())
                    .collect()
            };
            match key.as_str() {
                "camera_position" | "center" | "point_of_interest" | "direction" | "up" => {
                    let v = self.vec3(line, key, &take(3))?;
                    match key.as_str() {
                        "camera_position" | "center" => position = Some(v),
                        "point_of_interest" => poi = Some(v),
                        "direction" => direction = Some(v),
                        _ => up = v,
                    }
                    i += 4;
                }
                "angle" => {
                    let a = number(
                        self.file,
                        line,
                        "the camera `angle`",
                        take(1).first().copied(),
                    )?;
                    // The older RPI dialect gives radians, the newer degrees. No field of view
                    // reaches π radians, and none in these scenes is as narrow as π degrees, so
                    // a value above π is degrees.
                    let radians = if a > std::f32::consts::PI {
                        a.to_radians()
                    } else {
                        a
                    };
                    if radians <= 0.0 || radians >= std::f32::consts::PI {
                        return Err(self.error(line, format!("expected a field-of-view angle between 0 and 180 degrees, found {a}")));
                    }
                    angle = Some(radians);
                    i += 2;
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
        let position = position.ok_or_else(|| {
            self.error(
                start,
                "expected `camera_position` in the camera block, found none".into(),
            )
        })?;
        let point_of_interest = match (poi, direction) {
            (Some(p), _) => p,
            (None, Some(d)) => position + d,
            (None, None) => {
                return Err(self.error(
                    start,
                    "expected `point_of_interest` in the camera block, found none".into(),
                ));
            }
        };
        let fov = angle.ok_or_else(|| {
            self.error(
                start,
                "expected `angle` in the camera block, found none".into(),
            )
        })?;
        let forward = point_of_interest - position;
        if forward.length_squared() == 0.0 || forward.cross(up).length_squared() == 0.0 {
            return Err(self.error(
                start,
                "expected a camera whose point_of_interest differs from its position and whose up is not parallel to the view direction".into(),
            ));
        }
        Ok(Camera {
            position,
            point_of_interest,
            up,
            fov,
        })
    }

    fn finish(self, last_line: usize) -> Result<Scene, ParseError> {
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
                "expected at least one face (`f`), sphere (`s`) or ring (`r`), found none".into(),
            ));
        }
        let mut scene = Scene {
            source: self.file.to_string(),
            materials: self.materials,
            background: self.background,
            camera_from_file: self.camera.is_some(),
            face_count: self.faces.len(),
            ring_count: self.rings,
            ..Scene::default()
        };
        let mut warnings = self.warnings;
        for (face_index, face) in self.faces.iter().enumerate() {
            let face_id = face_index as u32;
            if face.corners.len() == 4 {
                scene.quad_count += 1;
            }
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
                scene.triangles.push(Triangle {
                    v0: a,
                    e1,
                    e2,
                    normal: n.normalize(),
                    material: face.material,
                    face: face_id,
                });
            }
            if scene.materials[face.material as usize].emitted != Vec3::ZERO {
                scene.lights.push(make_light(
                    face_id,
                    &face.corners,
                    fan,
                    polygon_normal,
                    scene.materials[face.material as usize].emitted,
                ));
            }
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
fn newell_normal(corners: &[Vec3]) -> Vec3 {
    let mut n = Vec3::ZERO;
    for (i, &a) in corners.iter().enumerate() {
        let b = corners[(i + 1) % corners.len()];
        n += a.cross(b);
    }
    n
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
        let cdf = areas
            .iter()
            .map(|w| {
                running += w / area;
                running
            })
            .collect::<Vec<f32>>();
        let mut cdf = cdf;
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
        up: Vec3::Y,
        fov: 20f32.to_radians(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "material\ndiffuse 1 1 1\nm 0\n";

    fn ring_scene(ring: &str, segments: u32) -> Result<Scene, ParseError> {
        parse_scene_str_with(
            &format!("{HEAD}{ring}\n"),
            "ring.obj",
            &ParseOptions {
                ring_segments: segments,
            },
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
