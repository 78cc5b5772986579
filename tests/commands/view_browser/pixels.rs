//! The render canvas against `raywave render`: the page draws each level's PNG into a canvas of
//! the level's size at 1:1; read back at full resolution, the last level must equal, byte for
//! byte, the PNG the command line writes for the same settings (the PNG is decoded without
//! colour conversion, so a colour-managed or scaled draw would show here).

use super::webdriver::Session;
use base64::Engine as _;
use std::process::Command;

/// The render canvas's size and its RGBA bytes, read with getImageData at full resolution.
fn canvas_rgba(c: &Session) -> (u32, u32, Vec<u8>) {
    let got = c.execute(
        "const cv = document.getElementById('render');
         const d = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data;
         let s = '';
         for (let k = 0; k < d.length; k += 4096) s += String.fromCharCode(...d.subarray(k, k + 4096));
         return [cv.width, cv.height, btoa(s)];",
        vec![],
    );
    let size = |k: usize| got[k].as_u64().expect("a canvas size") as u32;
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(got[2].as_str().unwrap_or_default())
        .expect("base64 pixels");
    (size(0), size(1), bytes)
}

/// `raywave render --size W H FLAGS` decoded with the image crate.
fn cli_render(width: u32, height: u32, flags: &[&str]) -> image::RgbImage {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("render.png");
    let (w, h) = (width.to_string(), height.to_string());
    let run = Command::new(crate::common::bin::exe())
        .args(["render", "--size", &w, &h, "-q", "--output"])
        .arg(&out)
        .args(flags)
        .output()
        .expect("run raywave render");
    assert!(
        run.status.success(),
        "raywave render {flags:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    image::open(&out).expect("decode its PNG").to_rgb8()
}

/// Asserts that the canvas holds exactly what `raywave render --size W H FLAGS` writes.
pub(super) fn assert_canvas_is_cli_render(c: &Session, flags: &[&str]) {
    let (w, h, rgba) = canvas_rgba(c);
    let expected = cli_render(w, h, flags);
    assert_eq!((w, h), expected.dimensions(), "canvas size ({flags:?})");
    let mut differ = Vec::new();
    for (i, p) in expected.pixels().enumerate() {
        let got = &rgba[4 * i..4 * i + 4];
        if got[..3] != p.0 || got[3] != 255 {
            differ.push((i as u32 % w, i as u32 / w, got.to_vec(), p.0));
        }
    }
    assert!(
        differ.is_empty(),
        "{flags:?}: {} of {} pixels differ from raywave render's; the first (x, y, canvas RGBA, PNG RGB): {:?}",
        differ.len(),
        w * h,
        &differ[..differ.len().min(4)]
    );
}
