//! Any bytes through the scene reader: never a panic, and every error names a line of the file
//! (1 to the line count, or the line after the last for an unterminated block) and quotes
//! nothing raw: no control character but the message's own reaches the terminal.
#![no_main]

use libfuzzer_sys::fuzz_target;
use raywave::render::scene::{ParseOptions, parse_scene_in};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let options = ParseOptions { ring_segments: 3 + data.len() as u32 % 8 };
    if let Err(e) = parse_scene_in(text, "fuzz.obj", &options, None) {
        let lines = text.lines().count().max(1);
        assert!(e.line >= 1 && e.line <= lines + 1, "line {} of {lines}: {e}", e.line);
        assert!(!e.message.chars().any(char::is_control), "raw control in {e:?}");
    }
});
