//! Loading: TOML text -> document -> `--set` overrides -> fabric preset -> `Scene`
//! -> validation, with every error located at a line of the file or at the `--set`
//! that caused it.

use std::path::Path;

use super::error::{Issue, KeyPath, SceneError, SceneErrorKind, Seg, dotted, keys};
use super::serde_errors::translate;
use super::spans::{line_at, line_of};
use super::{Scene, SequenceFiles, overrides, presets, validate};

/// Sections the format names that this version does not implement, with what is planned.
/// (None at present; the mechanism stays for sections added to the format later.)
const UNSUPPORTED: [(&str, &str, &str); 0] = [];

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
    // Validation sees the document as written: a preset's values are not keys
    // the scene wrote.
    let filled = presets::expand(doc.clone()).map_err(|i| ctx.locate(i))?;
    let mut scene = deserialize(&filled).map_err(|i| ctx.locate(i))?;
    validate::validate(&scene, &doc).map_err(|i| ctx.locate(i))?;
    if let Some(p) = scene.cloth.path.as_deref() {
        let from_set = ctx.set_for(&keys(&["cloth", "path"])).is_some();
        let resolved = match base {
            Some(dir) if !from_set => dir.join(p),
            _ => Path::new(p).to_path_buf(),
        };
        if let Some(issue) = not_a_file(keys(&["cloth", "path"]), &resolved) {
            return Err(ctx.locate(issue));
        }
        scene.cloth.path = Some(resolved.to_string_lossy().into_owned());
    }
    for i in 0..scene.obstacle.len() {
        if let Some(files) = &scene.obstacle[i].files {
            let key = vec![
                Seg::Key("obstacle".into()),
                Seg::Index(i),
                Seg::Key("files".into()),
            ];
            let dir = if ctx.set_for(&key).is_some() {
                None
            } else {
                base
            };
            let first = scene.obstacle[i].first_frame.unwrap_or(0);
            let list = super::sequence_files::resolve(i, files, first, dir)
                .map_err(|issue| ctx.locate(issue))?;
            scene.obstacle[i].files = Some(SequenceFiles::List(list));
        }
        let Some(p) = scene.obstacle[i].path.as_deref() else {
            continue;
        };
        let key = vec![
            Seg::Key("obstacle".into()),
            Seg::Index(i),
            Seg::Key("path".into()),
        ];
        let resolved = match base {
            Some(dir) if ctx.set_for(&key).is_none() => dir.join(p),
            _ => Path::new(p).to_path_buf(),
        };
        if let Some(issue) = not_a_file(key, &resolved) {
            return Err(ctx.locate(issue));
        }
        scene.obstacle[i].path = Some(resolved.to_string_lossy().into_owned());
    }
    Ok(scene)
}

/// The issue at `key` if `path` is not an existing file (missing, or a directory).
fn not_a_file(key: KeyPath, path: &Path) -> Option<Issue> {
    let what = if path.is_file() {
        return None;
    } else if path.is_dir() {
        format!("`{}` is a directory, not an OBJ file", path.display())
    } else {
        format!("no such file: `{}`", path.display())
    };
    Some(
        Issue::new(key, SceneErrorKind::BadValue, what)
            .allowed("an existing OBJ file; paths in a scene file are relative to its directory"),
    )
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
        // A requirement that a --set introduced (e.g. `--set pin.0.region=box` needs
        // box_min): point at the file's line and name that --set.
        let cause = issue
            .cause
            .as_ref()
            .and_then(|c| self.set_for(c))
            .map(str::to_owned);
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
        self.error(issue, line, cause)
    }

    /// The error for `issue` caused by the `--set` argument `arg`.
    fn at_set(&self, arg: &str, issue: Issue) -> SceneError {
        self.error(issue, None, Some(arg.to_owned()))
    }

    fn error(&self, issue: Issue, line: Option<usize>, set: Option<String>) -> SceneError {
        SceneError {
            kind: issue.kind,
            file: self.origin.into(),
            line,
            set: set.map(Into::into),
            key: (!issue.path.is_empty()).then(|| dotted(&issue.path).into()),
            message: issue.message.into(),
            allowed: issue.allowed.map(Into::into),
        }
    }
}

fn syntax_error(origin: &str, text: &str, e: &toml::de::Error) -> SceneError {
    let line = e.span().map(|s| line_at(text, s.start));
    SceneError {
        kind: SceneErrorKind::Syntax,
        file: origin.into(),
        line,
        set: None,
        key: None,
        message: format!("TOML syntax error: {}", e.message().trim()).into(),
        allowed: None,
    }
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
