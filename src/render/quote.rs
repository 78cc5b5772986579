//! Text from the user (scene tokens, file names, flag values) quoted in messages: control
//! characters and escape sequences are shown escaped, never sent to the terminal, and long text
//! is cut, so that a hostile file can neither drive the terminal nor flood it.

/// The most characters of one quoted piece of input a message shows.
const QUOTE_CHARS: usize = 60;

/// `text` with every control or bidirectional-formatting character escaped (`\x1b`, `\n`,
/// `\u{202e}`); everything else, non-ASCII letters included, as is.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        push_escaped(&mut out, c);
    }
    out
}

/// [`escape`]d and cut after [`QUOTE_CHARS`] characters (marked with `…`): what every message
/// that quotes a token of a scene file or a flag's value shows.
pub fn quote(text: &str) -> String {
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == QUOTE_CHARS {
            out.push('…');
            break;
        }
        push_escaped(&mut out, c);
    }
    out
}

fn push_escaped(out: &mut String, c: char) {
    use std::fmt::Write as _;
    match c {
        '\n' => out.push_str("\\n"),
        '\r' => out.push_str("\\r"),
        '\t' => out.push_str("\\t"),
        c if (c as u32) < 0x80 && c.is_control() => {
            let _ = write!(out, "\\x{:02x}", c as u32);
        }
        // C1 controls, bidirectional overrides and isolates, zero-width and BOM characters:
        // invisible, or reorder what the terminal shows.
        c if c.is_control()
            || matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{feff}') =>
        {
            let _ = write!(out, "\\u{{{:x}}}", c as u32);
        }
        c => out.push(c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controls_are_escaped_and_long_text_is_cut() {
        assert_eq!(quote("\u{1b}[31mred"), "\\x1b[31mred");
        assert_eq!(quote("a\0b\u{7f}"), "a\\x00b\\x7f");
        assert_eq!(quote("\u{202e}txt"), "\\u{202e}txt");
        assert_eq!(quote("ünïcödé"), "ünïcödé");
        let long = "x".repeat(10_000_000);
        let q = quote(&long);
        assert_eq!(q.chars().count(), QUOTE_CHARS + 1);
        assert!(q.ends_with('…'));
        assert_eq!(quote(&"y".repeat(QUOTE_CHARS)), "y".repeat(QUOTE_CHARS));
        assert_eq!(escape(&"z".repeat(100)).len(), 100);
    }
}
