//! Serde's deserialisation errors, turned into located issues in plain words.

use toml::de::DeTable;

use super::error::{Issue, KeyPath, SceneErrorKind, Seg, dotted};
use super::schema;
use super::spans::path_at;

/// Turns a serde error into an issue at the key its span points to.
pub(crate) fn translate(canon: &str, e: &toml::de::Error) -> Issue {
    let mut path = match (DeTable::parse(canon), e.span()) {
        // The root's own span is empty: errors there are about the whole document.
        (Ok(root), Some(span)) if span != root.span() => path_at(root.get_ref(), &span),
        _ => KeyPath::new(),
    };
    let (kind, message, allowed) = classify(e.message().trim(), &mut path);
    // Errors inside an array of numbers name the array, not the element.
    while matches!(path.last(), Some(Seg::Index(_))) && kind != SceneErrorKind::UnknownKey {
        if path.len() >= 2 && matches!(path[path.len() - 2], Seg::Key(ref k) if k == "pin") {
            break;
        }
        path.pop();
    }
    Issue {
        path,
        kind,
        message,
        allowed,
        cause: None,
    }
}

/// The kind, the message and what is allowed of serde's message `msg` about
/// the key at `path`: one branch per serde message form. A missing field
/// extends `path` by its name.
fn classify(msg: &str, path: &mut KeyPath) -> (SceneErrorKind, String, Option<String>) {
    if let Some(rest) = msg.strip_prefix("unknown field ") {
        let list = expected(rest).unwrap_or_else(|| "no keys".to_owned());
        (
            SceneErrorKind::UnknownKey,
            "unknown key".to_owned(),
            Some(list),
        )
    } else if let Some(rest) = msg.strip_prefix("missing field ") {
        path.push(Seg::Key(rest.trim_matches('`').to_owned()));
        let allowed = described(path, None);
        (
            SceneErrorKind::MissingKey,
            "missing required key".to_owned(),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("unknown variant ") {
        let value = rest.split(", expected").next().unwrap_or(rest);
        let allowed = described(path, expected(rest));
        (
            SceneErrorKind::BadValue,
            format!("{value} is not a valid value"),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("invalid type: ") {
        let found = rest.split(", expected").next().unwrap_or(rest);
        let allowed = described(path, expected(rest));
        (
            SceneErrorKind::WrongType,
            format!("wrong type: found {found}"),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("invalid length ") {
        let n = rest.split(", expected").next().unwrap_or(rest);
        let allowed = described(path, expected(rest));
        (
            SceneErrorKind::WrongType,
            format!("wrong number of elements: {n}"),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("invalid value: ") {
        invalid_value(rest, path)
    } else {
        let allowed = described(path, None);
        (SceneErrorKind::BadValue, msg.to_owned(), allowed)
    }
}

/// Serde's `invalid value: REST` about the key at `path`: an integer out of
/// range, or another bad value.
fn invalid_value(rest: &str, path: &KeyPath) -> (SceneErrorKind, String, Option<String>) {
    let found = rest.split(", expected").next().unwrap_or(rest);
    let allowed = described(path, expected(rest));
    if found.starts_with("integer") && rest.ends_with("expected u32") {
        let n = found.trim_start_matches("integer ");
        (
            SceneErrorKind::OutOfRange,
            format!("{n} is out of range"),
            allowed,
        )
    } else {
        let kind = SceneErrorKind::BadValue;
        (kind, format!("invalid value: {found}"), allowed)
    }
}

/// What serde's message `m` says was expected (after `, expected `), without a
/// leading `one of `.
fn expected(m: &str) -> Option<String> {
    m.split_once(", expected ")
        .map(|(_, x)| x.trim_start_matches("one of ").to_owned())
}

/// What the key at `path` allows: the schema's words, else `fallback` (serde's
/// expectation) in plain words.
fn described(path: &KeyPath, fallback: Option<String>) -> Option<String> {
    schema::allowed(&dotted(path))
        .map(str::to_owned)
        .or(fallback.map(|x| plain(&x)))
}

/// Serde's type names in plain words.
fn plain(expected: &str) -> String {
    match expected {
        "u32" => "a non-negative integer".to_owned(),
        "f64" => "a number".to_owned(),
        "a sequence" => "an array".to_owned(),
        x if x.starts_with("struct ") => "a table".to_owned(),
        x => x.to_owned(),
    }
}
