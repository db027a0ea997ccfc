//! One key table: every key the parser accepts has its wording in
//! `schema::allowed` (the error messages) and a row in `docs/scenes.md`, and
//! every key row of `docs/scenes.md` is a key the parser accepts there.
//! The parser's own list of a table's keys is what it answers to an unknown
//! key there.

use super::load_scene_str;
use super::schema::allowed;

/// A scene that parses, with `[simulation]`, `[cloth]` and `[material]`.
const BASE: &str = "name = \"t\"\n[simulation]\nduration = 1.0\n[cloth]\nshape = \"rectangle\"\nwidth = 1.0\nheight = 1.0\nresolution = 4\n[material]\ndensity = 0.1\nstretch = 100.0\nbending = 1e-5\n";

/// Each table: its key path, the scene text with an unknown key `zzz` in it,
/// and the heading of its part of `docs/scenes.md`.
fn tables() -> Vec<(&'static str, String, &'static str)> {
    let after = |table: &str, extra: &str| BASE.replace(table, &format!("{table}\n{extra}"));
    let appended = |extra: &str| format!("{BASE}{extra}\n");
    vec![
        ("", format!("zzz = 1\n{BASE}"), "## Top level"),
        (
            "simulation",
            after("[simulation]", "zzz = 1"),
            "## `[simulation]`",
        ),
        (
            "simulation.adaptive_dt",
            appended("[simulation.adaptive_dt]\nzzz = 1"),
            "### `[simulation.adaptive_dt]`",
        ),
        ("cloth", after("[cloth]", "zzz = 1"), "## `[cloth]`"),
        (
            "cloth.sewing",
            appended("[cloth.sewing]\nzzz = 1"),
            "## `[cloth]`",
        ),
        (
            "material",
            after("[material]", "zzz = 1"),
            "## `[material]`",
        ),
        ("panel", appended("[[panel]]\nzzz = 1"), "## Garments"),
        ("seam", appended("[[seam]]\nzzz = 1"), "## Garments"),
        (
            "attachment",
            appended("[[attachment]]\nzzz = 1"),
            "## Garments",
        ),
        ("pin", appended("[[pin]]\nzzz = 1"), "## `[[pin]]`"),
        ("air", appended("[air]\nzzz = 1"), "## `[air]`"),
        ("wind", appended("[wind]\nzzz = 1"), "## `[wind]`"),
        ("adapt", appended("[adapt]\nzzz = 1"), "## `[adapt]`"),
        (
            "obstacle",
            appended("[[obstacle]]\nzzz = 1"),
            "## `[[obstacle]]`",
        ),
        (
            "obstacle.part",
            appended("[[obstacle]]\nshape = \"articulated\"\n[[obstacle.part]]\nzzz = 1"),
            "### Articulated bodies",
        ),
        (
            "self_collision",
            appended("[self_collision]\nzzz = 1"),
            "## `[self_collision]`",
        ),
        ("camera", appended("[camera]\nzzz = 1"), "## `[camera]`"),
    ]
}

/// The keys the parser lists for the unknown key in `text`.
fn accepted(text: &str) -> Vec<String> {
    let error = match load_scene_str(text, "t.toml", &[]) {
        Ok(_) => panic!("an unknown key was accepted:\n{text}"),
        Err(e) => e.to_string(),
    };
    let list = error
        .split_once("allowed: ")
        .unwrap_or_else(|| panic!("no list of keys in: {error}"))
        .1;
    list.split(", ")
        .flat_map(|k| k.split(" or "))
        .map(|k| k.trim().trim_matches(|c| c == '`' || c == '.').to_owned())
        .filter(|k| !k.is_empty())
        .collect()
}

/// The part of `docs` under `heading`, to the next heading of its level or above.
fn section<'a>(docs: &'a str, heading: &str) -> &'a str {
    let start = docs
        .find(heading)
        .unwrap_or_else(|| panic!("docs/scenes.md has no heading {heading}"));
    let level = heading.split(' ').next().unwrap_or("##");
    let rest = &docs[start + heading.len()..];
    let end = rest
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .find(|&i| {
            let line = &rest[i..];
            line.starts_with("## ") || (level == "###" && line.starts_with("### "))
        })
        .unwrap_or(rest.len());
    &rest[..end]
}

#[test]
fn every_accepted_key_has_its_wording_and_its_row_in_the_docs() {
    let docs = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes.md"),
    )
    .expect("docs/scenes.md");
    let mut missing = Vec::new();
    for (table, text, heading) in tables() {
        let part = section(&docs, heading);
        let keys = accepted(&text);
        assert!(!keys.is_empty(), "{table}: no keys listed");
        for key in keys {
            let path = if table.is_empty() {
                key.clone()
            } else {
                format!("{table}.{key}")
            };
            if allowed(&path).is_none() {
                missing.push(format!("`{path}`: no wording in src/scene/schema.rs"));
            }
            // A table's keys have rows of their own, under its heading.
            let is_table = tables().iter().any(|(t, _, _)| *t == path);
            if !is_table && !part.contains(&format!("| `{key}` |")) {
                missing.push(format!(
                    "`{path}`: no row under \"{heading}\" in docs/scenes.md"
                ));
            }
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// The first cells of the rows of the key tables (those whose header starts with
/// `| key |`) in `part`.
fn documented_keys(part: &str) -> Vec<String> {
    let mut keys = Vec::new();
    let mut in_key_table = false;
    for line in part.lines() {
        if !line.starts_with('|') {
            in_key_table = false;
            continue;
        }
        if line.starts_with("| key |") {
            in_key_table = true;
            continue;
        }
        if in_key_table && !line.starts_with("|---") && !line.starts_with("| ---") {
            let first = line.split('|').nth(1).unwrap_or("").trim();
            keys.push(first.trim_matches('`').to_owned());
        }
    }
    keys
}

#[test]
fn every_documented_key_is_one_the_parser_accepts() {
    let docs = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes.md"),
    )
    .expect("docs/scenes.md");
    let tables = tables();
    let mut stale = Vec::new();
    for (table, _, heading) in &tables {
        let part = section(&docs, heading);
        // The keys of this table and of the tables documented inside its part.
        let known: Vec<String> = tables
            .iter()
            .filter(|(_, _, h)| h == heading || part.contains(h))
            .flat_map(|(_, text, _)| accepted(text))
            .collect();
        for key in documented_keys(part) {
            if !known.contains(&key) {
                stale.push(format!(
                    "`{key}` has a row under \"{heading}\" in docs/scenes.md, but [{table}] does not accept it"
                ));
            }
        }
    }
    assert!(stale.is_empty(), "{}", stale.join("\n"));
}
