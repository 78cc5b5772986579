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

use super::texture::Texture;
use super::{Camera, Material, Scene, Sphere};
use crate::render::quote::quote;
use assemble::newell_normal;
use glam::Vec3;
use std::path::Path;

mod assemble;
mod rpi;
mod textures;

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
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}: warning: {message}")]
pub struct Warning {
    /// The file.
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    /// What happened.
    pub message: String,
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
    /// Texture coordinates of each corner's vertex (`vt`), or empty when none has any.
    st: Vec<Option<[f32; 2]>>,
    material: u32,
    line: usize,
}

/// Camera keys gathered from a `PerspectiveCamera { ... }` block.
struct CameraBlock {
    start_line: usize,
    tokens: Vec<(String, usize)>,
}

#[derive(Default)]
struct Parser<'a> {
    file: &'a str,
    options: ParseOptions,
    /// The folder `texture_file` names are relative to (`None`: the current directory).
    base: Option<&'a Path>,
    vertices: Vec<Vec3>,
    /// Texture coordinates of each vertex (`vt` after its `v`), in `vertices` order.
    vertex_st: Vec<Option<[f32; 2]>>,
    /// Textures read so far, in `texture_file` order (a file named twice is read once).
    textures: Vec<Texture>,
    materials: Vec<Material>,
    /// The `m i` selection.
    active_material: Option<u32>,
    /// Every `m i` and its line, checked against the materials at the end.
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

/// Parses scene text with the default [`ParseOptions`]; `file` is used in messages only, and
/// `texture_file` names are relative to the current directory.
pub fn parse_scene_str(text: &str, file: &str) -> Result<Scene, ParseError> {
    parse_scene_in(text, file, &ParseOptions::default(), None)
}

/// Parses scene text whose `texture_file` names are relative to `base` (the scene file's
/// folder; `None`: the current directory); `file` is used in messages only.
pub fn parse_scene_in(
    text: &str,
    file: &str,
    options: &ParseOptions,
    base: Option<&Path>,
) -> Result<Scene, ParseError> {
    // Editors on Windows start UTF-8 files with a byte-order mark; it is not part of the first
    // keyword (left in, it turned the first `material` into an unknown keyword).
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut p = Parser {
        file,
        options: *options,
        base,
        ..Parser::default()
    };
    let mut pending = String::new();
    let mut pending_line = 0;
    for (index, raw) in text.lines().enumerate() {
        let content = raw.split_once('#').map_or(raw, |(code, _)| code);
        if pending.is_empty() {
            pending_line = index + 1;
        }
        let trimmed = content.trim_end();
        if let Some(head) = trimmed.strip_suffix('\\') {
            pending.push_str(head);
            pending.push(' ');
            continue;
        }
        pending.push_str(trimmed);
        p.logical_line(&std::mem::take(&mut pending), pending_line)?;
    }
    if !pending.is_empty() {
        p.logical_line(&pending, pending_line)?;
    }
    if let Some(block) = &p.camera_block {
        return Err(p.error(
            block.start_line,
            "expected `}` to close the PerspectiveCamera block, found the end of the file",
        ));
    }
    p.finish(text.lines().count().max(1))
}

/// The largest magnitude of any number in a scene file. Squared lengths, areas and the light
/// colour 0.2·ke·area multiply up to four of them, which stays finite in f32 (1e36 < 3.4e38)
/// below 1e9; larger values overflowed to infinity and came out as "degenerate" faces or
/// infinite lights.
const MAX_NUMBER: f32 = 1e9;

/// Whether `token`, which Rust's float parser read as an infinity or NaN, is a finite number
/// past the type's range (`1e39` as an f32, `-1e309` as an f64: the parser rounds those to an
/// infinity) rather than one spelled infinite or not a number (`inf`, `-Infinity`, `NaN`).
pub fn beyond_range(token: &str) -> bool {
    let unsigned = token.strip_prefix(['+', '-']).unwrap_or(token);
    !["inf", "infinity", "nan"]
        .iter()
        .any(|s| unsigned.eq_ignore_ascii_case(s))
}

impl Parser<'_> {
    fn error(&self, line: usize, message: impl Into<String>) -> ParseError {
        ParseError {
            file: self.file.to_string(),
            line,
            message: message.into(),
        }
    }

    /// The one reading of a number in a scene file: an f32 of magnitude at most [`MAX_NUMBER`].
    fn number(&self, line: usize, what: &str, token: Option<&str>) -> Result<f32, ParseError> {
        let error = |message: String| self.error(line, message);
        let token =
            token.ok_or_else(|| error(format!("expected {what}, found the end of the line")))?;
        let parsed = token.parse::<f32>();
        let finite_beyond_f32 = beyond_range(token);
        let token = quote(token);
        match parsed {
            Ok(x) if x.is_finite() && x.abs() <= MAX_NUMBER => Ok(x),
            // Past 1e9, up to past f32's range: the same limit, the same message.
            Ok(x) if x.is_finite() || finite_beyond_f32 => Err(error(format!(
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

    fn warn(&mut self, line: usize, message: impl Into<String>) {
        self.warnings.push(Warning {
            file: self.file.to_string(),
            line,
            message: message.into(),
        });
    }

    /// Reads exactly three numbers after the keyword and nothing else.
    fn vec3(&self, line: usize, keyword: &str, args: &[&str]) -> Result<Vec3, ParseError> {
        let what = |axis: &str| format!("{axis} of `{keyword}`");
        let x = self.number(line, &what("1st number"), args.first().copied())?;
        let y = self.number(line, &what("2nd number"), args.get(1).copied())?;
        let z = self.number(line, &what("3rd number"), args.get(2).copied())?;
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
        self.active_material.ok_or_else(|| {
            self.error(
                line,
                format!("expected `m <material index>` before this {what}, found a {what} before any material was selected"),
            )
        })
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
                self.vertex_st.push(None);
            }
            "vt" => self.texture_coords(line, args)?,
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
                let radius = self.number(line, "the radius of `s`", Some(args[3]))?;
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
                self.active_material = Some(index);
                self.material_refs.push((index, line));
            }
            "material" => self.materials.push(Material::default()),
            "diffuse" => {
                let c = self.colour(line, keyword, args)?;
                let material = self.current_material(line, keyword)?;
                if material.texture.is_some() {
                    self.warn(
                        line,
                        "`diffuse` ignored: the material's texture gives its diffuse colour \
                         (RPI's materials have one or the other)",
                    );
                } else {
                    material.diffuse = c;
                }
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
                let g = self.number(
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
            "texture_file" => self.texture_file(line, args)?,
            "transmitted" => {
                // RPI's refraction colour, for its photon mapper: nothing a ray tracer of
                // mirrors renders, so only a non-zero one is worth a word.
                let c = self.colour(line, keyword, args)?;
                self.current_material(line, keyword)?;
                if c != Vec3::ZERO {
                    self.warn(line, "transmission is not rendered: `transmitted` ignored");
                }
            }
            "background_color" => self.background = Some(self.colour(line, keyword, args)?),
            "PerspectiveCamera" => {
                if self.camera.is_some() {
                    return Err(self.error(
                        line,
                        "expected one camera block, found a second `PerspectiveCamera`",
                    ));
                }
                self.camera_block = Some(CameraBlock {
                    start_line: line,
                    tokens: Vec::new(),
                });
                self.camera_line(&args.join(" "), line)?;
            }
            "vn" | "vp" | "g" | "o" | "usemtl" | "mtllib" => {}
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
        let mut st = Vec::with_capacity(args.len());
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
            st.push(self.vertex_st[(resolved - 1) as usize]);
        }
        if st.iter().all(Option::is_none) {
            st.clear();
        }
        let material = self.active_material(line, "face")?;
        self.push_face(line, corners, st, material)
    }

    /// Adds a polygon (with its corners' texture coordinates, or none), refusing one without
    /// area.
    fn push_face(
        &mut self,
        line: usize,
        corners: Vec<Vec3>,
        st: Vec<Option<[f32; 2]>>,
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
            st,
            material,
            line,
        });
        Ok(())
    }
}
