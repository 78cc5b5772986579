//! Image output: the lab's clamp (no gamma), the 'h' tone map 1 − e^(−3x), PFM layout, and
//! files written whole or not at all.

use glam::Vec3;
use raywave::output::image_file::{check_output_dir, ldr_format, write_rgb8};
use raywave::output::write_output;
use raywave::render::film::{Film, ToneMap};
use std::io::Write;

fn files_in(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn clamp_is_the_labs_look_without_gamma() {
    let mut film = Film::new(3, 2);
    film.pixels = vec![
        Vec3::new(0.0, 0.5, 1.0),
        Vec3::new(-1.0, 2.0, 0.2),
        Vec3::new(0.1, 0.6, f32::INFINITY),
        Vec3::new(0.25, 0.75, 0.999),
        Vec3::new(1.0 / 255.0, 0.5 / 255.0, 0.49 / 255.0),
        Vec3::new(f32::NAN, 0.0, 0.0),
    ];
    let img = film.to_rgb8(ToneMap::Clamp);
    // round(255·x) after clamping to [0, 1].
    assert_eq!(img.get_pixel(0, 0).0, [0, 128, 255]);
    assert_eq!(img.get_pixel(1, 0).0, [0, 255, 51]);
    assert_eq!(img.get_pixel(2, 0).0, [26, 153, 255]);
    assert_eq!(img.get_pixel(0, 1).0, [64, 191, 255]);
    assert_eq!(img.get_pixel(1, 1).0, [1, 1, 0]);
    assert_eq!(img.get_pixel(2, 1).0[1..], [0, 0]);
}

#[test]
fn exp_tone_map_is_one_minus_exp_minus_3x() {
    let mut film = Film::new(4, 1);
    film.pixels = vec![Vec3::ZERO, Vec3::splat(0.1), Vec3::ONE, Vec3::splat(10.0)];
    let img = film.to_rgb8(ToneMap::Exp);
    for (i, x) in [0.0f64, 0.1, 1.0, 10.0].iter().enumerate() {
        let want = ((1.0 - (-3.0 * x).exp()) * 255.0).round() as u8;
        let got = img.get_pixel(i as u32, 0).0;
        assert!(
            got.iter().all(|&g| (g as i32 - want as i32).abs() <= 1),
            "x = {x}: {got:?} vs {want}"
        );
    }
    assert_eq!(img.get_pixel(2, 0).0, [242, 242, 242]); // 255 · 0.9502 = 242.3
}

#[test]
fn pfm_stores_rows_bottom_to_top_little_endian() {
    let dir = tempfile::tempdir().unwrap();
    let mut film = Film::new(2, 2);
    film.pixels = vec![
        Vec3::new(1.0, 2.0, 3.0),    // top-left
        Vec3::new(4.0, 5.0, 6.0),    // top-right
        Vec3::new(7.0, 8.0, 9.0),    // bottom-left
        Vec3::new(10.0, 11.0, 12.0), // bottom-right
    ];
    let path = dir.path().join("x.pfm");
    film.write_hdr(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let header = b"PF\n2 2\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    let floats: Vec<f32> = bytes[header.len()..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(
        floats,
        [
            7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0
        ]
    );
    assert_eq!(files_in(dir.path()), ["x.pfm"]);
}

#[test]
fn exr_keeps_linear_values_above_one() {
    let dir = tempfile::tempdir().unwrap();
    let mut film = Film::new(2, 1);
    film.pixels = vec![Vec3::new(0.25, 3.5, 0.0), Vec3::new(1.0, 0.5, 100.0)];
    let path = dir.path().join("x.exr");
    film.write_hdr(&path).unwrap();
    let img = image::open(&path).unwrap().to_rgb32f();
    assert_eq!(img.get_pixel(0, 0).0, [0.25, 3.5, 0.0]);
    assert_eq!(img.get_pixel(1, 0).0, [1.0, 0.5, 100.0]);
}

#[test]
fn png_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let mut film = Film::new(3, 1);
    film.pixels = vec![Vec3::new(0.2, 0.1, 0.6), Vec3::ONE, Vec3::ZERO];
    let path = dir.path().join("x.png");
    write_rgb8(&film.to_rgb8(ToneMap::Clamp), &path).unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    assert_eq!(img.get_pixel(0, 0).0, [51, 26, 153]);
    assert_eq!(img.get_pixel(1, 0).0, [255; 3]);
    assert_eq!(files_in(dir.path()), ["x.png"]);
}

#[test]
fn a_failed_write_leaves_nothing_behind_and_keeps_the_old_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.png");
    let result = write_output(&path, |w| {
        w.write_all(b"half an image")?;
        anyhow::bail!("the encoder failed")
    });
    assert!(result.is_err());
    assert!(
        files_in(dir.path()).is_empty(),
        "{:?}",
        files_in(dir.path())
    );
    std::fs::write(&path, b"old").unwrap();
    let result = write_output(&path, |_| anyhow::bail!("failed again"));
    assert!(result.is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"old");
    assert_eq!(files_in(dir.path()), ["out.png"]);
    // A successful write replaces it whole.
    write_output(&path, |w| Ok(w.write_all(b"new")?)).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"new");
    assert_eq!(files_in(dir.path()), ["out.png"]);
}

#[test]
fn output_checks() {
    assert!(ldr_format(std::path::Path::new("a.png")).is_ok());
    assert!(ldr_format(std::path::Path::new("a.PNG")).is_ok());
    assert!(ldr_format(std::path::Path::new("a.ppm")).is_ok());
    let e = ldr_format(std::path::Path::new("a.jpg"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("a.jpg") && e.contains(".png"), "{e}");
    assert!(ldr_format(std::path::Path::new("noext")).is_err());
    assert!(check_output_dir(std::path::Path::new("render.png")).is_ok());
    let e = check_output_dir(std::path::Path::new("/no/such/dir/x.png"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/no/such/dir"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("x").join("y.png");
    std::fs::write(dir.path().join("x"), b"a file, not a directory").unwrap();
    assert!(check_output_dir(&missing).is_err());
    // An existing directory is not a file to write to.
    std::fs::create_dir(dir.path().join("d.png")).unwrap();
    let e = check_output_dir(&dir.path().join("d.png"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("d.png") && e.contains("directory"), "{e}");
    assert!(check_output_dir(&dir.path().join("new.png")).is_ok());
}

#[test]
fn a_pfm_with_a_zero_dimension_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    for header in ["PF\n0 4\n-1.0\n", "PF\n4 0\n-1.0\n", "PF\n0 0\n-1.0\n"] {
        let path = dir.path().join("zero.pfm");
        std::fs::write(&path, header).unwrap();
        let e = format!("{:#}", Film::read_pfm(&path).unwrap_err());
        assert!(
            e.contains("not a little-endian colour PFM"),
            "{header:?}: {e}"
        );
    }
}
