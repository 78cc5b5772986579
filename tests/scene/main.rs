//! Scene-file tests: the format (docs/SCENE_FORMAT.md) on every bundled scene and each
//! extension, its errors (each naming `file:line`), and the bounded fuzzing of the parser. One
//! test binary; each file is a module (docs/TESTING.md).

#[path = "../common/mod.rs"]
mod common;

mod scene_errors;
mod scene_fuzz;
mod scene_parse;
mod scene_textures;
