//! A `mesh_sequence`'s `files`: the pattern's placeholder, and the files it
//! or the list names, resolved against the scene file's directory.

use std::path::{Path, PathBuf};

use super::SequenceFiles;
use super::error::{Issue, KeyPath, SceneErrorKind, Seg};

/// The most frames a pattern is expanded to.
const MAX_FRAMES: u64 = 1_000_000;

/// The pattern's placeholder: `(text before, digits of zero padding (0: none),
/// text after)`, or what is wrong with it.
pub(super) fn placeholder(pattern: &str) -> Result<(&str, usize, &str), String> {
    let open = pattern.find('{');
    let close = pattern.find('}');
    let (Some(a), Some(b)) = (open, close) else {
        return Err(format!(
            "`{pattern}` has no placeholder for the frame number"
        ));
    };
    let after = &pattern[b + 1..];
    if b < a || after.contains(['{', '}']) || pattern[..a].contains('}') {
        return Err(format!(
            "`{pattern}` must have exactly one placeholder `{{}}` or `{{:0N}}`"
        ));
    }
    let spec = &pattern[a + 1..b];
    let width = match spec {
        "" => 0,
        s => s
            .strip_prefix(":0")
            .and_then(|d| d.parse::<usize>().ok())
            .filter(|&d| (1..=12).contains(&d))
            .ok_or_else(|| {
                format!(
                    "`{{{s}}}` in `{pattern}` is not a frame-number placeholder: use `{{}}` or `{{:0N}}` with N from 1 to 12 digits"
                )
            })?,
    };
    Ok((&pattern[..a], width, after))
}

/// The files of obstacle `i`'s `files`, resolved against `base` (`None`: as
/// written): a list's every file must exist; a pattern gives the files from
/// `first` up to the last consecutive number with a file, and its first must
/// exist. The issue names the missing path.
pub(super) fn resolve(
    i: usize,
    files: &SequenceFiles,
    first: u64,
    base: Option<&Path>,
) -> Result<Vec<String>, Issue> {
    let key: KeyPath = vec![
        Seg::Key("obstacle".into()),
        Seg::Index(i),
        Seg::Key("files".into()),
    ];
    let at = |p: &str| match base {
        Some(dir) => dir.join(p),
        None => PathBuf::from(p),
    };
    let missing = |key: KeyPath, path: &Path, what: &str| {
        Issue::new(
            key,
            SceneErrorKind::BadValue,
            format!("no such file: `{}`{what}", path.display()),
        )
        .allowed("existing OBJ files; paths in a scene file are relative to its directory")
    };
    match files {
        SequenceFiles::List(list) => list
            .iter()
            .enumerate()
            .map(|(n, f)| {
                let p = at(f);
                if p.is_file() {
                    Ok(p.to_string_lossy().into_owned())
                } else {
                    let mut k = key.clone();
                    k.push(Seg::Index(n));
                    Err(missing(k, &p, &format!(" (frame {n} of the list)")))
                }
            })
            .collect(),
        SequenceFiles::Pattern(pattern) => {
            let (before, width, after) = placeholder(pattern)
                .map_err(|why| Issue::new(key.clone(), SceneErrorKind::BadValue, why))?;
            let name = |n: u64| at(&format!("{before}{n:0width$}{after}"));
            let mut out = Vec::new();
            let mut n = first;
            while name(n).is_file() && n - first < MAX_FRAMES {
                out.push(name(n).to_string_lossy().into_owned());
                n += 1;
            }
            if out.is_empty() {
                let what = format!(" (the first frame, number {first}, of `{pattern}`)");
                return Err(missing(key, &name(first), &what));
            }
            Ok(out)
        }
    }
}
