//! Loading: TOML text -> document -> `--set` overrides -> `Scene` -> validation,
//! with every error located at a line of the file or at the `--set` that caused it.

use std::ops::Range;
use std::path::Path;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::error::{Issue, KeyPath, SceneError, SceneErrorKind, Seg, dotted, keys};
use super::{Scene, overrides, schema, validate};

/// Sections the format names that this version does not implement, with what is planned.
const UNSUPPORTED: [(&str, &str, &str); 3] = [
    ("adapt", "[adapt]", "adaptive meshing is planned"),
    (
        "obstacle",
        "[[obstacle]]",
        "obstacles and collisions are planned",
    ),
    (
        "self_collision",
        "[self_collision]",
        "self-collision handling is planned",
    ),
];

/// Loads and validates the scene in `text`; `origin` names it in messages and `base`
/// is the directory that `cloth.path` is relative to (`None`: the current directory).
pub(crate) fn load(
    text: &str,
    origin: &str,
    base: Option<&Path>,
    sets: &[String],
) -> Result<Scene, SceneError> {
    let mut doc: toml::Table = text.parse().map_err(|e| syntax_error(origin, text, &e))?;
    let mut ctx = Ctx {
        origin,
        text,
        applied: Vec::new(),
    };
    for arg in sets {
        let path = overrides::apply(&mut doc, arg).map_err(|issue| ctx.at_set(arg, issue))?;
        ctx.applied.push((path, arg.clone()));
    }
    unsupported(&doc).map_err(|i| ctx.locate(i))?;
    let mut scene = deserialize(&doc).map_err(|i| ctx.locate(i))?;
    validate::validate(&scene, &doc).map_err(|i| ctx.locate(i))?;
    if let Some(p) = scene.cloth.path.as_deref() {
        let from_set = ctx.set_for(&keys(&["cloth", "path"])).is_some();
        let resolved = match base {
            Some(dir) if !from_set => dir.join(p),
            _ => Path::new(p).to_path_buf(),
        };
        if !resolved.is_file() {
            let issue = Issue::new(
                keys(&["cloth", "path"]),
                SceneErrorKind::BadValue,
                format!("no such file: `{}`", resolved.display()),
            )
            .allowed("an existing OBJ file; paths in a scene file are relative to its directory");
            return Err(ctx.locate(issue));
        }
        scene.cloth.path = Some(resolved.to_string_lossy().into_owned());
    }
    Ok(scene)
}

/// What the messages need to say where a problem is.
struct Ctx<'a> {
    origin: &'a str,
    text: &'a str,
    /// The key path each `--set` wrote, with the argument, in order.
    applied: Vec<(KeyPath, String)>,
}

impl Ctx<'_> {
    /// The last `--set` that wrote `path` or a table containing it.
    fn set_for(&self, path: &[Seg]) -> Option<&str> {
        self.applied
            .iter()
            .rev()
            .find(|(p, _)| path.starts_with(p))
            .map(|(_, a)| a.as_str())
    }

    /// The error for `issue`, located at a `--set` or at a line of the file.
    fn locate(&self, issue: Issue) -> SceneError {
        if let Some(arg) = self.set_for(&issue.path) {
            return self.at_set(arg, issue);
        }
        let (line, complete, depth) = line_of(self.text, &issue.path);
        if !complete {
            // The deepest part that exists in the file; if a --set created what
            // lies below it, that --set is the better place to point at.
            let missing = &issue.path[..(depth + 1).min(issue.path.len())];
            if let Some((_, arg)) = self
                .applied
                .iter()
                .rev()
                .find(|(p, _)| p.starts_with(missing))
            {
                let arg = arg.clone();
                return self.at_set(&arg, issue);
            }
        }
        self.error(issue, line, None)
    }

    /// The error for `issue` caused by the `--set` argument `arg`.
    fn at_set(&self, arg: &str, issue: Issue) -> SceneError {
        self.error(issue, None, Some(arg.to_owned()))
    }

    fn error(&self, issue: Issue, line: Option<usize>, set: Option<String>) -> SceneError {
        SceneError {
            kind: issue.kind,
            file: self.origin.to_owned(),
            line,
            set,
            key: (!issue.path.is_empty()).then(|| dotted(&issue.path)),
            message: issue.message,
            allowed: issue.allowed,
        }
    }
}

fn syntax_error(origin: &str, text: &str, e: &toml::de::Error) -> SceneError {
    let line = e.span().map(|s| line_at(text, s.start));
    SceneError {
        kind: SceneErrorKind::Syntax,
        file: origin.to_owned(),
        line,
        set: None,
        key: None,
        message: format!("TOML syntax error: {}", e.message().trim()),
        allowed: None,
    }
}

/// 1-based line of byte `offset` in `text`.
fn line_at(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

fn unsupported(doc: &toml::Table) -> Result<(), Issue> {
    for (key, header, plan) in UNSUPPORTED {
        if doc.contains_key(key) {
            return Err(Issue::new(
                keys(&[key]),
                SceneErrorKind::Unsupported,
                format!("section {header} is not supported by this version of drape yet ({plan})"),
            )
            .allowed("remove the section"));
        }
    }
    Ok(())
}

/// Deserialises via a canonical TOML text, so serde's errors carry a span that
/// maps back to a key path (and from there to the original file or a `--set`).
fn deserialize(doc: &toml::Table) -> Result<Scene, Issue> {
    let canon = toml::to_string(doc).map_err(|e| {
        Issue::new(
            KeyPath::new(),
            SceneErrorKind::BadValue,
            e.to_string().trim(),
        )
    })?;
    toml::from_str::<Scene>(&canon).map_err(|e| translate(&canon, &e))
}

/// Turns a serde error into an issue at the key its span points to.
fn translate(canon: &str, e: &toml::de::Error) -> Issue {
    let mut path = match (DeTable::parse(canon), e.span()) {
        (Ok(root), Some(span)) => path_at(root.get_ref(), &span),
        _ => KeyPath::new(),
    };
    let msg = e.message().trim();
    let expected = |m: &str| {
        m.split_once(", expected ")
            .map(|(_, x)| x.trim_start_matches("one of ").to_owned())
    };
    let described = |path: &KeyPath, fallback: Option<String>| {
        schema::allowed(&dotted(path))
            .map(str::to_owned)
            .or(fallback.map(|x| plain(&x)))
    };
    let (kind, message, allowed) = if let Some(rest) = msg.strip_prefix("unknown field ") {
        let list = expected(rest).unwrap_or_else(|| "no keys".to_owned());
        (
            SceneErrorKind::UnknownKey,
            "unknown key".to_owned(),
            Some(list),
        )
    } else if let Some(rest) = msg.strip_prefix("missing field ") {
        path.push(Seg::Key(rest.trim_matches('`').to_owned()));
        let allowed = described(&path, None);
        (
            SceneErrorKind::MissingKey,
            "missing required key".to_owned(),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("unknown variant ") {
        let value = rest.split(", expected").next().unwrap_or(rest);
        let allowed = described(&path, expected(rest));
        (
            SceneErrorKind::BadValue,
            format!("{value} is not a valid value"),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("invalid type: ") {
        let found = rest.split(", expected").next().unwrap_or(rest);
        let allowed = described(&path, expected(rest));
        (
            SceneErrorKind::WrongType,
            format!("wrong type: found {found}"),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("invalid length ") {
        let n = rest.split(", expected").next().unwrap_or(rest);
        let allowed = described(&path, expected(rest));
        (
            SceneErrorKind::WrongType,
            format!("wrong number of elements: {n}"),
            allowed,
        )
    } else if let Some(rest) = msg.strip_prefix("invalid value: ") {
        let found = rest.split(", expected").next().unwrap_or(rest);
        let allowed = described(&path, expected(rest));
        (
            SceneErrorKind::BadValue,
            format!("invalid value: {found}"),
            allowed,
        )
    } else {
        let allowed = described(&path, None);
        (SceneErrorKind::BadValue, msg.to_owned(), allowed)
    };
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
    }
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

/// The key path of the smallest key or value whose span contains `span`.
fn path_at(root: &DeTable<'_>, span: &Range<usize>) -> KeyPath {
    let mut best: Option<(usize, KeyPath)> = None;
    let mut here = KeyPath::new();
    search_table(root, span, &mut here, &mut best);
    best.map(|(_, p)| p).unwrap_or_default()
}

fn consider(
    s: Range<usize>,
    span: &Range<usize>,
    here: &KeyPath,
    best: &mut Option<(usize, KeyPath)>,
) {
    if s.start <= span.start && span.end <= s.end {
        let len = s.end - s.start;
        if best.as_ref().is_none_or(|(l, _)| len < *l) {
            *best = Some((len, here.clone()));
        }
    }
}

fn search_table(
    t: &DeTable<'_>,
    span: &Range<usize>,
    here: &mut KeyPath,
    best: &mut Option<(usize, KeyPath)>,
) {
    for (k, v) in t.iter() {
        here.push(Seg::Key(k.get_ref().to_string()));
        consider(k.span(), span, here, best);
        search_value(v, span, here, best);
        here.pop();
    }
}

fn search_value(
    v: &Spanned<DeValue<'_>>,
    span: &Range<usize>,
    here: &mut KeyPath,
    best: &mut Option<(usize, KeyPath)>,
) {
    consider(v.span(), span, here, best);
    match v.get_ref() {
        DeValue::Table(t) => search_table(t, span, here, best),
        DeValue::Array(a) => {
            for (i, e) in a.iter().enumerate() {
                here.push(Seg::Index(i));
                search_value(e, span, here, best);
                here.pop();
            }
        }
        _ => {}
    }
}

/// The line of `path` in `text`: of the key itself, or of the deepest part of
/// the path that exists. Also whether the whole path exists and how many of its
/// steps do.
fn line_of(text: &str, path: &[Seg]) -> (Option<usize>, bool, usize) {
    let Ok(root) = DeTable::parse(text) else {
        return (None, false, 0);
    };
    let mut value: Option<&Spanned<DeValue<'_>>> = None;
    let mut table: Option<&DeTable<'_>> = Some(root.get_ref());
    let mut line = None;
    for (depth, seg) in path.iter().enumerate() {
        let found = match (seg, table, value.map(Spanned::get_ref)) {
            (Seg::Key(k), Some(t), _) => t
                .iter()
                .find(|(key, _)| key.get_ref().as_ref() == k.as_str())
                .map(|(key, v)| (key.span().start, v)),
            (Seg::Index(i), _, Some(DeValue::Array(a))) => a.get(*i).map(|v| (v.span().start, v)),
            _ => None,
        };
        let Some((start, v)) = found else {
            return (line, false, depth);
        };
        line = Some(line_at(text, start));
        value = Some(v);
        table = v.get_ref().as_table();
    }
    (line, true, path.len())
}
