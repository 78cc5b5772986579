//! `render --cost-map`: the map is the same bytes whatever the thread count and from run to
//! run; its flags' errors are usage errors (exit 2) naming the flag; the map is refused where
//! it would overwrite an input (the scene, a texture) or another output, as `-o` is; and
//! `--stats-json` carries the traversal counters.

use crate::common;

use common::bin::{dir_with, files_in, raywave, scenes, stderr};
use std::path::Path;

/// The mesh scene (684 triangles: the mesh BVH), small, on several tiles, soft shadows and a
/// bounce, with `threads` rayon threads.
fn cost_map(dir: &Path, threads: &str, map: &str, extra: &[&str]) -> Vec<u8> {
    let out = std::process::Command::new(crate::common::bin::exe())
        .args([
            "render",
            "mesh_spheres_small.obj",
            "--size",
            "40",
            "24",
            "--bounces",
            "1",
            "--shadow-samples",
            "4",
            "--batch-size",
            "64",
            "-q",
            "-o",
            "r.png",
            "--cost-map",
            map,
        ])
        .args(extra)
        .env("RAYON_NUM_THREADS", threads)
        .current_dir(dir)
        .output()
        .expect("run raywave");
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::read(dir.join(map)).unwrap()
}

#[test]
fn the_cost_map_is_the_same_bytes_on_one_thread_and_two() {
    let dir = dir_with(&["mesh_spheres_small.obj"]);
    let one = cost_map(dir.path(), "1", "one.png", &["--stats-json", "one.json"]);
    let two = cost_map(dir.path(), "2", "two.png", &["--stats-json", "two.json"]);
    let again = cost_map(dir.path(), "2", "again.png", &[]);
    // The thread counts took effect.
    let threads = |name: &str| {
        let text = std::fs::read_to_string(dir.path().join(name)).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()["threads"].clone()
    };
    assert_eq!(
        (threads("one.json"), threads("two.json")),
        (1.into(), 2.into())
    );
    assert!(one == two, "the cost map differs between 1 and 2 threads");
    assert!(two == again, "the cost map differs between two runs");
    let map = image::load_from_memory(&one).expect("a PNG").to_rgb8();
    // Two panels (nodes, tests), each the 40×24 map upscaled to 256 rows plus its bar.
    assert!(
        map.width() > 2 * 40 * 10 && map.height() > 24 * 10,
        "{:?}",
        map.dimensions()
    );
    // The counters agree with the map's source: every ray of a mesh scene visits the root.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("one.json")).unwrap())
            .unwrap();
    let t = &json["traversal"];
    for kind in ["camera", "shadow", "reflection"] {
        let (rays, nodes) = (t[kind]["rays"].as_u64(), t[kind]["nodes"].as_u64());
        assert_eq!(rays, json["rays"][kind]["rays"].as_u64(), "{kind}");
        assert!(nodes >= rays, "{kind}: {}", t[kind]);
        assert!(
            t[kind]["primitive_tests_per_ray"].as_f64() > Some(0.0),
            "{kind}"
        );
    }
    assert!(t["counted_seconds"].as_f64() > Some(0.0));
    // Each kind and measure is a map of its own.
    let shadow = cost_map(dir.path(), "2", "s.png", &["--cost-kind", "shadow"]);
    let nodes = cost_map(dir.path(), "2", "n.png", &["--cost-measure", "nodes"]);
    assert!(shadow != one && nodes != one);
}

#[test]
fn the_cost_map_flags_are_usage_errors_when_wrong() {
    let dir = dir_with(&["cornell_box.obj"]);
    let base = ["cornell_box.obj", "--size", "8", "8", "-q", "-o", "r.png"];
    let cases: &[(&[&str], &str)] = &[
        (
            &["--cost-map", "c.png", "--cost-kind", "sideways"],
            "--cost-kind",
        ),
        (
            &["--cost-map", "c.png", "--cost-measure", "time"],
            "--cost-measure",
        ),
        (&["--cost-kind", "shadow"], "--cost-map"),
        (
            &["--cost-map", "c.png", "--engine", "reference"],
            "--cost-map",
        ),
        (
            &["--cost-map", "c.txt"],
            "--cost-map c.txt: expected a file ending in .png",
        ),
        (&["--cost-map", "r.png"], "--cost-map r.png"),
    ];
    for (args, flag) in cases {
        let out = raywave(dir.path(), &[&base[..], args].concat());
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?} should name {flag}: {err}");
        assert_eq!(files_in(dir.path()), ["cornell_box.obj"], "{args:?}");
    }
    // The scene itself, under a name a cost map may have, as `-o` is refused.
    std::fs::rename(
        dir.path().join("cornell_box.obj"),
        dir.path().join("box.png"),
    )
    .unwrap();
    let out = raywave(
        dir.path(),
        &[
            "box.png",
            "--size",
            "8",
            "8",
            "-q",
            "-o",
            "r.png",
            "--cost-map",
            "./box.png",
        ],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--cost-map ./box.png is the same file as the input SCENE box.png"),
        "{err}"
    );
    assert_eq!(files_in(dir.path()), ["box.png"]);
    let scene = std::fs::read(dir.path().join("box.png")).unwrap();
    assert_eq!(
        scene,
        std::fs::read(scenes().join("cornell_box.obj")).unwrap()
    );
}

#[test]
fn the_cost_map_is_never_the_scenes_texture() {
    let dir = dir_with(&[]);
    let d = dir.path();
    std::fs::create_dir(d.join("textures")).unwrap();
    std::fs::copy(
        scenes().join("textures/asymmetric.ppm"),
        d.join("textures/asymmetric.ppm"),
    )
    .unwrap();
    std::fs::copy(scenes().join("textured_box.obj"), d.join("box.obj")).unwrap();
    let texture = std::fs::read(d.join("textures/asymmetric.ppm")).unwrap();
    let out = raywave(
        d,
        &[
            "box.obj",
            "--size",
            "8",
            "8",
            "-q",
            "-o",
            "r.png",
            "--cost-map",
            "textures/asymmetric.ppm",
        ],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "--cost-map textures/asymmetric.ppm is the same file as the input SCENE's texture_file"
        ),
        "{err}"
    );
    assert_eq!(
        std::fs::read(d.join("textures/asymmetric.ppm")).unwrap(),
        texture
    );
    assert_eq!(files_in(d), ["box.obj", "textures"]);
}
