//! docs/ARCHITECTURE.md's module map is `src/`: the tree under its "Module map" heading names
//! every folder and file, and nothing that is not there.
//!
//! A folder whose entries the map lists one per line (`render/`, `output/`, ...) must list
//! exactly its entries. A folder the map describes in a paragraph (`trace/`, `bench/`, ...)
//! must name each of its entries in that paragraph, and every `*.rs` the paragraph names must
//! be in it.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// One line of the map that names entries, with the lines that continue its description.
#[derive(Debug)]
struct Entry {
    /// The names that start the line (`scene/`, `mod.rs`; several on the stage line).
    names: Vec<String>,
    /// The text after the names, with its continuation lines.
    text: String,
    children: Vec<Entry>,
}

fn is_name(token: &str) -> bool {
    let stem = token.trim_end_matches('/').trim_end_matches(".rs");
    (token.ends_with('/') || token.ends_with(".rs"))
        && !stem.is_empty()
        && stem
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// The map's code block: the first ``` block after "## Module map".
fn map_block(doc: &str) -> Vec<&str> {
    let section = &doc[doc
        .find("## Module map")
        .expect("a \"## Module map\" heading")..];
    let mut lines = section.lines().skip_while(|l| !l.starts_with("```"));
    lines.next().expect("a code block in the module map");
    lines.take_while(|l| !l.starts_with("```")).collect()
}

/// The entries of `lines` as a tree: a line starts an entry when it begins with names and sits
/// at most one level (two spaces) below the folder above it; any other line continues the
/// description of the entry before it.
fn parse(lines: &[&str]) -> Entry {
    let mut stack: Vec<(usize, Entry)> = vec![(
        0,
        Entry {
            names: vec!["src/".into()],
            text: String::new(),
            children: Vec::new(),
        },
    )];
    assert_eq!(
        lines.first().map(|l| l.trim()),
        Some("src/"),
        "the map starts at src/"
    );
    for line in &lines[1..] {
        let indent = line.len() - line.trim_start().len();
        let mut tokens = line.split_whitespace().peekable();
        let mut names = Vec::new();
        while let Some(t) = tokens.peek().filter(|t| is_name(t)) {
            names.push(t.to_string());
            tokens.next();
        }
        let rest: Vec<&str> = tokens.collect();
        let parent_indent = stack.last().unwrap().0;
        if !names.is_empty() && indent <= parent_indent + 2 {
            while stack.last().unwrap().0 >= indent {
                let (_, done) = stack.pop().unwrap();
                stack.last_mut().unwrap().1.children.push(done);
            }
            stack.push((
                indent,
                Entry {
                    names,
                    text: rest.join(" "),
                    children: Vec::new(),
                },
            ));
        } else {
            let text = &mut stack.last_mut().unwrap().1.text;
            text.push(' ');
            text.push_str(line.trim());
        }
    }
    while stack.len() > 1 {
        let (_, done) = stack.pop().unwrap();
        stack.last_mut().unwrap().1.children.push(done);
    }
    stack.pop().unwrap().1
}

/// `dir`'s entries as the map spells them: `name/` for folders, `name.rs` for sources.
fn entries(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            if e.file_type().unwrap().is_dir() {
                format!("{name}/")
            } else {
                name
            }
        })
        .collect()
}

fn check(entry: &Entry, path: &Path, problems: &mut Vec<String>) {
    let on_disk = entries(path);
    let shown = path.display();
    if entry.children.is_empty() {
        // Described in a paragraph: every entry named there, and nothing named that is not.
        let words: BTreeSet<&str> = entry
            .text
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '/'))
            .map(|w| w.trim_end_matches('.'))
            .collect();
        for name in &on_disk {
            if !words.contains(name.as_str()) {
                problems.push(format!("{shown}/{name} is not named in the map"));
            }
        }
        for word in words.iter().filter(|w| w.ends_with(".rs") && is_name(w)) {
            if !on_disk.contains(*word) {
                problems.push(format!(
                    "the map names {shown}/{word}, which does not exist"
                ));
            }
        }
        return;
    }
    let listed: BTreeSet<String> = entry
        .children
        .iter()
        .flat_map(|c| c.names.clone())
        .collect();
    for name in on_disk.difference(&listed) {
        problems.push(format!("{shown}/{name} is missing from the map"));
    }
    for name in listed.difference(&on_disk) {
        problems.push(format!(
            "the map lists {shown}/{name}, which does not exist"
        ));
    }
    for child in &entry.children {
        for name in child.names.iter().filter(|n| n.ends_with('/')) {
            let sub: PathBuf = path.join(name.trim_end_matches('/'));
            if sub.is_dir() {
                check(child, &sub, problems);
            }
        }
    }
}

fn problems_of(doc: &str, src: &Path) -> Vec<String> {
    let tree = parse(&map_block(doc));
    let mut problems = Vec::new();
    check(&tree, src, &mut problems);
    problems
}

#[test]
fn the_module_map_is_the_source_tree() {
    let root = Path::new(env!("RAYWAVE_REPO"));
    let doc = std::fs::read_to_string(root.join("docs/ARCHITECTURE.md")).unwrap();
    let problems = problems_of(&doc, &root.join("src"));
    assert!(
        problems.is_empty(),
        "docs/ARCHITECTURE.md's module map and src/ disagree:\n{}",
        problems.join("\n")
    );
}

/// The check itself can fail: a map with a file missing, one with a file too many, and a
/// paragraph that forgets a file are each caught.
#[test]
fn a_stale_map_is_caught() {
    let root = Path::new(env!("RAYWAVE_REPO"));
    let doc = std::fs::read_to_string(root.join("docs/ARCHITECTURE.md")).unwrap();
    let src = &Path::new(env!("RAYWAVE_REPO")).join("src");
    let missing = doc.replacen("    camera.rs ", "    ", 1);
    assert!(
        problems_of(&missing, src)
            .iter()
            .any(|p| p.contains("camera.rs is missing"))
    );
    let extra = doc.replacen(
        "    camera.rs ",
        "    gone.rs           not a file\n    camera.rs ",
        1,
    );
    assert!(
        problems_of(&extra, src)
            .iter()
            .any(|p| p.contains("gone.rs, which does not"))
    );
    let forgotten = doc.replacen("palette.rs, ", "", 1);
    assert!(
        problems_of(&forgotten, src)
            .iter()
            .any(|p| p.contains("palette.rs is not named"))
    );
}
