//! The bounded, in-`cargo test` twin of the cargo-fuzz target `tests/fuzz/fuzz_targets/
//! parse_scene.rs`: random bytes, and random mutations of every bundled scene, through the
//! scene parser. Never a panic; every error names a line of the input; no message carries a raw
//! control character. Inputs that once crashed the fuzzer are kept below as regressions.

use crate::common;

use proptest::prelude::*;
use raywave::render::scene::{ParseOptions, parse_scene_in};

/// Parses `bytes` as the loader would (UTF-8 first) and checks the error, if any.
fn check(bytes: &[u8]) -> Result<(), TestCaseError> {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Ok(());
    };
    let options = ParseOptions { ring_segments: 4 };
    if let Err(e) = parse_scene_in(text, "fuzz.obj", &options, None) {
        let lines = text.lines().count().max(1);
        prop_assert!(
            e.line >= 1 && e.line <= lines + 1,
            "line {} of {lines}: {e}",
            e.line
        );
        prop_assert!(
            !e.message.chars().any(char::is_control),
            "raw control: {e:?}"
        );
        prop_assert!(
            e.message.len() < 1000,
            "{} bytes of message",
            e.message.len()
        );
    }
    Ok(())
}

/// The bytes of every bundled scene file: `scenes/*.obj` and RPI's in `scenes/rpi/`.
fn bundled() -> Vec<Vec<u8>> {
    let root = common::bin::scenes();
    let mut scenes: Vec<Vec<u8>> = [root.clone(), root.join("rpi")]
        .iter()
        .flat_map(|dir| std::fs::read_dir(dir).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    scenes.sort();
    scenes
}

/// A mutation: overwrite, insert or delete a byte, or splice in a token the parser knows.
#[derive(Debug, Clone)]
enum Edit {
    Set(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    Splice(usize, &'static str),
}

const TOKENS: &[&str] = &[
    " ",
    "\n",
    "\\\n",
    "#",
    "{",
    "}",
    "<",
    ",",
    "-",
    "1e9",
    "1e10",
    "nan",
    "inf",
    "-0",
    "0",
    "1e-45",
    "m 0\n",
    "m 99\n",
    "f 1 2 3\n",
    "f -1 -2 -3 -4\n",
    "s 0 0 0 1\n",
    "r 0 0 0 1 0 1\n",
    "material\n",
    "emitted 1 1 1\n",
    "vt 0.5 0.5\n",
    "texture_file textures/asymmetric.ppm\n",
    "PerspectiveCamera {",
    "angle 180",
    "\u{feff}",
    "\r\n",
    "\u{1b}[2J",
    "\0",
];

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Insert(i, b)),
        any::<usize>().prop_map(Edit::Delete),
        (any::<usize>(), prop::sample::select(TOKENS)).prop_map(|(i, t)| Edit::Splice(i, t)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2048, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        check(&bytes)?;
    }

    #[test]
    fn random_text_never_panics(text in "[ -~\n\t\r\u{1b}\u{0}]{0,300}") {
        check(text.as_bytes())?;
    }

    #[test]
    fn mutated_bundled_scenes_never_panic(
        which in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..8),
    ) {
        let scenes = bundled();
        let mut bytes = scenes[which.index(scenes.len())].clone();
        for e in edits {
            let at = |i: usize, len: usize| if len == 0 { 0 } else { i % len };
            match e {
                Edit::Set(i, b) if !bytes.is_empty() => { let i = at(i, bytes.len()); bytes[i] = b }
                Edit::Insert(i, b) => { let i = at(i, bytes.len() + 1); bytes.insert(i, b) }
                Edit::Delete(i) if !bytes.is_empty() => { let i = at(i, bytes.len()); bytes.remove(i); }
                Edit::Splice(i, t) => {
                    let i = at(i, bytes.len() + 1);
                    bytes.splice(i..i, t.bytes());
                }
                _ => {}
            }
        }
        check(&bytes)?;
    }
}

/// Regressions: inputs kept because they once went wrong (at the parser's edges).
#[test]
fn regressions() {
    for input in [
        &b""[..],
        b"\\",
        b"PerspectiveCamera {",
        b"PerspectiveCamera { } }",
        b"material\nm 0\nv 0 0 0\nv 1e-30 0 0\nv 0 1e-30 0\nf 1 2 3\n",
        b"material\nm 0\nr 0 0 0 1e-30 0 1e-30\n",
        b"material\nm 0\ns 0 0 0 1e-45\n",
    ] {
        check(input).unwrap();
    }
}
