//! The crate's layers (`docs/architecture.md`, "What each layer may import"),
//! checked on the source as a reader sees it: every `crate::<module>` path in
//! a top-level module's code (comments and unit tests left out) is an edge.
//! The test fails when a lower layer imports a higher one, when `kinematics`
//! imports anything but `math` and `spec`, or when the modules import each
//! other in a cycle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Layers from the bottom up; a module may import its own layer and those below.
const LAYERS: [&[&str]; 3] = [
    &["math", "spec"],
    &[
        "mesh",
        "garment",
        "kinematics",
        "pins",
        "world",
        "physics",
        "collide",
        "adapt",
        "sim",
    ],
    &[
        "scene",
        "cantilever",
        "summary",
        "record",
        "run",
        "check",
        "garmentcode",
        "bench",
        "stability",
        "cli",
    ],
];

/// The `.rs` files of each top-level module of `src`.
fn modules(src: &Path) -> BTreeMap<String, Vec<PathBuf>> {
    let mut modules: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for entry in std::fs::read_dir(src).expect("src/ readable") {
        let path = entry.expect("entry").path();
        let name = path
            .file_stem()
            .expect("name")
            .to_string_lossy()
            .into_owned();
        if name == "lib" || name == "main" {
            continue;
        }
        let files = modules.entry(name).or_default();
        if path.is_dir() {
            collect(&path, files);
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    modules
}

/// Every `.rs` file below `dir`, unit-test files and folders left out.
fn collect(dir: &Path, files: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("folder readable") {
        let path = entry.expect("entry").path();
        let name = path
            .file_name()
            .expect("name")
            .to_string_lossy()
            .into_owned();
        if path.is_dir() {
            if name != "tests" {
                collect(&path, files);
            }
        } else if name.ends_with(".rs") && name != "tests.rs" {
            files.push(path);
        }
    }
}

/// The modules a file's code names as `crate::<module>`.
fn imports(path: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(path).expect("source readable");
    let code: String = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let code = match code.find("#[cfg(test)]\nmod tests {") {
        Some(at) => &code[..at],
        None => &code[..],
    };
    code.match_indices("crate::")
        .map(|(at, _)| {
            code[at + 7..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect()
        })
        .collect()
}

fn layer(module: &str) -> usize {
    LAYERS
        .iter()
        .position(|l| l.contains(&module))
        .unwrap_or_else(|| {
            panic!("module `{module}` is in no layer of tests/integration/layers.rs")
        })
}

#[test]
fn no_module_imports_a_layer_above_it_or_closes_a_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let modules = modules(&src);
    let mut edges: BTreeMap<&str, BTreeSet<String>> = BTreeMap::new();
    for (module, files) in &modules {
        let to = edges.entry(module).or_default();
        for file in files {
            to.extend(
                imports(file)
                    .into_iter()
                    .filter(|m| m != module && modules.contains_key(m)),
            );
        }
    }
    let mut wrong = Vec::new();
    for (module, to) in &edges {
        for other in to {
            if layer(other) > layer(module) {
                wrong.push(format!("{module} imports {other}, a layer above it"));
            }
            if *module == "kinematics" && !["math", "spec"].contains(&other.as_str()) {
                wrong.push(format!("kinematics imports {other}"));
            }
        }
    }
    // A cycle: a module that reaches itself.
    for start in edges.keys() {
        let mut seen = BTreeSet::new();
        let mut stack: Vec<&str> = edges[start].iter().map(String::as_str).collect();
        while let Some(m) = stack.pop() {
            if m == *start {
                wrong.push(format!("{start} imports itself through a cycle"));
                break;
            }
            if seen.insert(m) {
                stack.extend(edges.get(m).into_iter().flatten().map(String::as_str));
            }
        }
    }
    println!(
        "{} top-level modules, {} import edges",
        modules.len(),
        edges.values().map(BTreeSet::len).sum::<usize>()
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
