//! `raywave trace-pixel` on scenes/trace_demo.obj: the tree of pixel (26, 32) at 64×64 (the
//! camera ray hits the mirror sphere, its reflection the red wall, and the slab under the
//! light blocks some of the wall's shadow rays). The expected segments come from the settings,
//! the blocked flags from the test's own f64 geometry of the scene file, and the colours from
//! both engines' whole-image renders.

mod common;

use common::bin::{dir_with, files_in, raywave, stderr, stdout};
use glam::{DQuat, DVec3, Vec3};
use raywave::engine::Engine;
use raywave::scene::Scene;
use raywave::settings::{RenderSettings, ShadowMode};
use raywave::trace::{RayTree, SegmentKind, trace_pixel};
use std::collections::BTreeMap;
use std::path::Path;

const SCENE: &str = "trace_demo.obj";
const PIXEL: (u32, u32) = (26, 32);
const FLAGS: &[&str] = &[
    "--size",
    "64",
    "64",
    "--bounces",
    "2",
    "--shadow-samples",
    "16",
];

/// The scene file's numbers, written out again here (not read through the code under test).
mod demo {
    /// The mirror sphere: centre and radius.
    pub const SPHERE: ([f64; 3], f64) = ([0.0, 0.0, 0.0], 0.6);
    /// The slab's underside (facing down): y and its x and z ranges.
    pub const OCCLUDER_Y: f64 = 1.6;
    pub const OCCLUDER_X: (f64, f64) = (-1.4, -0.7);
    pub const OCCLUDER_Z: (f64, f64) = (0.7, 1.6);
    /// The light: y = 3, x in -0.5..0.5, z in 0..1.
    pub const LIGHT_Y: f64 = 3.0;
    /// The red wall's plane x = -2.
    pub const RED_WALL_X: f64 = -2.0;
    /// The file's camera.
    pub const EYE: [f64; 3] = [0.0, 2.5, 6.0];
    pub const FOV_DEGREES: f64 = 40.0;
}

fn scene() -> Scene {
    Scene::load(&common::bin::scenes().join(SCENE)).unwrap()
}

fn settings() -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 64,
        bounces: 2,
        shadows: ShadowMode::Soft,
        shadow_samples: 16,
        ..RenderSettings::default()
    }
}

fn d(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0].into(), v[1].into(), v[2].into())
}

/// Whether the segment a → b crosses the slab's underside, and how far from the slab's edges
/// (the margin that makes the answer robust to rounding).
fn crosses_occluder(a: DVec3, b: DVec3) -> (bool, f64) {
    let f = (demo::OCCLUDER_Y - a.y) / (b.y - a.y);
    if !(0.0..=1.0).contains(&f) {
        return (false, f64::INFINITY);
    }
    let p = a + f * (b - a);
    let (x0, x1) = demo::OCCLUDER_X;
    let (z0, z1) = demo::OCCLUDER_Z;
    let inside = p.x > x0 && p.x < x1 && p.z > z0 && p.z < z1;
    let margin = [p.x - x0, x1 - p.x, p.z - z0, z1 - p.z]
        .iter()
        .map(|m| m.abs())
        .fold(f64::INFINITY, f64::min);
    (inside, margin)
}

/// Whether the segment a → b passes through the sphere (between its ends).
fn crosses_sphere(a: DVec3, b: DVec3) -> bool {
    let (c, r) = (DVec3::from_array(demo::SPHERE.0), demo::SPHERE.1);
    let d = b - a;
    let t = ((c - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (a + t * d - c).length() < r
}

#[test]
fn the_chosen_pixel_has_the_segments_the_settings_give() {
    let (scene, settings) = (scene(), settings());
    let tree = trace_pixel(&scene, &settings, PIXEL.0, PIXEL.1).unwrap();
    let count = |k: SegmentKind| tree.segments.iter().filter(|s| s.kind == k).count();
    // One aa sample: one camera ray; it hits the mirror, whose reflection hits the (diffuse)
    // red wall: one reflection; 16 points on the one light from each of the two hits.
    assert_eq!(count(SegmentKind::Camera), 1);
    assert_eq!(count(SegmentKind::Reflection), 1);
    assert_eq!(count(SegmentKind::Shadow), 2 * 16);

    let camera = &tree.segments[0];
    assert_eq!(camera.kind, SegmentKind::Camera);
    assert!((d(camera.origin) - DVec3::from_array(demo::EYE)).length() < 1e-6);
    let on_sphere = d(camera.end).length();
    assert!((on_sphere - demo::SPHERE.1).abs() < 1e-5, "{on_sphere}");
    let reflection = tree
        .segments
        .iter()
        .find(|s| s.kind == SegmentKind::Reflection)
        .unwrap();
    assert_eq!(reflection.parent, Some(camera.id));
    assert_eq!(reflection.depth, 1);
    assert!((f64::from(reflection.end[0]) - demo::RED_WALL_X).abs() < 1e-5);
    // The mirror direction, by the law of reflection at the sphere's outward normal.
    let n = d(camera.end).normalize();
    let incoming = d(camera.direction);
    let mirror = incoming - 2.0 * incoming.dot(n) * n;
    assert!((mirror - d(reflection.direction)).length() < 1e-5);

    for parent in [camera.id, reflection.id] {
        let shadows: Vec<_> = tree
            .segments
            .iter()
            .filter(|s| s.parent == Some(parent) && s.kind == SegmentKind::Shadow)
            .collect();
        assert_eq!(shadows.len(), 16, "shadow rays of segment {parent}");
        let mut indices: Vec<u32> = shadows
            .iter()
            .map(|s| s.shadow.as_ref().unwrap().sample_index)
            .collect();
        indices.sort();
        assert_eq!(indices, (0..16).collect::<Vec<_>>());
        for s in shadows {
            let p = d(s.shadow.as_ref().unwrap().light_point);
            assert!(
                (p.y - demo::LIGHT_Y).abs() < 1e-6
                    && p.x.abs() <= 0.5
                    && (0.0..=1.0).contains(&p.z)
            );
        }
    }
}

#[test]
fn blocked_flags_match_the_scene_geometry() {
    let tree = trace_pixel(&scene(), &settings(), PIXEL.0, PIXEL.1).unwrap();
    let mut blocked_by_depth = BTreeMap::new();
    for s in tree
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Shadow)
    {
        let info = s.shadow.as_ref().unwrap();
        let (a, b) = (d(s.origin), d(info.light_point));
        let (occluded, margin) = crosses_occluder(a, b);
        assert!(
            margin > 1e-3,
            "shadow ray {} passes within {margin} of the slab's edge: the test pixel is not robust",
            s.id
        );
        let expected = occluded || crosses_sphere(a, b);
        assert_eq!(info.blocked, Some(expected), "shadow ray {}", s.id);
        if expected {
            // The slab's underside is face 4 of the file.
            let blocker = info
                .blocker
                .as_ref()
                .expect("a blocked ray names its blocker");
            assert_eq!(blocker.primitive.face, Some(4), "shadow ray {}", s.id);
            assert!((f64::from(blocker.point[1]) - demo::OCCLUDER_Y).abs() < 1e-5);
            assert_eq!(s.contribution, [0.0; 3]);
        } else {
            assert!(info.blocker.is_none());
            assert!(
                s.contribution.iter().all(|&c| c > 0.0),
                "{:?}",
                s.contribution
            );
        }
        *blocked_by_depth.entry(s.depth).or_insert(0) += usize::from(expected);
    }
    // The camera hit sees the whole light; the slab hides part of it from the wall.
    assert_eq!(blocked_by_depth.get(&0), Some(&0));
    let wall = blocked_by_depth[&1];
    assert!(wall > 0 && wall < 16, "{wall} of 16 blocked");
}

/// The pixel as each engine's whole-image render gives it.
fn rendered(scene: &Scene, settings: &RenderSettings, x: u32, y: u32) -> [Vec3; 2] {
    [Engine::Reference, Engine::Wavefront].map(|engine| {
        let (film, _) = engine.render(scene, settings, 256, &|| {});
        film.pixels[(y * settings.width + x) as usize]
    })
}

fn assert_sums_to(tree: &RayTree, pixel: Vec3) {
    for c in 0..3 {
        let diff = (tree.sum[c] - f64::from(pixel[c])).abs();
        assert!(
            diff <= 1e-5 * f64::from(pixel[c]).max(1.0),
            "channel {c}: sum {} vs rendered {}",
            tree.sum[c],
            pixel[c]
        );
    }
}

#[test]
fn contributions_sum_to_the_pixel_both_engines_render() {
    let scene = scene();
    let base = settings();
    let variants = [
        base.clone(),
        RenderSettings {
            aa_samples: 4,
            sampler: raywave::sampling::LightSampler::Sobol,
            seed: 3,
            ..base.clone()
        },
        RenderSettings {
            shadows: ShadowMode::Hard,
            shadow_samples: 1,
            ..base.clone()
        },
        RenderSettings {
            shadows: ShadowMode::Off,
            ..base.clone()
        },
    ];
    for settings in &variants {
        let tree = trace_pixel(&scene, settings, PIXEL.0, PIXEL.1).unwrap();
        let cameras = tree
            .segments
            .iter()
            .filter(|s| s.kind == SegmentKind::Camera)
            .count();
        assert_eq!(cameras as u32, settings.aa_samples, "{settings:?}");
        for pixel in rendered(&scene, settings, PIXEL.0, PIXEL.1) {
            assert_sums_to(&tree, pixel);
        }
        if settings.shadows == ShadowMode::Off {
            assert!(
                tree.segments
                    .iter()
                    .filter_map(|s| s.shadow.as_ref())
                    .all(|i| i.blocked.is_none())
            );
        }
    }
    // Pixels elsewhere too: the background, the floor, the sphere's rim.
    for (x, y) in [(0, 0), (63, 63), (32, 20), (40, 40)] {
        let tree = trace_pixel(&scene, &base, x, y).unwrap();
        for pixel in rendered(&scene, &base, x, y) {
            assert_sums_to(&tree, pixel);
        }
    }
}

#[test]
fn the_builtin_scene_sums_too() {
    // The lab's box: three mirror spheres, 5 bounces, soft shadows, 2×2 aa.
    let scene = Scene::builtin_default();
    let settings = RenderSettings {
        width: 48,
        height: 48,
        aa_samples: 4,
        shadow_samples: 4,
        ..RenderSettings::default()
    };
    for (x, y) in [(15, 36), (30, 33), (24, 10)] {
        let tree = trace_pixel(&scene, &settings, x, y).unwrap();
        for pixel in rendered(&scene, &settings, x, y) {
            assert_sums_to(&tree, pixel);
        }
    }
}

/// Runs trace-pixel on the demo pixel with `extra` flags in a scratch directory.
fn run(dir: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["trace-pixel", "26", "32", SCENE];
    args.extend_from_slice(FLAGS);
    args.extend_from_slice(extra);
    raywave(dir, &args)
}

#[test]
fn json_is_the_tree_with_its_check() {
    let dir = dir_with(&[SCENE]);
    let out = run(dir.path(), &["--json", "tree.json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("tree.json")).unwrap();
    let mut tree: RayTree = serde_json::from_str(&text).unwrap();
    let check = tree.check.take().expect("the CLI checks the pixel");
    assert!(check.agrees, "{check:?}");
    let mut expected = trace_pixel(&scene(), &settings(), PIXEL.0, PIXEL.1).unwrap();
    expected.scene = tree.scene.clone();
    assert_eq!(tree, expected);
    assert!(stdout(&out).contains("agrees"), "{}", stdout(&out));

    // `-` writes it to standard output; the summary then goes to standard error.
    let out = run(dir.path(), &["--json", "-"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let piped: RayTree = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(piped.segments.len(), 34);
    assert!(stderr(&out).contains("agrees"));
}

#[test]
fn the_summary_names_every_segment_and_the_check() {
    let dir = dir_with(&[SCENE]);
    let out = run(dir.path(), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("1 camera, 1 reflection, 32 shadow"), "{text}");
    assert_eq!(text.matches("shadow ray #").count(), 32, "{text}");
    assert!(text.contains("blocked by face 4"), "{text}");
    assert!(
        text.contains("the tree adds up to the rendered pixel"),
        "{text}"
    );
    assert_eq!(files_in(dir.path()), vec![SCENE.to_string()]);
}

/// The schema checked in under docs/ is the one the types give. Set RAYWAVE_BLESS=1 to write
/// it after changing the types.
#[test]
fn the_checked_in_schema_matches_the_types() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/schema/ray-tree.schema.json");
    let schema = schemars::schema_for!(RayTree);
    let generated = serde_json::to_string_pretty(&schema).unwrap() + "\n";
    if std::env::var_os("RAYWAVE_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let checked_in = std::fs::read_to_string(&path).expect("docs/schema/ray-tree.schema.json");
    assert_eq!(
        serde_json::from_str::<serde_json::Value>(&checked_in).unwrap(),
        serde_json::from_str::<serde_json::Value>(&generated).unwrap(),
        "docs/schema/ray-tree.schema.json is stale: run RAYWAVE_BLESS=1 cargo test --release --test trace_pixel"
    );
    // Every field the tree writes is in the schema.
    let tree = trace_pixel(&scene(), &settings(), PIXEL.0, PIXEL.1).unwrap();
    let json = serde_json::to_value(&tree).unwrap();
    let properties = &serde_json::to_value(&schema).unwrap()["properties"];
    for key in json.as_object().unwrap().keys() {
        assert!(properties.get(key).is_some(), "{key} is not in the schema");
    }
}

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

#[test]
fn bad_input_is_a_usage_error_and_writes_nothing() {
    let dir = dir_with(&[SCENE]);
    let cases: &[(&[&str], &str)] = &[
        (
            &["trace-pixel", "64", "0", SCENE, "--size", "64", "64"],
            "outside the 64×64 image",
        ),
        (
            &["trace-pixel", "0", "64", SCENE, "--size", "64", "64"],
            "outside the 64×64 image",
        ),
        (&["trace-pixel", "-1", "0", SCENE], ""),
        (&["trace-pixel", "x", "0", SCENE], ""),
        (&["trace-pixel", "1"], ""),
        (
            &["trace-pixel", "1", "1", SCENE, "--orbit", "nan"],
            "finite",
        ),
        (
            &["trace-pixel", "1", "1", SCENE, "--view-from", "1", "2"],
            "",
        ),
        (
            &["trace-pixel", "1", "1", SCENE, "--view-size", "0", "10"],
            "",
        ),
        (
            &["trace-pixel", "1", "1", SCENE, "--view-distance", "0"],
            "positive",
        ),
        (&["trace-pixel", "1", "1", SCENE, "--png", "out.jpg"], "jpg"),
        (
            &["trace-pixel", "1", "1", SCENE, "--json", SCENE],
            "same file as the input",
        ),
        (
            &[
                "trace-pixel",
                "1",
                "1",
                SCENE,
                "--obj",
                "a.obj",
                "--ply",
                "a.obj",
            ],
            "same file",
        ),
        (&["trace-pixel", "1", "1", SCENE, "--frobnicate"], ""),
        (
            &[
                "trace-pixel",
                "1",
                "1",
                SCENE,
                "--view-from",
                "1",
                "2",
                "3",
                "--view-from",
                "4",
                "5",
                "6",
            ],
            "cannot be used multiple times",
        ),
        // 4096 camera rays × 3 path segments × (1 + 65536 points): refused before tracing.
        (
            &[
                "trace-pixel",
                "1",
                "1",
                SCENE,
                "--aa",
                "4096",
                "--shadow-samples",
                "65536",
            ],
            "segments",
        ),
        // The debug eye straight above the point of interest: no direction the up axis orients.
        (
            &[
                "trace-pixel",
                "1",
                "1",
                SCENE,
                "--png",
                "v.png",
                "--view-from",
                "0",
                "5",
                "0",
            ],
            "up axis",
        ),
    ];
    for (args, fragment) in cases {
        let out = raywave(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(fragment),
            "{args:?}: {}",
            stderr(&out)
        );
        assert!(!stderr(&out).contains("panicked"), "{args:?}");
        assert_eq!(files_in(dir.path()), vec![SCENE.to_string()], "{args:?}");
    }
    // Debug-camera flags without --png: the run goes ahead, with a warning.
    let out = raywave(
        dir.path(),
        &[
            "trace-pixel",
            "1",
            "1",
            SCENE,
            "--size",
            "8",
            "8",
            "--orbit",
            "10",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--orbit has no effect without --png"),
        "{}",
        stderr(&out)
    );
    // A scene that does not parse: exit 1, naming the file.
    let out = raywave(dir.path(), &["trace-pixel", "0", "0", "missing.obj"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("missing.obj"));
}

/// The `raywave` commands of the ```sh blocks in docs/TRACE.md and README's debug view (with
/// `\` continuations joined).
fn documented_commands() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let trace = std::fs::read_to_string(root.join("docs/TRACE.md")).unwrap();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let start = readme.find("### The debug view").unwrap();
    let end = start + readme[start..].find("\n## ").unwrap();
    let mut out = Vec::new();
    for doc in [trace.as_str(), &readme[start..end]] {
        let mut in_sh = false;
        let mut pending = String::new();
        for line in doc.lines() {
            match line.trim() {
                "```sh" => in_sh = true,
                "```" => in_sh = false,
                l if in_sh => {
                    let (body, more) = match l.strip_suffix('\\') {
                        Some(b) => (b, true),
                        None => (l, false),
                    };
                    pending.push_str(body);
                    pending.push(' ');
                    if !more {
                        out.push(pending.trim().to_string());
                        pending.clear();
                    }
                }
                _ => {}
            }
        }
    }
    out
}

#[test]
fn the_documented_commands_run() {
    let commands = documented_commands();
    assert!(commands.len() >= 4, "{commands:?}");
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("scenes")).unwrap();
    std::fs::copy(
        common::bin::scenes().join(SCENE),
        dir.path().join("scenes").join(SCENE),
    )
    .unwrap();
    for command in &commands {
        let words: Vec<&str> = command.split_whitespace().collect();
        assert_eq!(words[0], "raywave", "{command}");
        let out = raywave(dir.path(), &words[1..]);
        assert!(out.status.success(), "{command}: {}", stderr(&out));
        // Every file the command names is there.
        for (i, w) in words.iter().enumerate() {
            if matches!(*w, "--json" | "--obj" | "--ply" | "--png" | "-o") {
                assert!(
                    dir.path().join(words[i + 1]).is_file(),
                    "{command}: {}",
                    words[i + 1]
                );
            }
        }
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
