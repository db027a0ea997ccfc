//! Byte spans to key paths and key paths to lines, over toml's spanned parse tree.

use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::error::{KeyPath, Seg};

/// 1-based line of byte `offset` in `text`.
pub(crate) fn line_at(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The key path of the smallest key or value whose span contains `span`.
pub(crate) fn path_at(root: &DeTable<'_>, span: &Range<usize>) -> KeyPath {
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
pub(crate) fn line_of(text: &str, path: &[Seg]) -> (Option<usize>, bool, usize) {
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
