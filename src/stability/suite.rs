//! Which scenes a suite runs: the hard cases built into the binary, or every
//! scene file of a folder (`drape stability --suite DIR`).
//!
//! A suite loads every scene it runs when it is made, so that a bad scene is
//! an error before the first run. A built-in scene is named
//! `scenes/hard/NAME.toml (embedded)` in messages; the files it reads (the
//! sliver's OBJ mesh) are written to a temporary folder that lives as long as
//! the suite.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::cases::{CASES, Case, OTHER};
use super::{StabilityError, Variant};
use crate::scene::{Scene, load_scene_file, load_scene_str_in};

/// One scene of a suite, loaded, with how the suite runs it.
#[derive(Debug, Clone)]
pub struct SuiteCase {
    /// The case name: the scene file's name without `.toml`.
    pub name: String,
    /// How the suite runs it: the hard case of the same name, or [`OTHER`].
    pub plan: &'static Case,
    /// The scene as its file says.
    pub scene: Scene,
}

/// The scenes of one run of `drape stability`.
#[derive(Debug)]
pub struct Suite {
    /// The cases, in the order they run.
    pub cases: Vec<SuiteCase>,
    /// Where the built-in scenes' files were written (removed on drop): the
    /// scenes' `cloth.path` point into it until the suite is dropped.
    _files: Option<TempFolder>,
}

impl Suite {
    /// The built-in hard cases named in `names` (all when empty), in suite order.
    pub fn embedded(names: &[String]) -> Result<Suite, StabilityError> {
        let known: Vec<&str> = CASES.iter().map(|c| c.name).collect();
        check_names(names, &known)?;
        let chosen: Vec<&'static Case> = CASES
            .iter()
            .filter(|c| names.is_empty() || names.iter().any(|n| n == c.name))
            .collect();
        let files = if chosen.iter().any(|c| !c.files.is_empty()) {
            let folder = TempFolder::new()?;
            for (name, text) in chosen.iter().flat_map(|c| c.files) {
                folder.write(name, text)?;
            }
            Some(folder)
        } else {
            None
        };
        let dir = files.as_ref().map_or(Path::new("."), |f| f.path.as_path());
        let mut cases = Vec::with_capacity(chosen.len());
        for plan in chosen {
            let origin = format!("scenes/hard/{}.toml (embedded)", plan.name);
            cases.push(SuiteCase {
                name: plan.name.to_string(),
                plan,
                scene: load_scene_str_in(plan.toml, &origin, dir, &[])?,
            });
        }
        Ok(Suite {
            cases,
            _files: files,
        })
    }

    /// Every `*.toml` scene of `dir` (those named in `names` when not empty):
    /// the hard cases' names first, in suite order and with their settings,
    /// then the others by name, run as [`OTHER`] says.
    pub fn from_dir(dir: &Path, names: &[String]) -> Result<Suite, StabilityError> {
        let read_error = |source| StabilityError::ReadSuite {
            dir: dir.to_path_buf(),
            source,
        };
        let mut paths: Vec<PathBuf> = Vec::new();
        for entry in std::fs::read_dir(dir).map_err(read_error)? {
            let path = entry.map_err(read_error)?.path();
            if path.extension().is_some_and(|e| e == "toml") && path.is_file() {
                paths.push(path);
            }
        }
        if paths.is_empty() {
            return Err(StabilityError::EmptySuite {
                dir: dir.to_path_buf(),
            });
        }
        let stem = |p: &Path| {
            p.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        let order = |p: &Path| {
            let name = stem(p);
            let rank = CASES.iter().position(|c| c.name == name);
            (rank.unwrap_or(CASES.len()), name)
        };
        paths.sort_by_key(|p| order(p));
        let known: Vec<String> = paths.iter().map(|p| stem(p)).collect();
        check_names(names, &known)?;
        let mut cases = Vec::new();
        for path in &paths {
            let name = stem(path);
            if !names.is_empty() && !names.contains(&name) {
                continue;
            }
            let plan = CASES.iter().find(|c| c.name == name).unwrap_or(&OTHER);
            cases.push(SuiteCase {
                scene: load_scene_file(path, &[])?,
                name,
                plan,
            });
        }
        Ok(Suite {
            cases,
            _files: None,
        })
    }

    /// Every run of the suite: each case with each integrator it allows (those
    /// of `--quick` with `quick`), adaptivity on (when the scene adapts), then
    /// off where the case allows.
    pub fn variants(&self, quick: bool) -> Vec<Variant<'_>> {
        let mut out = Vec::new();
        for case in &self.cases {
            let integrators = if quick {
                case.plan.quick_integrators
            } else {
                case.plan.integrators
            };
            for &integrator in integrators {
                let adapts = case.scene.adapt.is_some();
                for adaptive in [true, false] {
                    if (adaptive && adapts) || (!adaptive && case.plan.adapt_off) {
                        out.push(Variant {
                            case,
                            integrator,
                            adaptive,
                        });
                    }
                }
            }
        }
        out
    }
}

/// An error naming the first of `names` that is not in `known`.
fn check_names<S: AsRef<str>>(names: &[String], known: &[S]) -> Result<(), StabilityError> {
    match names
        .iter()
        .find(|n| !known.iter().any(|k| k.as_ref() == n.as_str()))
    {
        Some(name) => Err(StabilityError::UnknownCase {
            name: name.clone(),
            known: known
                .iter()
                .map(AsRef::as_ref)
                .collect::<Vec<_>>()
                .join(", "),
        }),
        None => Ok(()),
    }
}

/// A fresh folder under the system's temporary directory, removed on drop.
#[derive(Debug)]
struct TempFolder {
    path: PathBuf,
}

impl TempFolder {
    fn new() -> Result<TempFolder, StabilityError> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!("drape-stability-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&path).map_err(|source| StabilityError::Files {
            path: path.clone(),
            source,
        })?;
        Ok(TempFolder { path })
    }

    fn write(&self, name: &str, text: &str) -> Result<(), StabilityError> {
        let path = self.path.join(name);
        std::fs::write(&path, text).map_err(|source| StabilityError::Files { path, source })
    }
}

impl Drop for TempFolder {
    fn drop(&mut self) {
        // Nothing to report if it fails: the folder is in the temporary directory.
        let _ = std::fs::remove_dir_all(&self.path);
    }
}
