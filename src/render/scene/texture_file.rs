//! Reading a `texture_file` PPM, P3 (ASCII) or P6 (binary), with the `image` crate's decoder.
//!
//! What could hang, exhaust memory or half-read is refused before the texels are read: the name
//! must be a regular file (not a directory, a FIFO or a device), the header must be a PPM's, and
//! its width × height must be at least 1 and at most [`MAX_TEXTURE_TEXELS`]. A short or
//! malformed body is the decoder's error. Every error says what was expected and what was found;
//! the parser puts the scene's file and line in front. A build without the `textures` feature
//! (the renderer alone, as the instruction-count gate builds it) reads no texture and says so.

use super::texture::Texture;
use crate::render::quote::escape;
#[cfg(feature = "textures")]
use image::ImageDecoder;
#[cfg(feature = "textures")]
use image::codecs::pnm::{PnmDecoder, PnmSubtype};
#[cfg(feature = "textures")]
use std::fs::File;
#[cfg(feature = "textures")]
use std::io::{BufReader, Read};
use std::path::{Component, Path, PathBuf};

/// The most texels a texture may have: 2^26 (8192²), 768 MiB once linear. A header that asks
/// for more is refused before anything else is read.
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 26;

/// Where a `texture_file` name points: resolved against the folder of the scene file (`base`;
/// the current directory for text with no file), and whether it leaves that folder (an absolute
/// name, or one that climbs out through `..`).
pub(crate) fn resolve(name: &str, base: Option<&Path>) -> (PathBuf, bool) {
    let named = Path::new(name);
    let mut depth = 0i32;
    let mut escapes = named.is_absolute();
    for c in named.components() {
        match c {
            Component::ParentDir => depth -= 1,
            Component::Normal(_) => depth += 1,
            _ => {}
        }
        escapes |= depth < 0;
    }
    let path = base.map_or_else(|| named.to_path_buf(), |dir| dir.join(named));
    // The resolved path is shown in the render's summary: canonical when it exists.
    (std::fs::canonicalize(&path).unwrap_or(path), escapes)
}

/// Without the `textures` feature (a renderer-only build) no texture is read: the error says
/// why.
#[cfg(not(feature = "textures"))]
pub(crate) fn read_texture(_name: &str, path: &Path) -> Result<Texture, String> {
    Err(format!(
        "cannot read {}: this build of raywave reads no textures (built without the `textures` \
         feature)",
        escape(&path.display().to_string())
    ))
}

/// Reads the texture `name` at `path`. The error is a sentence naming the path.
#[cfg(feature = "textures")]
pub(crate) fn read_texture(name: &str, path: &Path) -> Result<Texture, String> {
    // The path comes from the scene file: its control characters are shown escaped.
    let shown = escape(&path.display().to_string());
    let cannot = |e: std::io::Error| format!("cannot read {shown}: {e}");
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        let kind = if meta.is_dir() {
            "a directory"
        } else {
            "a special file (FIFO, device or socket)"
        };
        return Err(format!("expected a PPM file at {shown}, found {kind}"));
    }
    let mut magic = Vec::new();
    let file = File::open(path).map_err(cannot)?;
    file.take(2).read_to_end(&mut magic).map_err(cannot)?;
    let found = match &magic[..] {
        b"P3" | b"P6" => None,
        b"P1" | b"P4" => Some("a PBM (bitmap, `P1`/`P4`)".to_string()),
        b"P2" | b"P5" => Some("a PGM (grey, `P2`/`P5`)".to_string()),
        b"P7" => Some("a PAM (`P7`)".to_string()),
        [] => Some("an empty file".to_string()),
        other => Some(format!(
            "a file starting `{}`",
            String::from_utf8_lossy(other).escape_debug()
        )),
    };
    if let Some(found) = found {
        return Err(format!(
            "expected a PPM texture (`P3` or `P6`) at {shown}, found {found}"
        ));
    }
    // The decoder reads the header again from the start.
    let file = File::open(path).map_err(cannot)?;
    let decoder = PnmDecoder::new(BufReader::new(file))
        .map_err(|e| format!("expected a PPM header at {shown}: {e}"))?;
    debug_assert!(matches!(decoder.subtype(), PnmSubtype::Pixmap(_)));
    let (width, height) = decoder.dimensions();
    if width == 0 || height == 0 {
        return Err(format!(
            "expected a texture of at least 1×1 texels at {shown}, found {width}×{height}"
        ));
    }
    let texels = width as u64 * height as u64;
    if texels > MAX_TEXTURE_TEXELS {
        return Err(format!(
            "expected a texture of at most {MAX_TEXTURE_TEXELS} texels (8192×8192) at {shown}, \
             found {width}×{height} = {texels}: refused before reading it ({:.1} GiB as linear \
             colours)",
            (texels * 12) as f64 / (1u64 << 30) as f64
        ));
    }
    let wide = decoder.color_type().bytes_per_pixel() == 6;
    let mut bytes = vec![0u8; decoder.total_bytes() as usize];
    decoder.read_image(&mut bytes).map_err(|e| {
        format!("expected {width}×{height} RGB texels at {shown}, found a truncated or malformed body: {e}")
    })?;
    let digest = [&width.to_le_bytes()[..], &height.to_le_bytes(), &bytes]
        .into_iter()
        .fold(
            crate::render::digest::START,
            crate::render::digest::continued,
        );
    let name = name.to_string();
    let path = path.to_path_buf();
    let texture = if wide {
        let sample = |k: usize| u16::from_ne_bytes([bytes[2 * k], bytes[2 * k + 1]]);
        Texture::from_srgb(name, path, width, height, sample, 65535.0)
    } else {
        Texture::from_srgb(name, path, width, height, |k| bytes[k] as u16, 255.0)
    };
    Ok(Texture { digest, ..texture })
}

#[cfg(all(test, feature = "textures"))]
mod tests {
    use super::*;
    use glam::Vec3;

    fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn reads_p3_and_p6_alike() {
        let dir = tempfile::tempdir().unwrap();
        let p3 = write(
            dir.path(),
            "a.ppm",
            b"P3\n# c\n2 1\n255\n255 0 0  0 0 255\n",
        );
        let p6 = write(
            dir.path(),
            "b.ppm",
            b"P6\n2 1\n255\n\xff\x00\x00\x00\x00\xff",
        );
        let a = read_texture("a.ppm", &p3).unwrap();
        let b = read_texture("b.ppm", &p6).unwrap();
        assert_eq!(a.texels, b.texels);
        assert_eq!(a.texels, vec![Vec3::X, Vec3::Z]);
        let deep = write(dir.path(), "c.ppm", b"P3\n1 1\n65535\n65535 0 65535\n");
        assert_eq!(
            read_texture("c.ppm", &deep).unwrap().texels,
            vec![Vec3::new(1.0, 0.0, 1.0)]
        );
    }

    #[test]
    fn refuses_what_is_not_a_whole_ppm() {
        let dir = tempfile::tempdir().unwrap();
        let cases: [(&str, &[u8], &str); 6] = [
            ("grey.ppm", b"P5\n1 1\n255\n\x00", "found a PGM"),
            ("empty.ppm", b"", "found an empty file"),
            ("png.ppm", b"\x89PNG\r\n", "found a file starting"),
            ("short.ppm", b"P6\n4 4\n255\n\x00\x01", "truncated"),
            ("zero.ppm", b"P6\n0 0\n255\n", "at least 1×1"),
            (
                "huge.ppm",
                b"P6\n65536 65536\n255\n\x00",
                "refused before reading",
            ),
        ];
        for (name, bytes, expected) in cases {
            let path = write(dir.path(), name, bytes);
            let e = read_texture(name, &path).unwrap_err();
            assert!(e.contains(expected), "{name}: {e}");
            assert!(e.contains(name), "{name}: {e}");
        }
        let e = read_texture("missing.ppm", &dir.path().join("missing.ppm")).unwrap_err();
        assert!(
            e.contains("cannot read") && e.contains("missing.ppm"),
            "{e}"
        );
        let e = read_texture("dir", dir.path()).unwrap_err();
        assert!(e.contains("found a directory"), "{e}");
    }

    #[test]
    fn names_that_leave_the_scene_folder_are_flagged() {
        let base = Path::new("/scenes/room");
        assert!(!resolve("wood.ppm", Some(base)).1);
        assert!(!resolve("textures/../wood.ppm", Some(base)).1);
        assert!(resolve("../wood.ppm", Some(base)).1);
        assert!(resolve("a/../../wood.ppm", Some(base)).1);
        assert!(resolve("/tmp/wood.ppm", Some(base)).1);
        assert_eq!(resolve("wood.ppm", Some(base)).0, base.join("wood.ppm"));
    }
}
