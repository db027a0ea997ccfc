//! `--set dotted.path=value` overrides. They are applied to the parsed document
//! before it is deserialised, so they are checked exactly like the file's values.

use toml::{Table, Value};

use super::error::{Issue, KeyPath, SceneErrorKind, Seg, dotted};

/// Applies one `--set` argument to `doc` and returns the key path it set.
///
/// The value is read as a TOML value (`64`, `1e-5`, `[0, 0, -1]`, `"rk4"`); if it is
/// not valid TOML it is taken as a string (`rk4`, `corner:top_left`). Missing tables
/// are created; `pin.N.key` addresses the N-th `[[pin]]` (N = count appends one).
pub(crate) fn apply(doc: &mut Table, arg: &str) -> Result<KeyPath, Issue> {
    let Some((path, raw)) = arg.split_once('=') else {
        return Err(Issue::new(
            KeyPath::new(),
            SceneErrorKind::BadOverride,
            "expected `dotted.path=value`",
        )
        .allowed("e.g. `cloth.resolution=64` or `pin.0.region=corner:top_left`"));
    };
    let parts: Vec<&str> = path.split('.').map(str::trim).collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(Issue::new(
            KeyPath::new(),
            SceneErrorKind::BadOverride,
            format!("the key path `{path}` has an empty part"),
        )
        .allowed("keys separated by single dots, e.g. `simulation.dt`"));
    }
    let mut done = KeyPath::new();
    set_in_table(doc, &parts, parse_value(raw.trim()), &mut done)?;
    Ok(done)
}

/// A TOML value if `raw` is one, otherwise the string itself.
fn parse_value(raw: &str) -> Value {
    format!("v = {raw}")
        .parse::<Table>()
        .ok()
        .filter(|t| t.len() == 1)
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| Value::String(raw.to_owned()))
}

fn set_in_table(
    t: &mut Table,
    parts: &[&str],
    value: Value,
    done: &mut KeyPath,
) -> Result<(), Issue> {
    let Some((first, rest)) = parts.split_first() else {
        return Ok(());
    };
    done.push(Seg::Key((*first).to_owned()));
    if rest.is_empty() {
        t.insert((*first).to_owned(), value);
        return Ok(());
    }
    // A missing part followed by an index (`obstacle.0.shape` in a scene without
    // obstacles) is an array of tables, to which index 0 appends the first one.
    let next_is_index = rest.first().is_some_and(|p| p.parse::<usize>().is_ok());
    let child = t.entry((*first).to_owned()).or_insert_with(|| {
        if next_is_index {
            Value::Array(Vec::new())
        } else {
            Value::Table(Table::new())
        }
    });
    set_in_value(child, rest, value, done)
}

fn set_in_value(
    v: &mut Value,
    parts: &[&str],
    value: Value,
    done: &mut KeyPath,
) -> Result<(), Issue> {
    let Some((first, rest)) = parts.split_first() else {
        return Ok(());
    };
    match v {
        Value::Table(t) => set_in_table(t, parts, value, done),
        Value::Array(a) => {
            let Ok(i) = first.parse::<usize>() else {
                let here = dotted(done);
                return Err(Issue::new(
                    done.clone(),
                    SceneErrorKind::BadOverride,
                    format!("`{here}` is an array: address an element by its index"),
                )
                .allowed(format!("`{here}.N.{first}` with N from 0")));
            };
            let len = a.len();
            if i > len {
                return Err(Issue::new(
                    done.clone(),
                    SceneErrorKind::BadOverride,
                    format!("index {i} is out of range: the scene has {len}"),
                )
                .allowed(format!("an index from 0 to {len} ({len} appends one)")));
            }
            done.push(Seg::Index(i));
            if rest.is_empty() {
                match a.get_mut(i) {
                    Some(slot) => *slot = value,
                    None => a.push(value),
                }
                return Ok(());
            }
            if i == len {
                a.push(Value::Table(Table::new()));
            }
            match a.get_mut(i) {
                Some(elem) => set_in_value(elem, rest, value, done),
                None => Ok(()),
            }
        }
        other => Err(Issue::new(
            done.clone(),
            SceneErrorKind::WrongType,
            format!(
                "is a {}, not a table, so it has no key `{first}`",
                other.type_str()
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Table {
        "[cloth]\nresolution = 8\n[[pin]]\nregion = \"all\"\n"
            .parse()
            .expect("test document")
    }

    #[test]
    fn values_are_toml_or_strings() {
        let mut d = doc();
        apply(&mut d, "cloth.resolution=64").expect("set");
        apply(&mut d, "simulation.integrator=rk4").expect("set");
        apply(&mut d, "simulation.gravity=[0,0,-1]").expect("set");
        apply(&mut d, "pin.0.region=corner:top_left").expect("set");
        apply(&mut d, "pin.1.region=all").expect("append");
        assert_eq!(d["cloth"]["resolution"].as_integer(), Some(64));
        assert_eq!(d["simulation"]["integrator"].as_str(), Some("rk4"));
        assert_eq!(d["simulation"]["gravity"].as_array().map(Vec::len), Some(3));
        assert_eq!(d["pin"][0]["region"].as_str(), Some("corner:top_left"));
        assert_eq!(d["pin"][1]["region"].as_str(), Some("all"));
    }

    #[test]
    fn an_index_into_a_missing_array_creates_it() {
        let mut d = doc();
        apply(&mut d, "obstacle.0.shape=sphere").expect("first obstacle");
        assert_eq!(d["obstacle"][0]["shape"].as_str(), Some("sphere"));
        assert!(apply(&mut d, "wind_tables.1.x=1").is_err(), "index 1 of 0");
    }

    #[test]
    fn bad_paths_are_errors() {
        let mut d = doc();
        assert!(apply(&mut d, "cloth.resolution").is_err());
        assert!(apply(&mut d, "cloth..resolution=3").is_err());
        assert!(apply(&mut d, "pin.5.region=all").is_err());
        assert!(apply(&mut d, "pin.region=all").is_err());
        assert!(apply(&mut d, "cloth.resolution.x=1").is_err());
    }
}
