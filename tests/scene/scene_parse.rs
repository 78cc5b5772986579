//! The scene format (docs/SCENE_FORMAT.md): the lab's five seed scenes, every scene in
//! `scenes/`, and the extensions (comments, continuations, relative indices, polygons, the RPI
//! camera block and materials). Parse errors are in `scene_errors.rs`.

use crate::common;

use common::scenes::{WHITE_MATERIAL as MAT, error_at};
use glam::Vec3;
use raywave::render::scene::{LightShape, Scene, parse_scene_str};
use std::path::{Path, PathBuf};

/// Counts read off the five files by hand: (file, materials, quads, spheres, lights).
const SEED_COUNTS: &[(&str, usize, usize, usize, usize)] = &[
    ("cornell_box.obj", 5, 6, 0, 1),
    ("cornell_box_diffuse_sphere.obj", 6, 6, 1, 1),
    ("cornell_box_reflective_spheres.obj", 8, 6, 3, 1),
    ("l.obj", 2, 14, 0, 1),
    ("reflective_spheres.obj", 4, 2, 2, 1),
];

fn manifest_dir() -> PathBuf {
    PathBuf::from(env!("RAYWAVE_REPO"))
}

fn check_counts(dir: &Path) {
    for &(name, materials, quads, spheres, lights) in SEED_COUNTS {
        let path = dir.join(name);
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(scene.materials.len(), materials, "{name}: materials");
        assert_eq!(scene.quad_count, quads, "{name}: quads");
        assert_eq!(scene.face_count, quads, "{name}: faces (all quads)");
        assert_eq!(scene.triangles.len(), 2 * quads, "{name}: triangles");
        assert_eq!(scene.spheres.len(), spheres, "{name}: spheres");
        assert_eq!(scene.lights.len(), lights, "{name}: lights");
        assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
        assert!(
            !scene.camera_from_file,
            "{name}: the lab's files have no camera"
        );
    }
}

#[test]
fn seed_scenes_parse_with_the_right_counts() {
    let dir = manifest_dir().join("../shared/seed-scenes");
    if !dir.is_dir() {
        println!(
            "skipped: {} is absent, the lab's seed scenes cannot be checked",
            dir.display()
        );
        return;
    }
    check_counts(&dir);
}

#[test]
fn project_copies_of_the_seed_scenes_have_the_same_counts() {
    check_counts(&manifest_dir().join("scenes"));
}

#[test]
fn every_project_scene_loads() {
    let mut count = 0;
    for entry in std::fs::read_dir(manifest_dir().join("scenes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "obj") {
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(scene.primitive_count() > 0, "{}", path.display());
            count += 1;
        }
    }
    assert!(count >= 5, "scenes/ holds only {count} .obj files");
}

#[test]
fn seed_light_geometry_is_the_quad() {
    // reflective_spheres.obj: light quad (-6,10,6) (-6,10,4) (-4,10,4) (-4,10,6), a 2×2 square.
    let scene = Scene::load(&manifest_dir().join("scenes/reflective_spheres.obj")).unwrap();
    let light = &scene.lights[0];
    assert!((light.area - 4.0).abs() < 1e-6);
    assert!(light.centroid.distance(Vec3::new(-5.0, 10.0, 5.0)) < 1e-6);
    // Winding (-6,10,6) -> (-6,10,4) -> (-4,10,4): (0,0,-2) × (2,0,-2) = (0,-4,0): faces down.
    assert!(light.normal.distance(Vec3::NEG_Y) < 1e-6);
    assert!(
        (light.color - Vec3::splat(0.2 * 2.0 * 4.0))
            .abs()
            .max_element()
            < 1e-6
    );
    // Lab default camera: bbox x [-10,10], y [-1,10], z [-10,10] -> poi (0, 4.5, 0), extent 20.
    assert!(
        scene
            .camera
            .point_of_interest
            .distance(Vec3::new(0.0, 4.5, 0.0))
            < 1e-5
    );
    assert!(scene.camera.position.distance(Vec3::new(0.0, 4.5, 80.0)) < 1e-4);
    assert!((scene.camera.fov - 20f32.to_radians()).abs() < 1e-6);
}

#[test]
fn light_points_cover_the_whole_quad_uniformly() {
    // The lab's RandomPoint bug sampled a bow tie; a uniform map must put a quarter of a fine
    // grid of (u, v) into each quadrant of the light.
    let scene = Scene::load(&manifest_dir().join("scenes/reflective_spheres.obj")).unwrap();
    let light = &scene.lights[0];
    let mut quadrant = [0u32; 4];
    let n = 40;
    for a in 0..n {
        for b in 0..n {
            let p = light.point((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
            assert!((p.y - 10.0).abs() < 1e-5);
            assert!(
                (-6.0..=-4.0).contains(&p.x) && (4.0..=6.0).contains(&p.z),
                "{p}"
            );
            let q = (p.x > -5.0) as usize * 2 + (p.z > 5.0) as usize;
            quadrant[q] += 1;
        }
    }
    assert_eq!(quadrant, [400; 4]);
}

// ---------------------------------------------------------------------------------------------
// Extensions that must parse.

#[test]
fn unknown_keywords_warn_with_file_and_line() {
    let text = format!("{MAT}m 0\nfrobnicate 1 2\ns 0 0 0 1\nlight 3\n");
    let scene = parse_scene_str(&text, "f.obj").unwrap();
    assert_eq!(scene.spheres.len(), 1);
    let lines: Vec<String> = scene.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(scene.warnings.len(), 2, "{lines:?}");
    assert!(lines[0].starts_with("f.obj:7:") && lines[0].contains("frobnicate"));
    assert!(lines[1].starts_with("f.obj:9:") && lines[1].contains("light"));
}

#[test]
fn comments_continuations_and_ignored_keywords() {
    let text = "\
# a comment line
material # trailing comment
diffuse 0.5 0.25 1   # 5
reflective 0 0 0
emitted 0 0 0
glossiness 0.5#no space
o object
g group
usemtl whatever
mtllib x.mtl
s off
s 1
vn 0 0 1
m 0
v -1 -1 1  # 1
v 1 \\
  -1 \\
  1
v 1 1 1 # 3
vt 0.5 0.5
f 1 2 3
";
    let scene = parse_scene_str(text, "f.obj").unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.materials[0].diffuse, Vec3::new(0.5, 0.25, 1.0));
    assert_eq!(scene.materials[0].glossiness, 0.5);
    assert_eq!(scene.triangles.len(), 1);
    assert_eq!(scene.spheres.len(), 0);
    let t = &scene.triangles[0];
    assert_eq!(t.v0, Vec3::new(-1.0, -1.0, 1.0));
    assert_eq!(t.v0 + t.e1, Vec3::new(1.0, -1.0, 1.0));
    assert_eq!(t.v0 + t.e2, Vec3::new(1.0, 1.0, 1.0));
    assert!(t.normal.distance(Vec3::Z) < 1e-6);
}

#[test]
fn negative_relative_indices_and_slash_tokens() {
    let text =
        format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\nf 1/7/9 2//3 3/1\n");
    let scene = parse_scene_str(&text, "f.obj").unwrap();
    assert_eq!(scene.face_count, 2);
    assert_eq!(scene.quad_count, 1);
    assert_eq!(scene.triangles.len(), 3);
    let q = &scene.triangles[0];
    assert_eq!(q.v0, Vec3::ZERO);
    assert_eq!(q.v0 + q.e1, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(q.v0 + q.e2, Vec3::new(1.0, 1.0, 0.0));
    let q2 = &scene.triangles[1];
    assert_eq!(q2.v0 + q2.e1, Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(q2.v0 + q2.e2, Vec3::new(0.0, 1.0, 0.0));
    let t = &scene.triangles[2];
    assert_eq!(t.face, 1);
    assert_eq!(t.v0 + t.e2, Vec3::new(1.0, 1.0, 0.0));
    // Relative indices count from the vertices read so far, not the whole file.
    let text = format!("{MAT}m 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\n");
    let scene = parse_scene_str(&text, "f.obj").unwrap();
    assert_eq!(scene.triangles[0].v0 + scene.triangles[0].e2, Vec3::Y);
}

#[test]
fn triangles_and_convex_polygons_are_fan_triangulated() {
    // A regular hexagon of circumradius 1 in the z = 0 plane, CCW from +z: area 3√3/2.
    let mut text = format!("{MAT}m 0\n");
    for k in 0..6 {
        let a = k as f32 * std::f32::consts::PI / 3.0;
        text += &format!("v {} {} 0\n", a.cos(), a.sin());
    }
    text += "f 1 2 3 4 5 6\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 7 8 9\n";
    let scene = parse_scene_str(&text, "f.obj").unwrap();
    assert_eq!(scene.face_count, 2);
    assert_eq!(scene.quad_count, 0);
    assert_eq!(scene.triangles.len(), 4 + 1);
    let hex_area: f32 = scene.triangles[..4]
        .iter()
        .map(|t| 0.5 * t.e1.cross(t.e2).length())
        .sum();
    assert!((hex_area - 1.5 * 3f32.sqrt()).abs() < 1e-5, "{hex_area}");
    for t in &scene.triangles {
        assert!(t.normal.distance(Vec3::Z) < 1e-6);
    }
    assert_eq!(scene.triangles[4].face, 1);
}

#[test]
fn emissive_polygon_is_a_light_sampled_uniformly() {
    // An emissive hexagon: a fan light whose points all lie in the polygon, spread by area.
    let mut text = "material\nemitted 1 1 1\nm 0\n".to_string();
    for k in 0..6 {
        let a = k as f32 * std::f32::consts::PI / 3.0;
        text += &format!("v {} {} 0\n", a.cos(), a.sin());
    }
    text += "f 1 2 3 4 5 6\n";
    let scene = parse_scene_str(&text, "f.obj").unwrap();
    let light = &scene.lights[0];
    assert!(matches!(light.shape, LightShape::Fan { .. }));
    let area = 1.5 * 3f32.sqrt();
    assert!((light.area - area).abs() < 1e-5);
    assert!(light.centroid.length() < 1e-5, "{}", light.centroid);
    // Every point lies inside the hexagon, their mean is its centre, and their mean squared
    // radius is the uniform hexagon's 5/12 · R² (six equilateral triangles: R²/12 about each
    // centroid plus (R/√3)² to it), here R = 1.
    let n = 200;
    let mut mean = Vec3::ZERO;
    let mut r2 = 0.0;
    for a in 0..n {
        for b in 0..n {
            let p = light.point((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
            assert!(
                p.z.abs() < 1e-6 && p.truncate().length() <= 1.0 + 1e-5,
                "{p}"
            );
            mean += p;
            r2 += p.length_squared();
        }
    }
    let count = (n * n) as f32;
    assert!((mean / count).length() < 5e-3, "{}", mean / count);
    assert!((r2 / count - 5.0 / 12.0).abs() < 1e-2, "{}", r2 / count);
}

#[test]
fn materials_in_any_order_with_defaults_and_rpi_keys() {
    let text = "\
material
glossiness 0.3
emitted 0 0 0
reflective 0.1 0.2 0.3
diffuse 0.4 0.5 0.6
material
diffuse 1 0 0
material
roughness 0.7
diffuse 0 1 0
material
transmitted 0.1 0 0
reflective 0 0 0
m 3
s 0 0 0 1
";
    let scene = parse_scene_str(text, "f.obj").unwrap();
    let m = &scene.materials;
    assert_eq!(m.len(), 4);
    assert_eq!(m[0].diffuse, Vec3::new(0.4, 0.5, 0.6));
    assert_eq!(m[0].reflective, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(m[0].glossiness, 0.3);
    assert_eq!(m[1].glossiness, 0.0);
    assert_eq!(m[1].reflective, Vec3::ZERO);
    assert_eq!(m[1].emitted, Vec3::ZERO);
    assert_eq!(m[2].glossiness, 0.7);
    assert_eq!(m[3].diffuse, Vec3::ZERO);
    // RPI's refraction colour is read and, being non-zero, reported as not rendered.
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = scene.warnings[0].to_string();
    assert!(
        w.starts_with("f.obj:12:") && w.contains("transmitted"),
        "{w}"
    );
}

#[test]
fn background_color_is_read() {
    let text = format!("{MAT}m 0\ns 0 0 0 1\nbackground_color 0.2 0.1 0.6\n");
    let scene = parse_scene_str(&text, "f.obj").unwrap();
    assert_eq!(scene.background, Some(Vec3::new(0.2, 0.1, 0.6)));
}

#[test]
fn camera_block_with_angle_brackets_and_radians_or_degrees() {
    let body = format!("{MAT}m 0\ns 0 0 0 1\n");
    let radians = format!(
        "{body}PerspectiveCamera {{\n  camera_position    5.3406 2.02057 5.92681\n  point_of_interest  1.3208 0.388196 0.955876\n  up                 0 1 0\n  angle              0.349066\n}}\n"
    );
    let degrees = format!(
        "{body}PerspectiveCamera\n{{\n  camera_position < 5.3406, 2.02057, 5.92681 >\n  point_of_interest <1.3208,0.388196,0.955876>\n  up < 0, 1, 0 >\n  angle 20\n}}\n"
    );
    let a = parse_scene_str(&radians, "f.obj").unwrap();
    let b = parse_scene_str(&degrees, "f.obj").unwrap();
    for s in [&a, &b] {
        assert!(s.camera_from_file);
        assert_eq!(s.camera.position, Vec3::new(5.3406, 2.02057, 5.92681));
        assert_eq!(
            s.camera.point_of_interest,
            Vec3::new(1.3208, 0.388196, 0.955876)
        );
        assert_eq!(s.camera.up, Vec3::Y);
        assert!((s.camera.fov - 0.349066).abs() < 1e-5, "{}", s.camera.fov);
    }
    // A wide radian angle just below π stays radians; just above is degrees.
    let wide = body.clone()
        + "PerspectiveCamera {\ncamera_position 0 0 5\npoint_of_interest 0 0 0\nangle 3.0\n}\n";
    let s = parse_scene_str(&wide, "f.obj").unwrap();
    assert!((s.camera.fov - 3.0).abs() < 1e-6);
    let deg = body.clone()
        + "PerspectiveCamera {\ncamera_position 0 0 5\npoint_of_interest 0 0 0\nangle 4\n}\n";
    let s = parse_scene_str(&deg, "f.obj").unwrap();
    assert!((s.camera.fov - 4f32.to_radians()).abs() < 1e-6);
    // Lines after the block parse normally.
    let after = degrees + "frob\n";
    let s = parse_scene_str(&after, "f.obj").unwrap();
    assert_eq!(s.warnings.len(), 1);
    assert!(s.warnings[0].to_string().starts_with("f.obj:15:"));
}

#[test]
fn lab_camera_frames_the_bounding_box() {
    // A triangle spanning x [-1, 3], y [0, 1] at z = -2, plus a sphere reaching z = 1: the box
    // is x [-1, 3], y [0, 1], z [-2, 1], centre (1, 0.5, -0.5), largest extent 4 (along x).
    let text = format!("{MAT}m 0\nv -1 0 -2\nv 3 0 -2\nv 3 1 -2\nf 1 2 3\ns 0 0.5 0.5 0.5\n");
    let s = parse_scene_str(&text, "f.obj").unwrap();
    assert!(!s.camera_from_file);
    assert!(
        s.camera
            .point_of_interest
            .distance(Vec3::new(1.0, 0.5, -0.5))
            < 1e-6
    );
    assert!(
        s.camera.position.distance(Vec3::new(1.0, 0.5, 15.5)) < 1e-5,
        "{}",
        s.camera.position
    );
    assert_eq!(s.camera.up, Vec3::Y);
}

/// What a scene file holds, counted by hand from the file.
struct Contents {
    name: &'static str,
    materials: usize,
    faces: usize,
    quads: usize,
    triangles: usize,
    spheres: usize,
    lights: usize,
    camera_from_file: bool,
}

#[test]
fn the_projects_own_scenes_have_the_expected_contents() {
    // A scene not (yet) in scenes/ is skipped.
    let expected = [
        Contents {
            name: "two_lights.obj",
            materials: 8,
            faces: 7,
            quads: 7,
            triangles: 14,
            spheres: 2,
            lights: 2,
            camera_from_file: false,
        },
        Contents {
            name: "camera_block.obj",
            materials: 5,
            faces: 6,
            quads: 6,
            triangles: 12,
            spheres: 2,
            lights: 1,
            camera_from_file: true,
        },
        Contents {
            name: "mesh_spheres_small.obj",
            materials: 8,
            faces: 390,
            quads: 294,
            triangles: 2 * 294 + 96,
            spheres: 0,
            lights: 1,
            camera_from_file: false,
        },
    ];
    for want in &expected {
        let name = want.name;
        let path = manifest_dir().join("scenes").join(name);
        if !path.exists() {
            println!("skipped: scenes/{name} is absent");
            continue;
        }
        let s = Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s.materials.len(), want.materials, "{name}");
        assert_eq!(s.face_count, want.faces, "{name}");
        assert_eq!(s.quad_count, want.quads, "{name}");
        assert_eq!(s.triangles.len(), want.triangles, "{name}");
        assert_eq!(s.spheres.len(), want.spheres, "{name}");
        assert_eq!(s.lights.len(), want.lights, "{name}");
        assert_eq!(s.camera_from_file, want.camera_from_file, "{name}");
        assert!(s.warnings.is_empty(), "{name}: {:?}", s.warnings);
        if name == "camera_block.obj" {
            assert_eq!(s.camera.position, Vec3::new(0.7, 0.35, 4.2));
            assert_eq!(s.camera.point_of_interest, Vec3::new(0.0, -0.25, 0.0));
            assert_eq!(s.camera.fov, 0.6, "0.6 < π: radians");
            assert_eq!(s.background, Some(Vec3::new(0.05, 0.05, 0.1)));
            assert_eq!(s.materials[2].glossiness, 0.05, "roughness");
        }
    }
}

#[test]
fn a_utf8_byte_order_mark_is_not_part_of_the_first_keyword() {
    // Editors on Windows save UTF-8 with a BOM; the first line is still `material`.
    let text = format!("\u{feff}{MAT}m 0\ns 0 0 0 1\n");
    let scene = parse_scene_str(&text, "f.obj").unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.materials[0].diffuse, Vec3::ONE);
}

#[test]
fn crlf_line_endings_and_tabs() {
    let text = format!("{MAT}m 0\r\nv\t0 0 0\r\nv 1 0 \\\r\n0\r\nv 0 1 0\r\nf 1\t2 3\r\n")
        .replace('\n', "\r\n");
    let scene = parse_scene_str(&text, "f.obj").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 1);
    assert_eq!(scene.triangles[0].v0 + scene.triangles[0].e1, Vec3::X);
}

#[test]
fn camera_block_with_center_and_direction() {
    // The other RPI spelling: `center` for the position and `direction` instead of a point.
    let text = format!(
        "{MAT}m 0\ns 0 0 0 1\nPerspectiveCamera {{ center 0 1 10 direction 0 0 -2 up 0 1 0 angle 30 }}\n"
    );
    let s = parse_scene_str(&text, "f.obj").unwrap();
    assert_eq!(s.camera.position, Vec3::new(0.0, 1.0, 10.0));
    assert_eq!(s.camera.point_of_interest, Vec3::new(0.0, 1.0, 8.0));
    assert!((s.camera.fov - 30f32.to_radians()).abs() < 1e-6);
    // A second camera block is an error naming its line.
    let twice = format!("{text}PerspectiveCamera {{ center 0 1 10 direction 0 0 -2 angle 30 }}\n");
    error_at(&twice, 9, &["camera"]);
    // Up parallel to the view direction.
    let bad = format!(
        "{MAT}m 0\ns 0 0 0 1\nPerspectiveCamera {{ center 0 5 0 direction 0 -1 0 up 0 1 0 angle 30 }}\n"
    );
    error_at(&bad, 8, &["up"]);
}

#[test]
fn a_non_convex_polygon_is_loaded_with_a_warning() {
    // A dart (0,0) (2,1) (0,2) (1,1): fanned from (0,0), its second triangle (0,0) (0,2) (1,1)
    // winds the other way, so the fan overlaps itself. The square after it is convex.
    let scene = raywave::render::scene::parse_scene_str(
        "material\ndiffuse 1 1 1\n\
         v 0 0 0\nv 2 1 0\nv 0 2 0\nv 1 1 0\n\
         v 3 0 0\nv 4 0 0\nv 4 1 0\nv 3 1 0\n\
         m 0\nf 1 2 3 4\nf 5 6 7 8\n",
        "dart.obj",
    )
    .unwrap();
    let warnings: Vec<String> = scene.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("dart.obj:12:") && warnings[0].contains("non-convex"),
        "{warnings:?}"
    );
}
