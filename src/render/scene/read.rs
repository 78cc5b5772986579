//! Reading a scene's bytes, once: from a regular file, a FIFO, or standard input (`-`), never
//! more than [`MAX_SCENE_BYTES`]. Directories, devices and sockets are refused before a byte is
//! read, so `/dev/zero` ends at once with a message instead of filling memory.

use super::SceneError;
use crate::render::quote::escape;
use std::io::Read;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;

/// The largest scene raywave reads: 256 MiB. The largest generated benchmark mesh
/// (`raywave meshgen --triangles 1000000`) is 31.5 MB, so this leaves room for meshes of about
/// eight million triangles; past it, parsing alone would hold several GiB of vertices and
/// faces.
pub const MAX_SCENE_BYTES: u64 = 256 << 20;

/// The name standard input goes by in messages, in bench records (`scene.source`) and, as
/// `Scene::source`, everywhere else; caches key on the bytes read, not on this name.
pub const STDIN_NAME: &str = "<stdin>";

/// The bytes of the scene at `path` (`-` is standard input) and the name messages give it.
pub fn read_scene_bytes(path: &Path) -> Result<(Vec<u8>, String), SceneError> {
    if path.as_os_str() == "-" {
        let bytes = read_capped(std::io::stdin().lock(), STDIN_NAME, MAX_SCENE_BYTES)?;
        return Ok((bytes, STDIN_NAME.to_string()));
    }
    let name = escape(&path.display().to_string());
    let io = |source| SceneError::Io {
        path: name.clone(),
        source,
    };
    let kind = std::fs::metadata(path).map_err(io)?;
    let refuse = |what: &str| SceneError::Input {
        path: name.clone(),
        message: format!(
            "expected a scene file (a regular file, a FIFO, or `-` for standard input), found {what}"
        ),
    };
    let file_type = kind.file_type();
    if file_type.is_dir() {
        return Err(refuse("a directory"));
    } else if file_type.is_char_device() {
        return Err(refuse("a character device"));
    } else if file_type.is_block_device() {
        return Err(refuse("a block device"));
    } else if file_type.is_socket() {
        return Err(refuse("a socket"));
    } else if file_type.is_file() && kind.len() > MAX_SCENE_BYTES {
        return Err(too_large(&name, Some(kind.len()), MAX_SCENE_BYTES));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let bytes = read_capped(file, &name, MAX_SCENE_BYTES)?;
    Ok((bytes, name))
}

/// Reads `reader` to its end, refusing more than `cap` bytes ([`MAX_SCENE_BYTES`]).
fn read_capped(reader: impl Read, name: &str, cap: u64) -> Result<Vec<u8>, SceneError> {
    let mut bytes = Vec::new();
    reader
        .take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|source| SceneError::Io {
            path: name.to_string(),
            source,
        })?;
    if bytes.len() as u64 > cap {
        return Err(too_large(name, None, cap));
    }
    Ok(bytes)
}

fn too_large(name: &str, size: Option<u64>, cap: u64) -> SceneError {
    let found = match size {
        Some(n) => format!("{n} bytes"),
        None => "more".to_string(),
    };
    SceneError::Input {
        path: name.to_string(),
        message: format!(
            "expected a scene of at most {} MiB ({cap} bytes), found {found}",
            cap >> 20
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stream_longer_than_the_cap_is_refused_after_reading_one_byte_past_it() {
        let ok = read_capped(&b"v 0 0 0\n"[..], "s", 8).unwrap();
        assert_eq!(ok.len(), 8);
        let e = read_capped(&b"v 0 0 0\n\n"[..], "s", 8).unwrap_err();
        assert!(e.to_string().contains("at most"), "{e}");
        // An endless stream stops at the cap.
        let e = read_capped(std::io::repeat(b'x'), "<stdin>", 1 << 20).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("<stdin>: expected a scene of at most 1 MiB")
        );
    }

    #[test]
    fn directories_and_devices_are_refused_before_reading() {
        for (path, what) in [
            ("/", "a directory"),
            ("/dev/zero", "a character device"),
            ("/dev/null", "a character device"),
        ] {
            let e = read_scene_bytes(Path::new(path)).unwrap_err().to_string();
            assert!(e.contains(what) && e.starts_with(path), "{e}");
        }
    }
}
