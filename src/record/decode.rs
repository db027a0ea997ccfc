//! The cloth mesh of one frame, decoded back from a recording: what the viewer shows at that
//! frame (the latest value of each `cloth/mesh` component at or before it), mapped back onto
//! the simulated mesh (vertices, triangles, their levels and their classes).

use std::path::Path;

use super::inspect::{InspectError, Message, RecordingFile};
use super::mesh::{DUPLICATE_COMPONENT, LEVEL_COMPONENT, simulated_triangles};
use super::{ENTITY_MESH, TIMELINE_FRAME};
use rerun::external::arrow::array::{
    Array, ArrayRef, AsArray, FixedSizeListArray,
    types::{Float32Type, UInt8Type, UInt16Type, UInt32Type},
};
use rerun::log::Chunk;

/// The simulated cloth mesh at one frame, as the recording holds it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClothFrame {
    /// The frame these values are for.
    pub frame: i64,
    /// Positions of the simulated vertices (`f32`, m), in the engine's vertex order.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals of the simulated vertices.
    pub normals: Vec<[f32; 3]>,
    /// Triangles as indices into `positions`, in the engine's triangle order.
    pub triangles: Vec<[u32; 3]>,
    /// Refinement level per triangle.
    pub levels: Vec<u8>,
    /// Class id per triangle (its level, or its panel index with `--colour-by panel`): the
    /// class id of its recorded corners, which share one; empty when the recording has no
    /// class ids.
    pub classes: Vec<u16>,
    /// Vertices of the recorded `Mesh3D` (the simulated ones and their copies per level).
    pub recorded_vertices: usize,
    /// The frame whose row last logged the topology (at or before `frame`).
    pub topology_frame: i64,
}

/// The latest value of one component: the frame it was logged at, and the cell.
type Latest = Option<(i64, ArrayRef)>;

/// The `cloth/mesh` components [`cloth_mesh_at`] reads, in the order of [`MeshRows::latest`].
const MESH_COMPONENTS: [&str; 6] = [
    "vertex_positions",
    "vertex_normals",
    "triangle_indices",
    LEVEL_COMPONENT,
    DUPLICATE_COMPONENT,
    "class_ids",
];

/// What one pass over a recording's `cloth/mesh` rows finds for one frame.
#[derive(Default)]
struct MeshRows {
    /// Per entry of [`MESH_COMPONENTS`]: its latest value at or before the frame.
    latest: [Latest; 6],
    /// First frame with a `cloth/mesh` row.
    first: Option<i64>,
    /// Last frame with a `cloth/mesh` row.
    last: Option<i64>,
    /// Whether a `cloth/mesh` row is logged at the frame itself.
    at_frame: bool,
}

/// Decodes the recording at `path` and rebuilds the cloth mesh at `frame`.
///
/// Fails like [`super::inspect::inspect`] on a file that does not decode, with
/// [`InspectError::NoFrame`] when the recording holds no `cloth/mesh` row at `frame`, and with
/// [`InspectError::Decode`] when the mesh's components do not fit together (a copy or an
/// index past the recorded vertices, a level count other than the triangle count).
pub fn cloth_mesh_at(path: &Path, frame: i64) -> Result<ClothFrame, InspectError> {
    let file = RecordingFile::read(path)?;
    let mut rows = MeshRows::default();
    file.read_messages(|_, msg| {
        if let Message::Recording {
            chunk: Some(chunk), ..
        } = msg
        {
            rows.add_chunk(&chunk, frame);
        }
        Ok(())
    })?;
    rows.rebuild(path, frame)
}

impl MeshRows {
    /// Takes in one chunk: only the temporal `cloth/mesh` chunks on the `frame` timeline
    /// count; a later row at or before `frame` replaces an earlier value.
    fn add_chunk(&mut self, chunk: &Chunk, frame: i64) {
        if chunk.is_static()
            || chunk.entity_path().to_string().trim_start_matches('/') != ENTITY_MESH
        {
            return;
        }
        let Some(times) = timeline_times(chunk, TIMELINE_FRAME) else {
            return;
        };
        for &t in &times {
            self.first = Some(self.first.map_or(t, |f| f.min(t)));
            self.last = Some(self.last.map_or(t, |l| l.max(t)));
            self.at_frame |= t == frame;
        }
        for (slot, name) in self.latest.iter_mut().zip(MESH_COMPONENTS) {
            let Some(array) = chunk.component_descriptors().find_map(|d| {
                let c = d.component.as_str();
                (c == name || c.ends_with(&format!(":{name}")))
                    .then(|| chunk.components().get_array(d.component))
                    .flatten()
            }) else {
                continue;
            };
            for (row, &t) in times.iter().enumerate() {
                if t <= frame && array.is_valid(row) && slot.as_ref().is_none_or(|(s, _)| *s <= t) {
                    *slot = Some((t, array.value(row)));
                }
            }
        }
    }

    /// The simulated mesh at `frame` from the latest values: the recorded vertices less
    /// their per-level copies, and the triangles mapped back onto the simulated vertices.
    fn rebuild(self, path: &Path, frame: i64) -> Result<ClothFrame, InspectError> {
        let no_frame = || InspectError::NoFrame {
            frame,
            first: self.first.unwrap_or(0),
            last: self.last.unwrap_or(0),
        };
        let bad = |reason: &str| InspectError::Decode {
            path: path.to_path_buf(),
            index: 0,
            reason: format!("cloth/mesh at frame {frame}: {reason}"),
        };
        if !self.at_frame {
            return Err(no_frame());
        }
        let [positions, normals, indices, levels, copies, class_ids] = &self.latest;
        let (Some((_, positions)), Some((topology_frame, indices))) = (positions, indices) else {
            return Err(no_frame());
        };
        let positions = triples::<Float32Type, f32>(positions).ok_or_else(|| bad("positions"))?;
        let normals = match normals {
            Some((_, n)) => triples::<Float32Type, f32>(n).ok_or_else(|| bad("normals"))?,
            None => Vec::new(),
        };
        let indices = triples::<UInt32Type, u32>(indices).ok_or_else(|| bad("indices"))?;
        let levels = levels
            .as_ref()
            .and_then(|(_, l)| l.as_primitive_opt::<UInt8Type>())
            .map(|l| l.values().to_vec())
            .ok_or_else(|| bad("no triangle_level"))?;
        let copies = copies
            .as_ref()
            .and_then(|(_, c)| c.as_primitive_opt::<UInt32Type>())
            .map(|c| c.values().to_vec())
            .unwrap_or_default();
        let recorded_vertices = positions.len();
        let vertices = recorded_vertices
            .checked_sub(copies.len())
            .ok_or_else(|| bad("more copies than vertices"))?;
        let triangles = simulated_triangles(vertices, &indices, &copies)
            .filter(|t| t.iter().flatten().all(|&i| (i as usize) < vertices))
            .ok_or_else(|| bad("an index past the vertices"))?;
        if levels.len() != triangles.len() {
            return Err(bad("not one level per triangle"));
        }
        let vertex_classes = class_ids
            .as_ref()
            .and_then(|(_, c)| c.as_primitive_opt::<UInt16Type>())
            .map(|c| c.values().to_vec())
            .unwrap_or_default();
        let classes = if vertex_classes.is_empty() {
            Vec::new()
        } else {
            indices
                .iter()
                .map(|t| vertex_classes.get(t[0] as usize).copied())
                .collect::<Option<Vec<u16>>>()
                .ok_or_else(|| bad("fewer class ids than vertices"))?
        };
        Ok(ClothFrame {
            frame,
            positions: positions[..vertices].to_vec(),
            normals: normals.into_iter().take(vertices).collect(),
            triangles,
            levels,
            classes,
            recorded_vertices,
            topology_frame: *topology_frame,
        })
    }
}

/// The raw times of `chunk`'s rows on the timeline `name` (frame numbers, or
/// nanoseconds of `sim_time`); `None` when the chunk is not on it.
pub(super) fn timeline_times(chunk: &Chunk, name: &str) -> Option<Vec<i64>> {
    chunk
        .timelines()
        .iter()
        .find(|(n, _)| n.as_str() == name)
        .map(|(_, col)| col.times_raw().to_vec())
}

/// A list cell of fixed-size-3 lists as triples, or `None` when it is not one.
pub(super) fn triples<T, V>(cell: &ArrayRef) -> Option<Vec<[V; 3]>>
where
    T: rerun::external::arrow::datatypes::ArrowPrimitiveType<Native = V>,
    V: rerun::external::arrow::datatypes::ArrowNativeType,
{
    let list: &FixedSizeListArray = cell.as_fixed_size_list_opt()?;
    if list.value_length() != 3 {
        return None;
    }
    let values: &[V] = list.values().as_primitive_opt::<T>()?.values();
    Some(values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}
