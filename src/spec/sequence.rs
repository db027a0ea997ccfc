//! The keys of deforming mesh obstacles: a `mesh_sequence`'s files and an
//! articulated body's surface.

use serde::Deserialize;

/// The OBJ files of a `mesh_sequence` obstacle, one per frame.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum SequenceFiles {
    /// A pattern with one `{}` or `{:0N}` placeholder (N digits, zero-padded)
    /// for the frame number, e.g. `"body/frame_{:04}.obj"`: frames from
    /// `first_frame` up to the last consecutive number with a file.
    Pattern(String),
    /// The files in frame order.
    List(Vec<String>),
}

/// How an articulated obstacle meets the cloth.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum BodySurface {
    /// Each part is its own rigid primitive.
    #[default]
    Parts,
    /// The parts' surfaces, tessellated, form one triangle mesh whose vertices
    /// follow their parts (rigid skinning): a deforming mesh obstacle.
    SkinnedMesh,
}
