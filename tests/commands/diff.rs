//! `raywave diff` and `render --mse-reference` on tiny images this test writes itself (PFM and
//! PPM by hand, PNG through `image`, EXR through `exr`), against figures worked out by hand.

use crate::common;

use common::bin::{raywave, stderr, stdout};
use raywave::output::false_colour::{MIN_SIDE, inferno};
use serde_json::Value;
use std::path::Path;

/// A colour PFM as the format defines it: little-endian (negative scale), rows bottom to top.
fn write_pfm(path: &Path, width: usize, pixels: &[[f32; 3]]) {
    let height = pixels.len() / width;
    let mut bytes = format!("PF\n{width} {height}\n-1.0\n").into_bytes();
    for row in pixels.chunks(width).rev() {
        for p in row {
            for v in p {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// An 8-bit PNG through the `image` crate.
fn write_png(path: &Path, width: u32, pixels: &[[u8; 3]]) {
    let height = pixels.len() as u32 / width;
    let raw: Vec<u8> = pixels.iter().flatten().copied().collect();
    image::RgbImage::from_raw(width, height, raw)
        .unwrap()
        .save_with_format(path, image::ImageFormat::Png)
        .unwrap();
}

/// The 2×2 pair of the hand-worked figures (row-major: (0,0), (1,0), (0,1), (1,1)).
/// Differences a − b: R +0.5 at (0,0); G +0.25 at (1,0); B −0.5 at (0,1) and +0.25 at (1,1).
const A: [[f32; 3]; 4] = [
    [0.5, 0.0, 0.0],
    [0.0, 0.25, 0.0],
    [0.0, 0.0, 0.0],
    [1.0, 1.0, 1.0],
];
const B: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0],
    [0.0, 0.0, 0.5],
    [1.0, 1.0, 0.75],
];

fn pair() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    write_pfm(&dir.path().join("a.pfm"), 2, &A);
    write_pfm(&dir.path().join("b.pfm"), 2, &B);
    dir
}

/// Runs `raywave diff ARGS --json -` and parses the JSON; asserts the exit code.
fn diff_json(dir: &Path, args: &[&str], code: i32) -> Value {
    let mut all = vec!["diff"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--json", "-"]);
    let out = raywave(dir, &all);
    assert_eq!(
        out.status.code(),
        Some(code),
        "{all:?}:\n{}\n{}",
        stdout(&out),
        stderr(&out)
    );
    serde_json::from_str(&stdout(&out)).unwrap()
}

fn close(got: &Value, want: f64) {
    let got = got
        .as_f64()
        .unwrap_or_else(|| panic!("not a number: {got}"));
    assert!(
        (got - want).abs() <= 1e-12 * want.abs().max(1e-300),
        "got {got}, want {want}"
    );
}

#[test]
fn figures_match_the_hand_worked_values() {
    let dir = pair();
    let j = diff_json(dir.path(), &["a.pfm", "b.pfm"], 0);
    let ch = |c: usize, key: &str| j["channels"][c][key].clone();
    // MSE: R 0.5²/4, G 0.25²/4, B (0.5² + 0.25²)/4; all: the 12 squares / 12.
    close(&ch(0, "mse"), 0.0625);
    close(&ch(1, "mse"), 0.015625);
    close(&ch(2, "mse"), 0.078125);
    close(&j["all"]["mse"], 0.625 / 12.0);
    // relMSE: d² / (b + 0.01)², b the reference.
    close(&ch(0, "relmse"), 0.25 / (0.01 * 0.01) / 4.0);
    close(&ch(1, "relmse"), 0.0625 / (0.01 * 0.01) / 4.0);
    let rel_b = (0.25 / (0.51 * 0.51) + 0.0625 / (0.76 * 0.76)) / 4.0;
    close(&ch(2, "relmse"), rel_b);
    close(
        &j["all"]["relmse"],
        (2500.0 + 625.0 + 0.25 / (0.51 * 0.51) + 0.0625 / (0.76 * 0.76)) / 12.0,
    );
    // Largest |a − b| and where: the first in row-major order on a tie (R at (0,0) beats B at
    // (0,1)).
    close(&ch(0, "max_abs"), 0.5);
    assert_eq!(ch(1, "max_at"), serde_json::json!([1, 0]));
    assert_eq!(ch(2, "max_at"), serde_json::json!([0, 1]));
    assert_eq!(j["all"]["max_at"], serde_json::json!([0, 0]));
    // PSNR = 10 log10(1 / MSE).
    close(&ch(0, "psnr"), 10.0 * 16f64.log10());
    close(&j["all"]["psnr"], 10.0 * (12.0f64 / 0.625).log10());
    assert_eq!(j["pixels_compared"], 4);
    assert_eq!(j["region_pixels"], 4);
}

#[test]
fn the_table_says_the_figures_are_exact_and_how_psnr_is_taken() {
    let dir = pair();
    let out = raywave(dir.path(), &["diff", "a.pfm", "b.pfm"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    for needle in [
        "all ",
        "5.208e-2",
        "no sampling error",
        "(b+0.01)²",
        "10·log10(1²/MSE)",
    ] {
        assert!(text.contains(needle), "`{needle}` missing:\n{text}");
    }
    // B stays within [0, 1]: no HDR warning about PSNR's peak.
    assert!(!text.contains("HDR"), "{text}");
    write_pfm(&dir.path().join("hdr.pfm"), 2, &[[4.0; 3]; 4]);
    let out = raywave(dir.path(), &["diff", "a.pfm", "hdr.pfm"]);
    assert!(
        stdout(&out).contains("B reaches 4.0000 > 1 (HDR)"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn identical_images_give_zero_and_infinite_psnr() {
    let dir = pair();
    let j = diff_json(dir.path(), &["a.pfm", "a.pfm"], 0);
    for key in ["mse", "relmse", "max_abs"] {
        assert_eq!(j["all"][key], 0.0, "{key}");
    }
    // JSON has no infinity: an infinite PSNR is null.
    assert!(j["all"]["psnr"].is_null());
    let out = raywave(dir.path(), &["diff", "a.pfm", "a.pfm"]);
    let all = stdout(&out)
        .lines()
        .find(|l| l.starts_with("all"))
        .unwrap()
        .to_string();
    assert!(all.trim_end().ends_with("inf"), "{all}");
}

#[test]
fn mismatched_sizes_and_unreadable_files_are_refused_by_name() {
    let dir = pair();
    write_pfm(&dir.path().join("wide.pfm"), 4, &[[0.0; 3]; 4]);
    let out = raywave(dir.path(), &["diff", "a.pfm", "wide.pfm"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("A a.pfm is 2×2 but B wide.pfm is 4×1"),
        "{err}"
    );
    let out = raywave(dir.path(), &["diff", "a.pfm", "missing.png"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("cannot read missing.png"),
        "{}",
        stderr(&out)
    );
    std::fs::write(dir.path().join("junk.png"), b"not an image at all").unwrap();
    let out = raywave(dir.path(), &["diff", "junk.png", "a.pfm"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("junk.png: not a readable PNG image"),
        "{}",
        stderr(&out)
    );
    std::fs::write(dir.path().join("bad.pfm"), b"PF\n2 2\n-1.0\n\x00\x00").unwrap();
    let out = raywave(dir.path(), &["diff", "bad.pfm", "a.pfm"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("bad.pfm"), "{}", stderr(&out));
    let out = raywave(dir.path(), &["diff", "a.pfm", "."]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("it is a directory"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn every_format_loads_to_the_same_values() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bytes: [[u8; 3]; 6] = [
        [0, 0, 0],
        [255, 255, 255],
        [1, 128, 254],
        [17, 34, 51],
        [200, 100, 50],
        [9, 90, 190],
    ];
    write_png(&d.join("ref.png"), 3, &bytes);
    let mut ppm = b"P6\n3 2\n255\n".to_vec();
    ppm.extend(bytes.iter().flatten());
    std::fs::write(d.join("a.ppm"), ppm).unwrap();
    let raw16: Vec<u16> = bytes.iter().flatten().map(|&v| v as u16 * 257).collect();
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(3, 2, raw16)
        .unwrap()
        .save(d.join("a16.png"))
        .unwrap();
    let floats: Vec<[f32; 3]> = bytes.iter().map(|p| p.map(|v| v as f32 / 255.0)).collect();
    write_pfm(&d.join("a.pfm"), 3, &floats);
    exr::prelude::write_rgb_file(d.join("a.exr"), 3, 2, |x, y| {
        let p = floats[y * 3 + x];
        (p[0], p[1], p[2])
    })
    .unwrap();
    for (file, format, encoding) in [
        ("a.ppm", "PPM", "8-bit"),
        ("a16.png", "PNG", "16-bit"),
        ("a.pfm", "PFM", "float"),
        ("a.exr", "EXR", "float"),
    ] {
        let j = diff_json(d, &[file, "ref.png"], 0);
        assert_eq!(j["a"]["format"], format);
        assert_eq!(j["a"]["encoding"], encoding);
        assert_eq!(j["b"]["encoding"], "8-bit");
        let mse = j["all"]["mse"].as_f64().unwrap();
        assert!(mse < 1e-12, "{file}: MSE {mse}");
    }
    // And a real difference is seen through each reader: one byte off by 51.
    let mut off = bytes;
    off[3][2] = 0;
    write_png(&d.join("off.png"), 3, &off);
    let j = diff_json(d, &["a.exr", "off.png"], 0);
    // 51/255 as an f32, as the readers hold it.
    close(&j["channels"][2]["max_abs"], (51.0f32 / 255.0) as f64);
    assert_eq!(j["all"]["max_at"], serde_json::json!([0, 1]));
}

#[test]
fn fail_above_exits_3_past_the_threshold_and_0_within() {
    let dir = pair();
    let d = dir.path();
    let all_mse = 0.625 / 12.0;
    let all_psnr = 10.0 * (12.0f64 / 0.625).log10(); // 12.83 dB
    let cases: [(&[&str], i32); 8] = [
        (&["--fail-above", "0.06"], 0),
        (&["--fail-above", "0.05"], 3),
        (&["--metric", "max", "--fail-above", "0.5"], 0),
        (&["--metric", "max", "--fail-above", "0.49"], 3),
        (&["--metric", "psnr", "--fail-above", "12.8"], 0),
        (&["--metric", "psnr", "--fail-above", "12.9"], 3),
        // (2500 + 625 + 0.25/0.51² + 0.0625/0.76²) / 12 = 260.5
        (&["--metric", "relmse", "--fail-above", "260"], 3),
        (&["--metric", "relmse", "--fail-above", "261"], 0),
    ];
    assert!(all_mse > 0.05 && all_mse < 0.06 && all_psnr > 12.8 && all_psnr < 12.9);
    for (flags, code) in cases {
        let mut args = vec!["a.pfm", "b.pfm"];
        args.extend_from_slice(flags);
        let j = diff_json(d, &args, code);
        assert_eq!(j["failed"], code == 3, "{flags:?}");
    }
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--fail-above", "0.05"]);
    assert!(stdout(&out).contains("FAIL     mse"), "{}", stdout(&out));
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--fail-above", "nan"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_mask_file_restricts_every_figure() {
    let dir = pair();
    let d = dir.path();
    // Inside: (0,0) and (1,1).
    write_png(
        &d.join("mask.png"),
        2,
        &[[255, 255, 255], [0, 0, 0], [0, 0, 0], [0, 0, 7]],
    );
    let j = diff_json(d, &["a.pfm", "b.pfm", "--mask", "mask.png"], 0);
    assert_eq!(j["region_pixels"], 2);
    assert_eq!(j["pixels_compared"], 2);
    close(&j["channels"][0]["mse"], 0.25 / 2.0);
    close(&j["channels"][1]["mse"], 0.0);
    close(&j["channels"][2]["mse"], 0.0625 / 2.0);
    close(&j["all"]["mse"], 0.3125 / 6.0);
    assert_eq!(j["channels"][2]["max_at"], serde_json::json!([1, 1]));
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--mask", "mask.png"]);
    assert!(
        stdout(&out).contains("2 of 4 pixels (50.0%)"),
        "{}",
        stdout(&out)
    );
    // An empty mask compares nothing: an error, not a 0.
    write_png(&d.join("empty.png"), 2, &[[0, 0, 0]; 4]);
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--mask", "empty.png"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("no pixel to compare"),
        "{}",
        stderr(&out)
    );
    write_png(&d.join("big.png"), 3, &[[1, 1, 1]; 3]);
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--mask", "big.png"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--mask big.png is 3×1"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn a_mask_file_named_penumbra_is_read_through_its_path() {
    let dir = pair();
    let d = dir.path();
    write_png(
        &d.join("penumbra"),
        2,
        &[[0, 0, 0], [9, 9, 9], [0, 0, 0], [0, 0, 0]],
    );
    let j = diff_json(d, &["a.pfm", "b.pfm", "--mask", "./penumbra"], 0);
    assert_eq!(j["region_pixels"], 1);
    close(&j["channels"][1]["mse"], 0.0625);
    // Scene flags without --mask penumbra: a warning naming them; a figure not .png or .ppm:
    // a usage error naming --out.
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--bounces", "2"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        stderr(&out).contains("warning: --bounces has no effect without --mask penumbra"),
        "{}",
        stderr(&out)
    );
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--out", "d.jpg"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--out d.jpg: expected"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn non_finite_pixels_are_left_out_and_counted() {
    let dir = pair();
    let mut a = A;
    a[1] = [f32::NAN, 0.0, 0.0];
    write_pfm(&dir.path().join("nan.pfm"), 2, &a);
    let j = diff_json(dir.path(), &["nan.pfm", "b.pfm"], 0);
    assert_eq!(j["non_finite_pixels"], 1);
    assert_eq!(j["pixels_compared"], 3);
    // Pixel (1,0) held G's only difference.
    close(&j["channels"][1]["mse"], 0.0);
    close(&j["channels"][0]["mse"], 0.25 / 3.0);
}

#[test]
fn the_penumbra_mask_is_variances() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (w, h) = (12usize, 10usize);
    // A ramp against zeros: every pixel differs, by a known amount.
    let a: Vec<[f32; 3]> = (0..w * h).map(|i| [i as f32 / 128.0; 3]).collect();
    write_pfm(&d.join("a.pfm"), w, &a);
    write_pfm(&d.join("z.pfm"), w, &vec![[0.0; 3]; w * h]);
    let j = diff_json(
        d,
        &[
            "a.pfm",
            "z.pfm",
            "--mask",
            "penumbra",
            "--bounces",
            "2",
            "--mask-samples",
            "16",
        ],
        0,
    );
    let settings = raywave::render::settings::RenderSettings {
        width: w as u32,
        height: h as u32,
        bounces: 2,
        ..Default::default()
    };
    let scene = raywave::render::scene::Scene::builtin_default();
    let mask = raywave::variance::penumbra_mask(&scene, &settings, 16).penumbra;
    let inside: Vec<usize> = (0..w * h).filter(|&i| mask[i]).collect();
    assert!(!inside.is_empty() && inside.len() < w * h);
    assert_eq!(j["region_pixels"], inside.len());
    let mse: f64 = inside
        .iter()
        .map(|&i| (a[i][0] as f64).powi(2))
        .sum::<f64>()
        / inside.len() as f64;
    close(&j["all"]["mse"], mse);
}

#[test]
fn the_diff_image_has_the_map_and_a_colour_bar() {
    let dir = pair();
    let d = dir.path();
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--out", "d.png"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let img = image::open(d.join("d.png")).unwrap().to_rgb8();
    // The 2×2 map is drawn at least MIN_SIDE pixels high, with room for the bar beside it.
    assert!(img.height() > MIN_SIDE && img.width() > MIN_SIDE + 60);
    // The bar: a column right of the map running from the map's brightest colour at the top to
    // its darkest at the bottom.
    let (top, bottom) = (inferno(1.0), inferno(0.0));
    let bar = (MIN_SIDE..img.width()).find(|&x| {
        let col: Vec<[u8; 3]> = (0..img.height()).map(|y| img.get_pixel(x, y).0).collect();
        let first = col.iter().position(|c| *c == top);
        let last = col.iter().rposition(|c| *c == bottom);
        matches!((first, last), (Some(f), Some(l)) if l > f + MIN_SIDE as usize / 2)
    });
    assert!(bar.is_some(), "no colour bar in the figure");
    // The worst pixels (squared error 0.25/3 at (0,0)) are drawn brightest: the map's top-left
    // quarter is pale, the (1,0) quarter with 0.0625/3 is darker.
    let lum = |c: [u8; 3]| c.iter().map(|&v| v as u32).sum::<u32>();
    let bright = (0..img.width())
        .map(|x| lum(img.get_pixel(x, img.height() / 3).0))
        .max()
        .unwrap();
    assert!(bright >= lum(inferno(0.95)), "{bright}");
}

#[test]
fn a_long_thin_image_gets_no_giant_figure() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_pfm(&d.join("a.pfm"), 300, &[[0.25; 3]; 300]);
    write_pfm(&d.join("b.pfm"), 300, &[[0.5; 3]; 300]);
    let out = raywave(d, &["diff", "a.pfm", "b.pfm", "--out", "d.png"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("too elongated"), "{}", stderr(&out));
    assert!(!d.join("d.png").exists());
}

#[test]
fn outputs_never_overwrite_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_png(&d.join("a.png"), 2, &[[1, 2, 3]; 4]);
    write_png(&d.join("b.png"), 2, &[[3, 2, 1]; 4]);
    write_png(&d.join("m.png"), 2, &[[1, 1, 1]; 4]);
    let before = std::fs::read(d.join("a.png")).unwrap();
    for flags in [
        ["--out", "a.png"],
        ["--json", "b.png"],
        ["--out", "./b.png"],
        ["--out", "m.png"],
    ] {
        let mut args = vec!["diff", "a.png", "b.png", "--mask", "m.png"];
        args.extend_from_slice(&flags);
        let out = raywave(d, &args);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(&format!("{} {}", flags[0], flags[1])),
            "{flags:?}: {}",
            stderr(&out)
        );
    }
    assert_eq!(std::fs::read(d.join("a.png")).unwrap(), before);
    assert_eq!(
        common::bin::files_in(d),
        ["a.png", "b.png", "m.png"],
        "a refused run left a file"
    );
}

#[test]
fn render_mse_reference_agrees_with_diff_on_the_same_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // References the test writes: a grey float image and an 8-bit one.
    write_pfm(&d.join("ref.pfm"), 16, &vec![[0.5, 0.25, 0.125]; 16 * 12]);
    write_png(&d.join("ref.png"), 16, &vec![[128, 64, 32]; 16 * 12]);
    for (reference, output) in [("ref.pfm", "r.pfm"), ("ref.png", "r.png")] {
        let out = raywave(
            d,
            &[
                "--size",
                "16",
                "12",
                "-q",
                "-o",
                output,
                "--mse-reference",
                reference,
                "--stats-json",
                "s.json",
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        assert!(
            stdout(&out).contains(&format!("against --mse-reference {reference}")),
            "{}",
            stdout(&out)
        );
        let stats: Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("s.json")).unwrap()).unwrap();
        let from_render = &stats["mse_reference"];
        let from_diff = diff_json(d, &[output, reference], 0);
        for key in ["mse", "relmse", "max_abs", "psnr", "max_at"] {
            assert_eq!(from_render["all"][key], from_diff["all"][key], "{key}");
            assert_eq!(
                from_render["channels"][1][key], from_diff["channels"][1][key],
                "{key}"
            );
        }
        assert!(from_diff["all"]["mse"].as_f64().unwrap() > 0.0);
    }
    // A reference of another size is refused before rendering.
    let out = raywave(
        d,
        &[
            "--size",
            "8",
            "8",
            "-o",
            "x.png",
            "--mse-reference",
            "ref.pfm",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--mse-reference ref.pfm is 16×12"),
        "{}",
        stderr(&out)
    );
    assert!(!d.join("x.png").exists());
}

#[cfg(feature = "flip")]
#[test]
fn flip_is_zero_for_identical_images_and_positive_otherwise() {
    let dir = pair();
    let j = diff_json(dir.path(), &["a.pfm", "a.pfm", "--flip"], 0);
    assert_eq!(j["flip"]["mean"], 0.0);
    let j = diff_json(dir.path(), &["a.pfm", "b.pfm", "--metric", "flip"], 0);
    let mean = j["flip"]["mean"].as_f64().unwrap();
    assert!(mean > 0.0 && mean <= 1.0, "{mean}");
    assert_eq!(j["value"], j["flip"]["mean"]);
    let out = raywave(
        dir.path(),
        &[
            "diff",
            "a.pfm",
            "b.pfm",
            "--metric",
            "flip",
            "--fail-above",
            "0",
        ],
    );
    assert_eq!(out.status.code(), Some(3));
}
