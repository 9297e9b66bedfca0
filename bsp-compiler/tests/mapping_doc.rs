//! `docs/mapping.md` lists every entity key and classname the stages read: this collects them
//! from the source of the compiler, vis, light and the viewer and fails on any the page lacks.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

const CRATES: [&str; 4] = ["bsp-compiler", "vis", "light", "runtime-viewer"];

/// How the crates read entity keys: `Entity` accessors (`get`, `get_float`, `get_floats`),
/// the spellings of light's declared entity keys (`NAME: ["key", ...]`), and the prefab module's
/// key constants. The literal follows each opening. Keys starting with `_` are taken wherever
/// they appear (light lists some in tables), as are classname-like literals.
const KEY_OPENINGS: [&str; 5] = [".get(\"", ".get_float(\"", ">(\"", ": [\"", ": &str = \""];

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("source dir").flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The file's code without its unit tests and comment lines (which use keys of every kind as
/// examples).
fn non_test_code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).expect("read source");
    let code = text.split("#[cfg(test)]").next().unwrap_or("");
    code.lines()
        .filter(|line| !line.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The string literals in `code`, each with the text just before it.
fn literals(code: &str) -> Vec<(&str, &str)> {
    let mut out = Vec::new();
    let mut rest = code;
    let mut consumed = 0;
    while let Some(start) = rest.find('"') {
        let Some(len) = rest[start + 1..].find('"') else {
            break;
        };
        let at = consumed + start;
        let mut before = at.saturating_sub(16);
        while !code.is_char_boundary(before) {
            before -= 1;
        }
        out.push((&code[before..at + 1], &rest[start + 1..start + 1 + len]));
        consumed += start + len + 2;
        rest = &code[consumed..];
    }
    out
}

fn is_key_like(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// Keys and classnames the code reads.
fn read_by_code() -> BTreeSet<String> {
    let mut files = Vec::new();
    for krate in CRATES {
        rust_files(&repo().join(krate).join("src"), &mut files);
    }
    let mut found = BTreeSet::new();
    for file in files {
        let code = non_test_code(&file);
        for (before, literal) in literals(&code) {
            if !is_key_like(literal) {
                continue;
            }
            let accessor = KEY_OPENINGS.iter().any(|o| before.ends_with(o));
            let underscore_key = literal.starts_with('_') && literal.len() > 2;
            let in_key_list = before.contains("_any(&[");
            let classname = literal == "worldspawn"
                || ["func_", "info_", "misc_", "light_", "trigger_", "rotate_"]
                    .iter()
                    .any(|p| literal.starts_with(p));
            if accessor || underscore_key || in_key_list || classname {
                found.insert(literal.to_string());
            }
        }
    }
    found
}

#[test]
fn every_key_the_stages_read_is_documented() {
    let page = std::fs::read_to_string(repo().join("docs/mapping.md")).expect("docs/mapping.md");
    let read = read_by_code();
    // The collector finds what it should: a key of each kind of accessor.
    for known in [
        "targetname",
        "_external_map_scale",
        "_sunlight2",
        "_mincolor",
        "mangle",
        "func_detail",
    ] {
        assert!(read.contains(known), "collector missed {known}: {read:?}");
    }
    let missing: Vec<&String> = read
        .iter()
        .filter(|k| !page.contains(&format!("`{k}")))
        .collect();
    assert!(
        missing.is_empty(),
        "read by the code but not in docs/mapping.md: {missing:?}"
    );
}
