//! `raywave trace-pixel`'s tree on scenes/trace_demo.obj (tests/commands/trace_demo/): the expected
//! segments come from the settings, the blocked flags from the test's own f64 geometry of the
//! scene file, and the colours from both engines' whole-image renders; then the JSON, the
//! summary, the schema, bad input and the documented commands. The exports are tested in
//! tests/commands/trace_pixel_exports.rs.

use crate::common;
use crate::trace_demo;

use common::bin::{dir_with, files_in, raywave, stderr, stdout};
use glam::{DVec3, Vec3};
use raywave::render::engine::Engine;
use raywave::render::progress::Progress;
use raywave::render::scene::Scene;
use raywave::render::settings::{RenderSettings, ShadowMode};
use raywave::trace::{RayTree, SegmentKind, trace_pixel};
use std::collections::BTreeMap;
use std::path::Path;
use trace_demo::{PIXEL, SCENE, d, demo, run, scene, settings};

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
    let rays = raywave::trace::check_pixel(&scene, &settings, &tree).rays;
    let expected = raywave::render::per_kind::RayCounts {
        camera: 1,
        reflection: 1,
        shadow: 32,
    };
    assert_eq!((rays.reference, rays.wavefront), (expected, expected));

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
        let (film, _) = engine.render(scene, settings, 256, &Progress::SILENT);
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
            sampler: raywave::render::sampling::LightSampler::Sobol,
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
        // Each engine counts, for this pixel, the rays the tree holds.
        let check = raywave::trace::check_pixel(&scene, settings, &tree);
        assert_eq!(check.rays.reference, check.rays.tree, "{settings:?}");
        assert_eq!(check.rays.wavefront, check.rays.tree, "{settings:?}");
        assert!(check.agrees, "{check:?}");
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
fn the_sum_check_fails_when_one_contribution_is_off_by_1e_4_of_the_pixel() {
    let (scene, settings) = (scene(), settings());
    let tree = trace_pixel(&scene, &settings, PIXEL.0, PIXEL.1).unwrap();
    let check = raywave::trace::check_pixel(&scene, &settings, &tree);
    assert!(check.agrees, "{check:?}");
    // The demo pixel is reddest (the red wall seen in the mirror): nudge a visible shadow
    // ray's red contribution by a fraction of the pixel's red. 1e-4 of it is about 3e-5, three
    // times the tolerance (1e-5 for a pixel below 1); 1e-7 of it is well inside.
    let red = f64::from(check.reference[0]);
    let visible = tree
        .segments
        .iter()
        .position(|s| s.shadow.as_ref().is_some_and(|i| i.blocked == Some(false)))
        .expect("a visible shadow ray");
    for (fraction, agrees) in [(1e-4, false), (1e-7, true)] {
        let mut nudged = tree.clone();
        nudged.segments[visible].contribution[0] += (fraction * red) as f32;
        let check = raywave::trace::check_pixel(&scene, &settings, &nudged);
        assert_eq!(
            check.agrees, agrees,
            "nudged by {fraction} of the pixel: {check:?}"
        );
        let over = |d: f64| d > check.tolerance;
        assert_eq!(over(check.reference_difference), !agrees, "{check:?}");
        assert_eq!(over(check.wavefront_difference), !agrees, "{check:?}");
        // The rays are the same ones: the sum alone decides.
        assert_eq!(check.rays.tree, check.rays.reference);
        assert_eq!(check.rays.tree, check.rays.wavefront);
    }
}

#[test]
fn the_ray_count_check_fails_when_a_shadow_segment_is_missing_or_doubled() {
    let (scene, settings) = (scene(), settings());
    let tree = trace_pixel(&scene, &settings, PIXEL.0, PIXEL.1).unwrap();
    // A blocked shadow ray adds nothing: without it, or with it twice, the sum is the same and
    // only the count can tell.
    let blocked = tree
        .segments
        .iter()
        .position(|s| s.shadow.as_ref().is_some_and(|i| i.blocked == Some(true)))
        .expect("a blocked shadow ray");
    let mut dropped = tree.clone();
    dropped.segments.remove(blocked);
    let mut doubled = tree.clone();
    doubled
        .segments
        .insert(blocked, tree.segments[blocked].clone());
    for (changed, shadow) in [(&dropped, 31), (&doubled, 33)] {
        let check = raywave::trace::check_pixel(&scene, &settings, changed);
        assert_eq!(check.rays.tree.shadow, shadow, "{check:?}");
        assert_eq!(check.rays.reference.shadow, 32, "{check:?}");
        assert_eq!(check.rays.wavefront.shadow, 32, "{check:?}");
        assert!(check.reference_difference <= check.tolerance, "{check:?}");
        assert!(check.wavefront_difference <= check.tolerance, "{check:?}");
        assert!(
            !check.agrees,
            "{shadow} shadow segments for 32 rays: {check:?}"
        );
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
    let path = Path::new(env!("RAYWAVE_REPO")).join("docs/schema/ray-tree.schema.json");
    let schema = schemars::schema_for!(RayTree);
    let generated = serde_json::to_string_pretty(&schema).unwrap() + "\n";
    if std::env::var_os("RAYWAVE_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let checked_in = std::fs::read_to_string(&path).expect("docs/schema/ray-tree.schema.json");
    assert_eq!(
        serde_json::from_str::<serde_json::Value>(&checked_in).unwrap(),
        serde_json::from_str::<serde_json::Value>(&generated).unwrap(),
        "docs/schema/ray-tree.schema.json is stale: run RAYWAVE_BLESS=1 cargo test --release --test commands trace_pixel::"
    );
    // Every field the tree writes is in the schema.
    let tree = trace_pixel(&scene(), &settings(), PIXEL.0, PIXEL.1).unwrap();
    let json = serde_json::to_value(&tree).unwrap();
    let properties = &serde_json::to_value(&schema).unwrap()["properties"];
    for key in json.as_object().unwrap().keys() {
        assert!(properties.get(key).is_some(), "{key} is not in the schema");
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
    let root = Path::new(env!("RAYWAVE_REPO"));
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

#[test]
fn a_ray_that_misses_ends_a_scene_diagonal_out_and_adds_the_background() {
    // Pixel (29, 32): the mirror sends the camera ray out of the open box.
    let tree = trace_pixel(&scene(), &settings(), 29, 32).unwrap();
    let reflection = tree
        .segments
        .iter()
        .find(|s| s.kind == SegmentKind::Reflection)
        .expect("the camera ray hits the mirror");
    assert!(reflection.hit.is_none(), "{reflection:?}");
    // The file's bounding box: x -2..3, y -1..3, z -2..3.
    let diagonal = (5.0f64 * 5.0 + 4.0 * 4.0 + 5.0 * 5.0).sqrt();
    let drawn = (d(reflection.end) - d(reflection.origin)).length();
    assert!((drawn - diagonal).abs() < 1e-4, "{drawn} vs {diagonal}");
    // White background times the mirror's kr, one aa sample.
    for c in 0..3 {
        assert!((f64::from(reflection.contribution[c]) - 0.85).abs() < 1e-6);
        assert!((f64::from(reflection.throughput[c]) - 0.85).abs() < 1e-6);
    }
    assert!(
        tree.segments
            .iter()
            .all(|s| s.parent != Some(reflection.id))
    );
}
