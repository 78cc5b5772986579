//! Textures through the binary: `trace-pixel` reports the texel colour a hit used, seen directly
//! and in a mirror, checked against a lookup written here from the PPM file (not raywave's); a
//! texture outside the scene's folder renders and the summary shows where it was read from.

use crate::common;

use common::bin::{raywave, scenes, stderr, stdout};

/// The asymmetric test texture's texels in linear colour, row 0 at the bottom (t = 0): read by
/// this test's own P3 reader and sRGB curve.
fn asymmetric_texels() -> (usize, usize, Vec<[f64; 3]>) {
    let text = std::fs::read_to_string(scenes().join("textures/asymmetric.ppm")).unwrap();
    let words: Vec<&str> = text
        .lines()
        .map(|l| l.split('#').next().unwrap())
        .flat_map(str::split_whitespace)
        .collect();
    assert_eq!(words[0], "P3");
    let (w, h): (usize, usize) = (words[1].parse().unwrap(), words[2].parse().unwrap());
    let max: f64 = words[3].parse().unwrap();
    let linear = |c: f64| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let sample = |k: usize| linear(words[4 + k].parse::<f64>().unwrap() / max);
    let mut texels = Vec::new();
    for row in (0..h).rev() {
        for col in 0..w {
            let at = 3 * (row * w + col);
            texels.push([sample(at), sample(at + 1), sample(at + 2)]);
        }
    }
    (w, h, texels)
}

/// RPI's bilinear lookup at (s, t) for coordinates inside [0, 1).
fn lookup(s: f64, t: f64) -> [f64; 3] {
    let (w, h, texels) = asymmetric_texels();
    let (x, y) = (s * w as f64, t * h as f64);
    let (i, j) = (x.floor() as usize, y.floor() as usize);
    let (dx, dy) = (x - i as f64, y - j as f64);
    let (i2, j2) = ((i + 1).min(w - 1), (j + 1).min(h - 1));
    let c = |i: usize, j: usize| texels[j * w + i];
    std::array::from_fn(|a| {
        c(i, j)[a] * (1.0 - dx) * (1.0 - dy)
            + c(i, j2)[a] * (1.0 - dx) * dy
            + c(i2, j)[a] * dx * (1.0 - dy)
            + c(i2, j2)[a] * dx * dy
    })
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap()
}

/// The segments of pixel (x, y)'s tree in textured_box.obj at 64 × 64 without shadows.
fn segments(x: &str, y: &str) -> Vec<serde_json::Value> {
    let scene = scenes().join("textured_box.obj");
    let args = [
        "trace-pixel",
        x,
        y,
        scene.to_str().unwrap(),
        "--size",
        "64",
        "64",
        "--shadows",
        "off",
        "--json",
        "-",
    ];
    let out = raywave(&scenes(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let tree: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    tree["segments"].as_array().unwrap().clone()
}

/// The one segment of `kind` whose hit is textured: its (s, t) agrees with `st_of(point)` and its
/// kd with this file's lookup there.
fn check_textured_hit(segments: &[serde_json::Value], kind: &str, st_of: fn([f64; 3]) -> [f64; 2]) {
    let seg = segments
        .iter()
        .find(|s| s["kind"] == kind && !s["hit"]["texture"].is_null())
        .unwrap_or_else(|| panic!("no textured {kind} hit in {segments:#?}"));
    let hit = &seg["hit"];
    assert_eq!(hit["texture"]["name"], "textures/asymmetric.ppm");
    let point = [0, 1, 2].map(|a| f(&hit["point"][a]));
    let st = [f(&hit["texture"]["st"][0]), f(&hit["texture"]["st"][1])];
    let expected = st_of(point);
    assert!(
        (st[0] - expected[0]).abs() < 1e-5 && (st[1] - expected[1]).abs() < 1e-5,
        "{kind}: (s, t) {st:?} at {point:?}, expected {expected:?}"
    );
    let kd = lookup(expected[0], expected[1]);
    for a in 0..3 {
        let got = f(&hit["diffuse"][a]);
        assert!(
            (got - kd[a]).abs() < 1e-5,
            "{kind}: kd {:?}, expected {kd:?}",
            hit["diffuse"]
        );
        // The hit's own term is throughput ⊙ ambient (0.2) ⊙ the texel's kd.
        let term = f(&seg["throughput"][a]) * 0.2 * kd[a];
        assert!(
            (f(&seg["contribution"][a]) - term).abs() < 1e-5,
            "{kind}: {seg:#?}"
        );
    }
}

#[test]
fn trace_pixel_reports_the_texel_a_hit_used() {
    // The back wall: s = x + 1 (0 to 2 across it), t = (y + 1) / 2.
    check_textured_hit(&segments("20", "20"), "camera", |p| {
        [p[0] + 1.0, (p[1] + 1.0) / 2.0]
    });
}

#[test]
fn trace_pixel_reports_the_texel_seen_in_a_mirror() {
    // The mirror sphere's lower half shows the floor: s = (x + 1) / 2, t = (1 − z) / 2.
    check_textured_hit(&segments("40", "52"), "reflection", |p| {
        [(p[0] + 1.0) / 2.0, (1.0 - p[2]) / 2.0]
    });
}

#[test]
fn a_texture_outside_the_scene_folder_renders_and_is_named_in_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("scenes");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(dir.path().join("shared.ppm"), "P3\n1 1\n255\n255 128 0\n").unwrap();
    std::fs::write(
        sub.join("floor.obj"),
        "material\ntexture_file ../shared.ppm\nmaterial\nemitted 1 1 1\n\
         v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv 0 1 0\nv 0.2 1 0\nv 0 1 0.2\n\
         m 0\nf 1 4 3 2\nm 1\nf 5 7 6\n",
    )
    .unwrap();
    let out = raywave(&sub, &["floor.obj", "--size", "8", "8", "-o", "floor.png"]);
    let text = stdout(&out) + &stderr(&out);
    assert!(out.status.success(), "{text}");
    let resolved = dir.path().canonicalize().unwrap().join("shared.ppm");
    let line = format!(
        "texture ../shared.ppm: 1×1 texels from {} (outside the scene file's folder)",
        resolved.display()
    );
    assert!(text.contains(&line), "no `{line}` in:\n{text}");
    // The face without `vt` is warned about: it takes texel (0, 0).
    assert!(text.contains("floor.obj:13: warning"), "{text}");
    assert!(sub.join("floor.png").is_file());
}
