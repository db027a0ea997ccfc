//! The scene error type. Every message names the file, then the line (or the
//! `--set` that supplied the value), then the key, what is wrong and what is allowed.

use std::fmt;

/// What kind of problem a [`SceneError`] reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneErrorKind {
    /// The scene file could not be read.
    Io,
    /// The text is not valid TOML.
    Syntax,
    /// A `--set` argument is malformed or addresses something that cannot exist.
    BadOverride,
    /// A key that the format does not have.
    UnknownKey,
    /// A value of the wrong TOML type (e.g. a string where a number belongs).
    WrongType,
    /// A value of the right type that is not one of the allowed ones.
    BadValue,
    /// A required key is absent.
    MissingKey,
    /// A number outside its allowed range (or not finite).
    OutOfRange,
    /// A key that does not apply to the chosen variant (e.g. `radius` on a rectangle).
    NotApplicable,
    /// A section the format names that this version does not implement yet.
    Unsupported,
}

/// An invalid scene: where, which key, what is wrong and what is allowed.
///
/// Displays as `FILE:LINE: key `section.key`: what is wrong; allowed: ...`; when the
/// value came from a `--set` override, the line is replaced by `--set section.key=...`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", self.render())]
pub struct SceneError {
    /// What kind of problem this is.
    pub kind: SceneErrorKind,
    /// The scene's origin: its path, or e.g. `<default scene>`.
    pub file: Box<str>,
    /// 1-based line in the file, when the problem has one.
    pub line: Option<usize>,
    /// The `--set` argument that supplied the offending value, if any.
    pub set: Option<Box<str>>,
    /// Dotted path of the offending key (`cloth.resolution`, `pin.0.region`), if any.
    pub key: Option<Box<str>>,
    /// What is wrong.
    pub message: Box<str>,
    /// What is allowed instead, if that can be said.
    pub allowed: Option<Box<str>>,
}

impl SceneError {
    /// The full one-line message (also the `Display` form).
    pub fn render(&self) -> String {
        let mut s = self.file.to_string();
        if let Some(line) = self.line {
            s.push_str(&format!(":{line}"));
        }
        s.push_str(": ");
        if let Some(set) = &self.set {
            s.push_str(&format!("--set {set}: "));
        }
        if let Some(key) = &self.key {
            s.push_str(&format!("key `{key}`: "));
        }
        s.push_str(&self.message);
        if let Some(allowed) = &self.allowed {
            s.push_str("; allowed: ");
            s.push_str(allowed);
        }
        s
    }
}

/// One step of a key path: a table key or an array index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Seg {
    /// A key in a table.
    Key(String),
    /// An index into an array (of tables, for `[[pin]]`).
    Index(usize),
}

/// A dotted key path as a list of steps.
pub(crate) type KeyPath = Vec<Seg>;

/// `pin.0.region` for display.
pub(crate) fn dotted(path: &[Seg]) -> String {
    let parts: Vec<String> = path
        .iter()
        .map(|s| match s {
            Seg::Key(k) => k.clone(),
            Seg::Index(i) => i.to_string(),
        })
        .collect();
    parts.join(".")
}

/// A path from string keys (validation code names keys statically).
pub(crate) fn keys(parts: &[&str]) -> KeyPath {
    parts.iter().map(|p| Seg::Key((*p).to_owned())).collect()
}

/// A problem found at a key path, before it is located in a file or a `--set`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Issue {
    /// Where (empty: the whole document).
    pub path: KeyPath,
    /// What kind of problem.
    pub kind: SceneErrorKind,
    /// What is wrong.
    pub message: String,
    /// What is allowed.
    pub allowed: Option<String>,
    /// The key whose value makes this a problem (e.g. `cloth.shape` for a missing `radius`).
    pub cause: Option<KeyPath>,
}

impl Issue {
    /// An issue at `path`.
    pub fn new(path: KeyPath, kind: SceneErrorKind, message: impl fmt::Display) -> Self {
        Self {
            path,
            kind,
            message: message.to_string(),
            allowed: None,
            cause: None,
        }
    }

    /// The same issue with an "allowed: ..." part.
    pub fn allowed(mut self, allowed: impl fmt::Display) -> Self {
        self.allowed = Some(allowed.to_string());
        self
    }

    /// The same issue, caused by the value at `cause`.
    pub fn because(mut self, cause: KeyPath) -> Self {
        self.cause = Some(cause);
        self
    }
}

/// A number as a message shows it: plain when it is of everyday size, in
/// scientific notation otherwise (`1e300` rather than 301 digits).
pub(crate) fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
