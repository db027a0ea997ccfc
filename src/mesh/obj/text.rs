//! The loader's own pass over the OBJ text: what tobj lets through unchecked,
//! the `v` positions as tobj reads them, the `l` elements, which tobj does
//! not keep, and the text tobj reads the faces from, whose `v` lines are
//! stand-ins that tell which `v` line each face corner uses.

use std::collections::HashMap;
use std::path::Path;

use super::ObjError;
use crate::math::Vector;

/// What the text scan found.
pub(super) struct ObjText {
    /// The file's text for tobj, line numbers unchanged: every `l` line left
    /// empty (tobj reads an `l` of three or more vertices as a face), and every
    /// `v` line tobj accepts replaced by a stand-in whose x is the line's
    /// 0-based index among the `v` lines ([`stand_in`]), so that the position
    /// of a corner in tobj's models is which `v` line it uses. A `v` line tobj
    /// refuses stays as it is, for tobj to refuse.
    pub faces_text: String,
    /// Each `v` line's position as tobj reads it (`None` where tobj refuses it).
    pub positions: Vec<Option<Vector>>,
    /// The `l` elements, in file order.
    pub lines: Vec<LineElement>,
}

/// One `l` element of the file.
pub(super) struct LineElement {
    /// Its 1-based line number.
    pub line: usize,
    /// Its vertices as 0-based indices of the file's `v` lines, each in range.
    pub vertices: Vec<usize>,
    /// The object or group it lies in: one number per distinct name of the
    /// `o` and `g` lines, in order of first appearance, 0 before any.
    pub group: usize,
}

/// An `l` element before its indices are checked against the whole file.
struct RawLine {
    line: usize,
    group: usize,
    /// Each vertex's text and its 0-based index (negative ones resolved).
    vertices: Vec<(String, i64)>,
}

/// Reads the file and checks what tobj lets through: coordinates that are NaN
/// or infinite, face indices of 0 (OBJ counts from 1; tobj accepts a texture
/// index 0, which OBJ does not define), `vt` on some faces only (tobj fills a
/// corner without `vt` with another corner's coordinates, so that is recognised
/// from the text), and `l` elements (each index must name a `v` line).
pub(super) fn scan_text(path: &Path, name: &str) -> Result<ObjText, ObjError> {
    let text = read_text(path, name)?;
    let bad = |line: usize, reason: String| ObjError::BadLine {
        path: name.to_string(),
        line,
        reason,
    };
    let (mut with, mut without) = (0usize, 0usize);
    let mut positions = Vec::new();
    let mut raw_lines = Vec::new();
    let mut groups = Groups::default();
    let mut faces_text = String::with_capacity(text.len());
    for (n, line) in text.lines().enumerate() {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        match tokens.first().copied() {
            Some(kind @ ("v" | "vt")) => {
                let value = tokens[1..]
                    .iter()
                    .filter_map(|t| t.parse::<f64>().ok())
                    .find(|x| !x.is_finite());
                if let Some(x) = value {
                    return Err(bad(
                        n + 1,
                        format!("`{kind}` has a coordinate that is not a finite number: {x}"),
                    ));
                }
                if kind == "v" {
                    let position = tobj_position(&tokens[1..]);
                    if position.is_some() {
                        faces_text.push_str(&stand_in(positions.len(), &tokens[1..]));
                        faces_text.push('\n');
                        positions.push(position);
                        continue;
                    }
                    positions.push(position);
                }
            }
            Some("f") => {
                for corner in &tokens[1..] {
                    if corner.split('/').any(|i| i.parse::<i64>() == Ok(0)) {
                        return Err(bad(
                            n + 1,
                            format!("face corner `{corner}` has index 0; OBJ indices start at 1"),
                        ));
                    }
                    match corner.split('/').nth(1) {
                        Some(vt) if !vt.is_empty() => with += 1,
                        _ => without += 1,
                    }
                }
            }
            Some("o" | "g") => groups.enter(line),
            Some("l") => {
                let mut element = line_element(&tokens[1..], n + 1, positions.len(), name)?;
                element.group = groups.current;
                raw_lines.push(element);
                faces_text.push('\n');
                continue;
            }
            _ => {}
        }
        faces_text.push_str(line);
        faces_text.push('\n');
    }
    if with > 0 && without > 0 {
        return Err(ObjError::PartialTexcoords {
            path: name.to_string(),
        });
    }
    let lines = check_line_indices(raw_lines, positions.len(), name)?;
    Ok(ObjText {
        faces_text,
        positions,
        lines,
    })
}

/// The objects and groups (`o`, `g`) the scan has met, by name.
#[derive(Default)]
struct Groups {
    /// The number of each name (from 1; 0 is before any `o` or `g`).
    number: HashMap<String, usize>,
    /// The number of the name the scan is in.
    current: usize,
}

impl Groups {
    /// Enters the object or group of the `o` or `g` line `line`, named as
    /// tobj names it: the rest of the line, trimmed.
    fn enter(&mut self, line: &str) {
        let name = line.trim_start()[1..].trim().to_owned();
        let next = self.number.len() + 1;
        self.current = *self.number.entry(name).or_insert(next);
    }
}

/// The file's text; a read error or a file that is not UTF-8 is [`ObjError::Read`].
fn read_text(path: &Path, name: &str) -> Result<String, ObjError> {
    let read = |reason: String| ObjError::Read {
        path: name.to_string(),
        reason,
    };
    match std::fs::read_to_string(path) {
        Ok(text) => Ok(text),
        Err(e) if e.kind() == std::io::ErrorKind::InvalidData => {
            Err(read("not a text file (it is not valid UTF-8)".into()))
        }
        Err(e) => Err(read(e.to_string())),
    }
}

/// A `v` line's position as tobj reads it: the first three numbers, divided by
/// a fourth (the homogeneous `w`) when there are exactly four; `None` where
/// tobj refuses the line.
fn tobj_position(tokens: &[&str]) -> Option<Vector> {
    let number = |k: usize| tokens.get(k).and_then(|t| t.parse::<f64>().ok());
    let mut p = [number(0)?, number(1)?, number(2)?];
    if tokens.len() == 4 {
        let w = number(3)?;
        if w == 0.0 {
            return None;
        }
        for c in &mut p {
            *c /= w;
        }
    }
    Some(Vector::from_array(p))
}

/// The stand-in for `v` line `index` (0-based) whose values after `v` are
/// `tokens`, which [`tobj_position`] accepts: `v index 0 0`, followed by the
/// line's values after its third when it has more than four (colours, which
/// tobj then reads, or refuses, as it would on the line itself). A homogeneous
/// `w` (exactly four values) is dropped; the loader divides by it itself.
fn stand_in(index: usize, tokens: &[&str]) -> String {
    let mut line = format!("v {index} 0 0");
    if tokens.len() > 4 {
        for t in &tokens[3..] {
            line.push(' ');
            line.push_str(t);
        }
    }
    line
}

/// Parses the vertices of the `l` element on line `line` (1-based), given
/// the number of `v` lines before it (negative indices count back from there).
fn line_element(
    tokens: &[&str],
    line: usize,
    positions_before: usize,
    name: &str,
) -> Result<RawLine, ObjError> {
    let bad = |reason: String| ObjError::BadLine {
        path: name.to_string(),
        line,
        reason,
    };
    if tokens.len() < 2 {
        return Err(bad(format!(
            "an `l` element needs at least two vertices, this one has {}",
            tokens.len()
        )));
    }
    let mut vertices = Vec::with_capacity(tokens.len());
    for &token in tokens {
        let index = token.split('/').next().unwrap_or("");
        let Ok(i) = index.parse::<i64>() else {
            return Err(bad(format!("`l` vertex `{token}` is not a vertex index")));
        };
        let absolute = match i {
            0 => {
                return Err(bad(format!(
                    "`l` vertex `{token}` has index 0; OBJ indices start at 1"
                )));
            }
            i if i < 0 => (positions_before as i64).saturating_add(i),
            i => i - 1,
        };
        vertices.push((token.to_string(), absolute));
    }
    Ok(RawLine {
        line,
        group: 0,
        vertices,
    })
}

/// Checks every `l` index against the file's `v` lines.
fn check_line_indices(
    raw: Vec<RawLine>,
    count: usize,
    name: &str,
) -> Result<Vec<LineElement>, ObjError> {
    raw.into_iter()
        .map(|element| {
            let vertices = element
                .vertices
                .iter()
                .map(|(token, i)| match usize::try_from(*i) {
                    Ok(i) if i < count => Ok(i),
                    _ => Err(ObjError::BadLine {
                        path: name.to_string(),
                        line: element.line,
                        reason: format!(
                            "`l` vertex `{token}` is out of range: the file has {count} \
                             vertices (`v` lines)"
                        ),
                    }),
                })
                .collect::<Result<Vec<usize>, ObjError>>()?;
            Ok(LineElement {
                line: element.line,
                group: element.group,
                vertices,
            })
        })
        .collect()
}
