//! `raywave trace-pixel`'s exports on scenes/trace_demo.obj (tests/commands/trace_demo/): the OBJ
//! and PLY parsed back against the tree, and the PNG against the same view without the rays and
//! against the test's own projection and visibility.

use crate::common;
use crate::trace_demo;

use common::bin::{dir_with, stderr};
use glam::{DQuat, DVec3};
use raywave::trace::{RayTree, SegmentKind};
use std::collections::BTreeMap;
use trace_demo::{SCENE, d, demo, run};

/// An OBJ's objects: name -> (vertices, faces, lines), and every vertex and line.
struct Obj {
    objects: BTreeMap<String, (usize, usize, usize)>,
    vertices: Vec<DVec3>,
    lines: BTreeMap<String, Vec<(usize, usize)>>,
}

fn parse_obj(text: &str) -> Obj {
    let mut obj = Obj {
        objects: BTreeMap::new(),
        vertices: Vec::new(),
        lines: BTreeMap::new(),
    };
    let mut current = String::new();
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.first() {
            Some(&"o") => {
                current = t[1].to_string();
                assert!(obj.objects.insert(current.clone(), (0, 0, 0)).is_none());
            }
            Some(&"v") => {
                assert_eq!(t.len(), 7, "v x y z r g b: {line}");
                let n: Vec<f64> = t[1..].iter().map(|x| x.parse().unwrap()).collect();
                assert!(n[3..].iter().all(|c| (0.0..=1.0).contains(c)));
                obj.vertices.push(DVec3::new(n[0], n[1], n[2]));
                obj.objects.get_mut(&current).unwrap().0 += 1;
            }
            Some(&"f") => {
                assert_eq!(t.len(), 4);
                for i in &t[1..] {
                    let i: usize = i.parse().unwrap();
                    assert!(i >= 1 && i <= obj.vertices.len(), "face index {i}");
                }
                obj.objects.get_mut(&current).unwrap().1 += 1;
            }
            Some(&"l") => {
                assert_eq!(t.len(), 3);
                let (a, b): (usize, usize) = (t[1].parse().unwrap(), t[2].parse().unwrap());
                assert!(a >= 1 && b >= 1 && a <= obj.vertices.len() && b <= obj.vertices.len());
                obj.lines
                    .entry(current.clone())
                    .or_default()
                    .push((a - 1, b - 1));
                obj.objects.get_mut(&current).unwrap().2 += 1;
            }
            Some(&"#") | None => {}
            Some(other) => panic!("unexpected OBJ statement {other}"),
        }
    }
    obj
}

#[test]
fn obj_and_ply_hold_the_scene_and_every_ray() {
    let dir = dir_with(&[SCENE]);
    let out = run(
        dir.path(),
        &["--obj", "tree.obj", "--ply", "tree.ply", "--json", "t.json"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let tree: RayTree =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("t.json")).unwrap()).unwrap();
    let obj = parse_obj(&std::fs::read_to_string(dir.path().join("tree.obj")).unwrap());
    // The file: 6 faces, 12 triangles, 2 of them the light; one sphere, tessellated as 12
    // bands of 24 steps (2 poles + 11 rings of 24 vertices, 2·24·11 triangles); the camera
    // marker is 4 edges from the eye, the 4 sides of the image and a tick on its top.
    let blocked = 4;
    let expected: BTreeMap<String, (usize, usize, usize)> = [
        ("scene", (30, 10, 0)),
        ("light_0", (6, 2, 0)),
        ("sphere_0", (2 + 11 * 24, 2 * 24 * 11, 0)),
        ("rays_camera", (2, 0, 1)),
        ("rays_reflection", (2, 0, 1)),
        ("rays_shadow_visible", (2 * (32 - blocked), 0, 32 - blocked)),
        ("rays_shadow_blocked", (2 * blocked, 0, blocked)),
        ("main_camera", (18, 0, 9)),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    assert_eq!(obj.objects, expected);
    // Each ray line runs from its segment's origin to its end, group by kind and outcome.
    for s in &tree.segments {
        let group = match (s.kind, s.shadow.as_ref().and_then(|i| i.blocked)) {
            (SegmentKind::Camera, _) => "rays_camera",
            (SegmentKind::Reflection, _) => "rays_reflection",
            (SegmentKind::Shadow, Some(true)) => "rays_shadow_blocked",
            (SegmentKind::Shadow, _) => "rays_shadow_visible",
        };
        let found = obj.lines[group].iter().any(|&(a, b)| {
            (obj.vertices[a] - d(s.origin)).length() < 1e-5
                && (obj.vertices[b] - d(s.end)).length() < 1e-5
        });
        assert!(found, "segment {} not in {group}", s.id);
    }

    // The PLY: a header whose counts match its body, the same totals as the OBJ.
    let ply = std::fs::read_to_string(dir.path().join("tree.ply")).unwrap();
    let (header, body) = ply.split_once("end_header\n").unwrap();
    let count = |element: &str| -> usize {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("element {element} ")))
            .unwrap()
            .parse()
            .unwrap()
    };
    let (v, f, e) = (count("vertex"), count("face"), count("edge"));
    let totals = expected
        .values()
        .fold((0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
    assert_eq!((v, f, e), totals);
    let rows: Vec<&str> = body.lines().collect();
    assert_eq!(rows.len(), v + f + e);
    assert!(rows[..v].iter().all(|r| r.split_whitespace().count() == 6));
    assert!(rows[v..v + f].iter().all(|r| r.starts_with("3 ")));
    for r in &rows[v + f..] {
        let n: Vec<usize> = r.split_whitespace().map(|x| x.parse().unwrap()).collect();
        assert!(n.len() == 5 && n[0] < v && n[1] < v, "{r}");
    }
}

/// The debug camera of the default view, computed here: the file's eye turned 30° about +y
/// around the point of interest (the origin); and a pinhole projection to pixel coordinates.
struct TestCamera {
    eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    size: f64,
}

impl TestCamera {
    fn default_view(size: u32) -> TestCamera {
        let eye = DQuat::from_rotation_y(30f64.to_radians()) * DVec3::from_array(demo::EYE);
        TestCamera::looking_from(eye, size)
    }

    /// A camera at `eye` looking at the origin (the file's point of interest), up +y.
    fn looking_from(eye: DVec3, size: u32) -> TestCamera {
        let forward = (-eye).normalize();
        let right = forward.cross(DVec3::Y).normalize();
        let up = right.cross(forward);
        TestCamera {
            eye,
            forward,
            right,
            up,
            size: size as f64,
        }
    }

    /// Pixel coordinates (x right, y down) of a point in front of the eye.
    fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let v = p - self.eye;
        let z = v.dot(self.forward);
        if z <= 1e-6 {
            return None;
        }
        let half = (demo::FOV_DEGREES.to_radians() / 2.0).tan();
        let sx = v.dot(self.right) / (z * half);
        let sy = v.dot(self.up) / (z * half);
        Some(((sx + 1.0) / 2.0 * self.size, (1.0 - sy) / 2.0 * self.size))
    }
}

fn distance_to_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

#[test]
fn png_differs_from_the_plain_view_exactly_along_the_rays() {
    let dir = dir_with(&[SCENE]);
    let size = 160u32;
    let view = ["--view-size", "160", "160"];
    let out = run(
        dir.path(),
        &[&["--png", "rays.png", "--json", "t.json"], &view[..]].concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = run(
        dir.path(),
        &[&["--png", "plain.png", "--no-rays"], &view[..]].concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let tree: RayTree =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("t.json")).unwrap()).unwrap();
    let rays = image::open(dir.path().join("rays.png")).unwrap().to_rgb8();
    let plain = image::open(dir.path().join("plain.png")).unwrap().to_rgb8();
    assert_eq!(rays.dimensions(), (size, size));
    let camera = TestCamera::default_view(size);
    // (start, end, dashed) in pixel coordinates.
    type Projected = ((f64, f64), (f64, f64), bool);
    let projected: Vec<Projected> = tree
        .segments
        .iter()
        .filter_map(|s| {
            let a = camera.project(d(s.origin))?;
            let b = camera.project(d(s.end))?;
            let dashed = s.shadow.as_ref().and_then(|i| i.blocked) == Some(true);
            Some((a, b, dashed))
        })
        .collect();
    assert_eq!(
        projected.len(),
        tree.segments.len(),
        "every segment is in front of the view"
    );
    let mut differing = 0;
    for (x, y, p) in rays.enumerate_pixels() {
        if p == plain.get_pixel(x, y) {
            continue;
        }
        differing += 1;
        let centre = (x as f64 + 0.5, y as f64 + 0.5);
        let nearest = projected
            .iter()
            .map(|&(a, b, _)| distance_to_segment(centre, a, b))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 1.5,
            "pixel ({x}, {y}) changed {nearest:.2} px from every ray"
        );
    }
    assert!(differing > 100, "only {differing} pixels changed");
    // And along each ray (inside the image) the pixels did change: all along solid rays,
    // about half along dashed ones.
    let changed_near = |q: (f64, f64)| {
        (-1i64..=1).any(|dy| {
            (-1i64..=1).any(|dx| {
                let (x, y) = (q.0.floor() as i64 + dx, q.1.floor() as i64 + dy);
                x >= 0
                    && y >= 0
                    && x < size as i64
                    && y < size as i64
                    && rays.get_pixel(x as u32, y as u32) != plain.get_pixel(x as u32, y as u32)
            })
        })
    };
    for (k, &(a, b, dashed)) in projected.iter().enumerate() {
        let inside: Vec<(f64, f64)> = (0..=100)
            .map(|i| {
                let f = i as f64 / 100.0;
                (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1))
            })
            .filter(|q| {
                q.0 >= 1.0 && q.1 >= 1.0 && q.0 < size as f64 - 1.0 && q.1 < size as f64 - 1.0
            })
            .collect();
        if inside.len() < 10 {
            continue;
        }
        let hit = inside.iter().filter(|&&q| changed_near(q)).count() as f64 / inside.len() as f64;
        let need = if dashed { 0.3 } else { 0.95 };
        assert!(hit >= need, "segment {k}: {hit:.2} of its pixels changed");
    }
}

/// Whether the sphere or the slab's top (y = 1.65, seen from above) hides `p` from `eye`, and
/// how clearly (the smallest distance from the edge of what hides it, or of what it misses).
fn hidden(eye: DVec3, p: DVec3) -> (bool, f64) {
    let (c, r) = (DVec3::from_array(demo::SPHERE.0), demo::SPHERE.1);
    let d = p - eye;
    // The sphere: the closest approach of eye → p, counted only in front of p.
    let t = ((c - eye).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    let gap = (eye + t * d - c).length() - r;
    let by_sphere = gap < 0.0 && t < 1.0 && (p - c).length() > r + 1e-4;
    let mut margin = gap.abs();
    let top = 1.65;
    let mut by_slab = false;
    if eye.y > top && p.y < top {
        let q = eye + (top - eye.y) / (p.y - eye.y) * d;
        let (x0, x1) = demo::OCCLUDER_X;
        let (z0, z1) = demo::OCCLUDER_Z;
        by_slab = q.x > x0 && q.x < x1 && q.z > z0 && q.z < z1;
        let edge = [q.x - x0, x1 - q.x, q.z - z0, z1 - q.z]
            .iter()
            .map(|m| m.abs())
            .fold(f64::INFINITY, f64::min);
        margin = margin.min(edge);
    }
    (by_sphere || by_slab, margin)
}

#[test]
fn rays_are_drawn_solid_where_seen_and_faint_where_hidden() {
    // From behind and above the mirror sphere: it hides the end of the camera ray and the start
    // of its shadow rays.
    let dir = dir_with(&[SCENE]);
    let size = 200u32;
    let eye = DVec3::new(0.4, 0.9, -1.9);
    let out = run(
        dir.path(),
        &[
            "--png",
            "v.png",
            "--json",
            "t.json",
            "--view-size",
            "200",
            "200",
            "--view-from",
            "0.4",
            "0.9",
            "-1.9",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let tree: RayTree =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("t.json")).unwrap()).unwrap();
    let img = image::open(dir.path().join("v.png")).unwrap().to_rgb8();
    let camera = TestCamera::looking_from(eye, size);
    let colour_of = |s: &raywave::trace::Segment| raywave::trace::palette::Style::of(s).colour();
    let (mut hidden_points, mut hidden_solid) = (0, 0);
    let (mut seen_points, mut seen_solid) = (0, 0);
    for s in &tree.segments {
        let dashed = s.shadow.as_ref().and_then(|i| i.blocked) == Some(true);
        for i in 5..=95 {
            let p = d(s.origin).lerp(d(s.end), i as f64 / 100.0);
            let Some((x, y)) = camera.project(p) else {
                continue;
            };
            if !(x >= 1.0 && y >= 1.0 && x < size as f64 - 1.0 && y < size as f64 - 1.0) {
                continue;
            }
            let (is_hidden, margin) = hidden(eye, p);
            if margin < 0.02 {
                continue;
            }
            // Within a pixel: is the segment's full colour there?
            let solid = (-1i64..=1).any(|dy| {
                (-1i64..=1).any(|dx| {
                    let (px, py) = (
                        (x.floor() as i64 + dx) as u32,
                        (y.floor() as i64 + dy) as u32,
                    );
                    img.get_pixel(px, py).0 == colour_of(s)
                })
            });
            if is_hidden {
                // Another ray of the same colour may pass in front nearby: count, then bound.
                hidden_points += 1;
                hidden_solid += usize::from(solid);
            } else if !dashed {
                seen_points += 1;
                seen_solid += usize::from(solid);
            }
        }
    }
    assert!(
        hidden_points > 50,
        "only {hidden_points} hidden sample points: the view tests nothing"
    );
    assert!(seen_points > 50, "only {seen_points} visible sample points");
    assert!(
        (hidden_solid as f64) < 0.1 * hidden_points as f64,
        "{hidden_solid} of {hidden_points} hidden points drawn in full colour"
    );
    assert!(
        (seen_solid as f64) > 0.9 * seen_points as f64,
        "{seen_solid} of {seen_points} visible points drawn in full colour"
    );
}
