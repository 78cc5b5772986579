//! The lab's debug view: every ray traced for one pixel, printed as a tree and drawn over the
//! image (projected through the camera), in the debug view's colours (`trace::palette`): camera
//! rays white, mirror rays red, shadow rays green when the light point is visible and magenta
//! when blocked. `raywave render --debug-pixel` fills a recorder from `trace::trace_pixel`'s
//! tree ([`RayRecorder::from_tree`]).

use crate::camera::CameraRays;
use crate::geometry::{Hit, Ray};
use crate::reference::TraceLog;
use glam::Vec3;
use std::fmt::Write;

/// One ray as seen by the debug view.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggedRay {
    /// 0 for the camera ray, k after k reflections.
    pub bounce: u32,
    /// What kind of ray.
    pub kind: LoggedKind,
    /// Start point.
    pub from: Vec3,
    /// End point (the hit, the light point, or far along a ray that missed).
    pub to: Vec3,
}

/// Kinds of logged rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoggedKind {
    /// Camera or mirror ray; `hit` is the primitive id, or None for a miss.
    Path {
        /// Primitive hit.
        hit: Option<u32>,
    },
    /// Shadow ray to light `light`; `blocked` is None when shadows are off.
    Shadow {
        /// Light index.
        light: u32,
        /// Outcome of the occlusion test.
        blocked: Option<bool>,
    },
}

/// Records rays; `miss_length` is how far a missing ray is drawn.
#[derive(Default)]
pub struct RayRecorder {
    /// The rays in the order they were cast.
    pub rays: Vec<LoggedRay>,
    /// Length used to draw rays that hit nothing.
    pub miss_length: f32,
}

impl TraceLog for RayRecorder {
    fn path_ray(&mut self, bounce: u32, ray: &Ray, hit: &Hit) {
        let t = if hit.is_hit() {
            hit.t
        } else {
            self.miss_length
        };
        self.rays.push(LoggedRay {
            bounce,
            kind: LoggedKind::Path {
                hit: hit.is_hit().then_some(hit.prim),
            },
            from: ray.origin,
            to: ray.origin + t * ray.direction,
        });
    }
    fn shadow_ray(&mut self, bounce: u32, light: u32, from: Vec3, to: Vec3, blocked: Option<bool>) {
        self.rays.push(LoggedRay {
            bounce,
            kind: LoggedKind::Shadow { light, blocked },
            from,
            to,
        });
    }
}

impl RayRecorder {
    /// The rays of a traced pixel's tree, in its order; rays that miss end at the tree's
    /// `miss_length`.
    pub fn from_tree(tree: &crate::trace::RayTree) -> RayRecorder {
        use crate::trace::SegmentKind;
        let rays = tree
            .segments
            .iter()
            .map(|s| LoggedRay {
                bounce: s.depth,
                kind: match s.kind {
                    SegmentKind::Camera | SegmentKind::Reflection => LoggedKind::Path {
                        hit: s.hit.as_ref().map(|h| h.primitive.id),
                    },
                    SegmentKind::Shadow => {
                        let info = s.shadow.as_ref();
                        LoggedKind::Shadow {
                            light: info.map_or(0, |i| i.light),
                            blocked: info.and_then(|i| i.blocked),
                        }
                    }
                },
                from: Vec3::from_array(s.origin),
                to: Vec3::from_array(s.end),
            })
            .collect();
        RayRecorder {
            rays,
            miss_length: tree.miss_length,
        }
    }

    /// The rays in tree order. The tracer logs a mirror ray before the shadow rays of the hit
    /// that spawned it (the recursion returns first), so each camera ray's chain (one hit per
    /// depth) is sorted stably by (depth, path ray before shadow rays).
    pub fn tree_order(&self) -> Vec<&LoggedRay> {
        let mut out = Vec::with_capacity(self.rays.len());
        let mut chain: Vec<&LoggedRay> = Vec::new();
        let key = |r: &&LoggedRay| (r.bounce, matches!(r.kind, LoggedKind::Shadow { .. }));
        for r in &self.rays {
            if r.bounce == 0 && matches!(r.kind, LoggedKind::Path { .. }) && !chain.is_empty() {
                chain.sort_by_key(key);
                out.append(&mut chain);
            }
            chain.push(r);
        }
        chain.sort_by_key(key);
        out.append(&mut chain);
        out
    }

    /// A readable tree, indented by bounce.
    pub fn report(&self, scene: &crate::scene::Scene) -> String {
        let mut s = String::new();
        for r in self.tree_order() {
            let indent = "  ".repeat(r.bounce as usize);
            let _ = match r.kind {
                LoggedKind::Path { hit } => {
                    let what = if r.bounce == 0 { "camera" } else { "mirror" };
                    let target = match hit {
                        Some(p) if (p as usize) < scene.triangles.len() => {
                            format!(
                                "hits face {} (triangle {p}) at {:.4}",
                                scene.triangles[p as usize].face, r.to
                            )
                        }
                        Some(p) => format!(
                            "hits sphere {} at {:.4}",
                            p as usize - scene.triangles.len(),
                            r.to
                        ),
                        None => "misses: background".to_string(),
                    };
                    writeln!(s, "{indent}{what} ray from {:.4} {target}", r.from)
                }
                LoggedKind::Shadow { light, blocked } => {
                    let outcome = match blocked {
                        Some(true) => "blocked",
                        Some(false) => "visible",
                        None => "assumed visible (shadows off)",
                    };
                    writeln!(
                        s,
                        "{indent}  shadow ray to light {light} at {:.4}: {outcome}",
                        r.to
                    )
                }
            };
        }
        s
    }

    /// Draws the rays over `img`, projected through `camera`.
    pub fn draw(&self, img: &mut image::RgbImage, camera: &CameraRays) {
        for r in &self.rays {
            use crate::trace::palette;
            let colour = match r.kind {
                LoggedKind::Path { .. } if r.bounce == 0 => palette::CAMERA,
                LoggedKind::Path { .. } => palette::REFLECTION,
                LoggedKind::Shadow {
                    blocked: Some(true),
                    ..
                } => palette::SHADOW_BLOCKED,
                LoggedKind::Shadow { blocked: None, .. } => palette::SHADOW_UNTESTED,
                LoggedKind::Shadow { .. } => palette::SHADOW_VISIBLE,
            };
            draw_segment(img, camera, r.from, r.to, colour);
        }
        // A camera ray runs along the line of sight and projects to a dot: mark its hit with a
        // cross, drawn last so the rays leaving that hit do not cover it.
        for r in self.rays.iter().filter(|r| r.bounce == 0) {
            if let LoggedKind::Path { .. } = r.kind
                && let Some((x, y)) = project(camera, r.to)
            {
                for d in -4..=4 {
                    put(img, x as i64 + d, y as i64, crate::trace::palette::CAMERA);
                    put(img, x as i64, y as i64 + d, crate::trace::palette::CAMERA);
                }
            }
        }
    }
}

/// Projects a world point to continuous pixel coordinates (x right, y down), or None behind
/// the eye.
fn project(camera: &CameraRays, p: Vec3) -> Option<(f32, f32)> {
    let d = p - camera.origin;
    let depth = d.dot(camera.forward);
    if depth <= 1e-4 {
        return None;
    }
    let half = camera.right.length();
    let sx = d.dot(camera.right) / (half * half * depth);
    let sy = d.dot(camera.up) / (half * half * depth);
    let (w, h) = (camera.width as f32, camera.height as f32);
    let m = w.max(h);
    let x = ((sx + 1.0) * 0.5 - 0.5) * m + 0.5 * w;
    let y = ((sy + 1.0) * 0.5 - 0.5) * m + 0.5 * h;
    Some((x, h - y))
}

fn draw_segment(img: &mut image::RgbImage, camera: &CameraRays, a: Vec3, b: Vec3, colour: [u8; 3]) {
    // Walk the 3D segment so the part in front of the eye is drawn even if an end is behind it.
    let steps = 2048;
    for k in 0..=steps {
        let p = a.lerp(b, k as f32 / steps as f32);
        if let Some((x, y)) = project(camera, p) {
            put(img, x.floor() as i64, y.floor() as i64, colour);
        }
    }
}

/// Sets a pixel if (x, y) lies inside the image.
fn put(img: &mut image::RgbImage, x: i64, y: i64, colour: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u64) < img.width() as u64 && (y as u64) < img.height() as u64 {
        img.put_pixel(x as u32, y as u32, image::Rgb(colour));
    }
}
