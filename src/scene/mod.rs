//! Scene files: TOML parsing with located errors, `--set` overrides, validation.
//!
//! ```text
//! TOML text -> toml::Table -> apply --set -> fill material.preset -> Scene (serde)
//!     -> validate -> resolve cloth.path
//! ```
//! Every error names the file, the line (or the `--set`) and the key; see
//! [`SceneError`] and `docs/scenes.md`.

pub mod camera;
mod error;
#[cfg(test)]
mod key_table_tests;
mod limits;
pub mod model;
mod overrides;
mod parse;
pub mod presets;
pub mod resolve;
mod schema;
mod sequence_files;
mod serde_errors;
mod spans;
mod validate;
mod validate_adapt;
mod validate_attach;
mod validate_body;
mod validate_collide;
mod validate_garment;
mod validate_material;
mod validate_measure;
mod validate_motion;
mod validate_region;
mod validate_step;

use std::path::Path;

pub use camera::CameraTable;
pub use error::{SceneError, SceneErrorKind};
pub use limits::{MAX_COUNT, MAX_RESOLUTION};
pub use model::*;
pub use resolve::cloth_spec;

/// The built-in scene used when no scene file is given (`src/scene/default.toml`).
pub const DEFAULT_SCENE_TOML: &str = include_str!("default.toml");

/// Origin named in messages about the built-in scene.
pub const DEFAULT_SCENE_ORIGIN: &str = "<default scene>";

/// Reads, overrides and validates the scene file at `path`.
///
/// `overrides` are `--set` arguments `dotted.path=value`, applied in order before
/// validation. `cloth.path` is resolved against the scene file's directory (a path
/// given by `--set` is taken as is, relative to the current directory) and stored
/// back resolved.
pub fn load_scene_file(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        kind: SceneErrorKind::Io,
        file: origin.as_str().into(),
        line: None,
        set: None,
        key: None,
        message: format!("cannot read the scene file: {e}").into(),
        allowed: None,
    })?;
    parse::load(&text, &origin, path.parent(), overrides)
}

/// Parses, overrides and validates scene `text`; `origin` names it in messages.
/// `cloth.path` is taken relative to the current directory.
pub fn load_scene_str(text: &str, origin: &str, overrides: &[String]) -> Result<Scene, SceneError> {
    parse::load(text, origin, None, overrides)
}

/// Parses, overrides and validates scene `text`; `origin` names it in messages
/// and `cloth.path` (and an obstacle's files) are taken relative to `dir`.
pub fn load_scene_str_in(
    text: &str,
    origin: &str,
    dir: &Path,
    overrides: &[String],
) -> Result<Scene, SceneError> {
    parse::load(text, origin, Some(dir), overrides)
}

/// The built-in default scene ([`DEFAULT_SCENE_TOML`]) with `overrides` applied.
pub fn default_scene(overrides: &[String]) -> Result<Scene, SceneError> {
    load_scene_str(DEFAULT_SCENE_TOML, DEFAULT_SCENE_ORIGIN, overrides)
}
