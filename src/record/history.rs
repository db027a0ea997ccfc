//! `drape inspect FILE --at X,Y,Z [--frame N]`: the history of the triangle under a point,
//! read back from a recording. Every frame's cloth mesh (positions, topology, levels and the
//! refinement decisions) and every event with its triangle's corners are decoded; the point
//! is placed on the nearest triangle at frame `N` and followed through the other frames
//! (`track.rs`), and [`History::report`] prints its level, ratio and state where they change
//! and every event whose triangle holds it.

use std::collections::BTreeMap;
use std::path::Path;
use std::rc::Rc;

use rerun::external::arrow::array::{
    Array, ArrayRef, AsArray, StringArray,
    types::{Float32Type, UInt8Type, UInt32Type},
};
use rerun::log::Chunk;

use super::decisions::{RATIO_COMPONENT, STATE_COMPONENT, TERM_COMPONENT};
use super::decode::triples;
use super::events::EVENT_CORNERS_COMPONENT;
use super::inspect::{InspectError, Message, RecordingFile};
use super::mesh::{DUPLICATE_COMPONENT, LEVEL_COMPONENT, simulated_triangles};
pub use super::track::Place;
use super::track::{follow, nearest};
use super::{ENTITY_EVENT_LOG, ENTITY_MESH, TIMELINE_FRAME, TIMELINE_SIM_TIME};

/// The `cloth/mesh` components the history reads, in the order of [`Cells::mesh`].
const COMPONENTS: [&str; 7] = [
    "vertex_positions",
    "triangle_indices",
    DUPLICATE_COMPONENT,
    LEVEL_COMPONENT,
    RATIO_COMPONENT,
    TERM_COMPONENT,
    STATE_COMPONENT,
];

/// The topology last logged: its frame, triangles and levels.
type Topology = (i64, Rc<Vec<[u32; 3]>>, Rc<Vec<u8>>);

/// What a history line shows of a frame: the level, and the ratio band, term and state.
type LineKey = (u8, Option<(usize, u8, u8)>);

/// What one frame logged: its `cloth/mesh` cells and its events.
#[derive(Default)]
struct Cells {
    sim_time: Option<f64>,
    mesh: [Option<ArrayRef>; 7],
    /// Each `events/log` row: its line and its triangle's corners, if any.
    events: Vec<(String, Option<[[f64; 3]; 3]>)>,
}

/// The cloth at one frame, as the viewer shows it: the latest value of each component.
#[derive(Debug, Clone, Default)]
pub struct MeshAt {
    /// Simulated time, s.
    pub sim_time: Option<f64>,
    /// Positions of the simulated vertices, m.
    pub positions: Vec<[f64; 3]>,
    /// Triangles of the simulated mesh.
    pub triangles: Rc<Vec<[u32; 3]>>,
    /// Level per triangle.
    pub levels: Rc<Vec<u8>>,
    /// The frame whose row logged the topology.
    pub topology_frame: i64,
    /// Per triangle: ratio, term and state code (empty without decisions).
    pub decisions: Vec<(f32, u8, u8)>,
    /// This frame's events: line and triangle corners.
    pub events: Vec<(String, Option<[[f64; 3]; 3]>)>,
}

/// The history of the triangle under a point.
#[derive(Debug, Clone)]
pub struct History {
    /// The point asked about, m.
    pub point: [f64; 3],
    /// The frame it was asked at.
    pub frame: i64,
    /// Distance from the point to the cloth at that frame, m.
    pub distance: f64,
    /// Per frame: where the point is followed to, with the frame's mesh.
    pub frames: BTreeMap<i64, (Place, MeshAt)>,
}

/// Decodes the recording at `path` and follows the point `at` (world coordinates, m) from
/// frame `frame` (the last frame when `None`) through every frame.
///
/// Fails like [`super::inspect::inspect`] on a file that does not decode, with
/// [`InspectError::NoFrame`] when `frame` has no cloth mesh, and with
/// [`InspectError::Decode`] when the mesh's components do not fit together.
pub fn history_at(path: &Path, at: [f64; 3], frame: Option<i64>) -> Result<History, InspectError> {
    let file = RecordingFile::read(path)?;
    let mut cells: BTreeMap<i64, Cells> = BTreeMap::new();
    file.read_messages(|_, msg| {
        if let Message::Recording {
            chunk: Some(chunk), ..
        } = msg
        {
            add_chunk(&mut cells, &chunk);
        }
        Ok(())
    })?;
    let meshes = resolve(path, cells)?;
    let (first, last) = match (meshes.keys().next(), meshes.keys().next_back()) {
        (Some(&f), Some(&l)) => (f, l),
        _ => {
            return Err(InspectError::NoFrame {
                frame: frame.unwrap_or(0),
                first: 0,
                last: 0,
            });
        }
    };
    let start = frame.unwrap_or(last);
    let mesh = meshes.get(&start).ok_or(InspectError::NoFrame {
        frame: start,
        first,
        last,
    })?;
    let (place, distance) = nearest(mesh, at).ok_or(InspectError::NoFrame {
        frame: start,
        first,
        last,
    })?;
    Ok(History {
        point: at,
        frame: start,
        distance,
        frames: follow(meshes, start, place),
    })
}

/// Takes in one chunk: the temporal rows of `cloth/mesh` and `events/log`.
fn add_chunk(cells: &mut BTreeMap<i64, Cells>, chunk: &Chunk) {
    let entity = chunk.entity_path().to_string();
    let entity = entity.trim_start_matches('/');
    if chunk.is_static() || (entity != ENTITY_MESH && entity != ENTITY_EVENT_LOG) {
        return;
    }
    let timeline = |name: &str| super::decode::timeline_times(chunk, name);
    let Some(frames) = timeline(TIMELINE_FRAME) else {
        return;
    };
    let times = timeline(TIMELINE_SIM_TIME);
    let column = |name: &str| {
        chunk.component_descriptors().find_map(|d| {
            let c = d.component.as_str();
            (c == name || c.ends_with(&format!(":{name}")))
                .then(|| chunk.components().get_array(d.component))
                .flatten()
        })
    };
    let cell = |array: Option<&rerun::external::arrow::array::ListArray>, row: usize| {
        array.filter(|a| a.is_valid(row)).map(|a| a.value(row))
    };
    if entity == ENTITY_MESH {
        let columns: Vec<_> = COMPONENTS.iter().map(|n| column(n)).collect();
        for (row, &f) in frames.iter().enumerate() {
            let c = cells.entry(f).or_default();
            if let Some(t) = times.as_ref().and_then(|t| t.get(row)) {
                c.sim_time = Some(*t as f64 * 1e-9);
            }
            for (slot, col) in c.mesh.iter_mut().zip(&columns) {
                if let Some(v) = cell(*col, row) {
                    *slot = Some(v);
                }
            }
        }
        return;
    }
    let (text, corners) = (column("text"), column(EVENT_CORNERS_COMPONENT));
    for (row, &f) in frames.iter().enumerate() {
        let Some(line) = cell(text, row) else {
            continue;
        };
        let Some(lines) = line.as_any().downcast_ref::<StringArray>() else {
            continue;
        };
        let tri = cell(corners, row)
            .and_then(|c| {
                c.as_primitive_opt::<Float32Type>()
                    .map(|c| c.values().to_vec())
            })
            .filter(|c| c.len() == 9)
            .map(|c| [0, 1, 2].map(|k| [0, 1, 2].map(|i| f64::from(c[3 * k + i]))));
        let c = cells.entry(f).or_default();
        c.events
            .extend(lines.iter().flatten().map(|l| (l.to_owned(), tri)));
    }
}

/// Every frame's mesh from the cells, each component carried from the last frame that
/// logged it.
fn resolve(
    path: &Path,
    cells: BTreeMap<i64, Cells>,
) -> Result<BTreeMap<i64, MeshAt>, InspectError> {
    let bad = |frame: i64, reason: &str| InspectError::Decode {
        path: path.to_path_buf(),
        index: 0,
        reason: format!("cloth/mesh at frame {frame}: {reason}"),
    };
    let mut latest: [Option<ArrayRef>; 7] = Default::default();
    let mut topology: Option<Topology> = None;
    let mut out = BTreeMap::new();
    for (frame, c) in cells {
        let logged_topology = c.mesh[1].is_some() || c.mesh[3].is_some();
        for (slot, v) in latest.iter_mut().zip(c.mesh) {
            if v.is_some() {
                *slot = v;
            }
        }
        let [positions, indices, copies, levels, ratio, term, state] = &latest;
        let Some(positions) = positions else {
            continue;
        };
        let positions =
            triples::<Float32Type, f32>(positions).ok_or_else(|| bad(frame, "positions"))?;
        let copies: Vec<u32> = copies
            .as_ref()
            .and_then(|c| {
                c.as_primitive_opt::<UInt32Type>()
                    .map(|c| c.values().to_vec())
            })
            .unwrap_or_default();
        let vertices = positions
            .len()
            .checked_sub(copies.len())
            .ok_or_else(|| bad(frame, "more copies than vertices"))?;
        if logged_topology || topology.is_none() {
            let (Some(indices), Some(levels)) = (indices, levels) else {
                return Err(bad(frame, "no topology logged at or before it"));
            };
            let indices =
                triples::<UInt32Type, u32>(indices).ok_or_else(|| bad(frame, "indices"))?;
            let triangles = simulated_triangles(vertices, &indices, &copies)
                .filter(|t| t.iter().flatten().all(|&i| (i as usize) < vertices))
                .ok_or_else(|| bad(frame, "an index past the vertices"))?;
            let levels = levels
                .as_primitive_opt::<UInt8Type>()
                .map(|l| l.values().to_vec())
                .filter(|l| l.len() == triangles.len())
                .ok_or_else(|| bad(frame, "not one level per triangle"))?;
            topology = Some((frame, triangles.into(), levels.into()));
        }
        let Some((topology_frame, triangles, levels)) = &topology else {
            continue;
        };
        let decisions = decisions(ratio, term, state)
            .filter(|d| d.len() == triangles.len())
            .unwrap_or_default();
        out.insert(
            frame,
            MeshAt {
                sim_time: c.sim_time,
                positions: positions[..vertices]
                    .iter()
                    .map(|p| p.map(f64::from))
                    .collect(),
                triangles: triangles.clone(),
                levels: levels.clone(),
                topology_frame: *topology_frame,
                decisions,
                events: c.events,
            },
        );
    }
    Ok(out)
}

/// The decision components zipped per triangle, when all three are there.
fn decisions(
    ratio: &Option<ArrayRef>,
    term: &Option<ArrayRef>,
    state: &Option<ArrayRef>,
) -> Option<Vec<(f32, u8, u8)>> {
    let ratio = ratio
        .as_ref()?
        .as_primitive_opt::<Float32Type>()?
        .values()
        .to_vec();
    let term = term
        .as_ref()?
        .as_primitive_opt::<UInt8Type>()?
        .values()
        .to_vec();
    let state = state
        .as_ref()?
        .as_primitive_opt::<UInt8Type>()?
        .values()
        .to_vec();
    (ratio.len() == term.len() && term.len() == state.len()).then(|| {
        ratio
            .into_iter()
            .zip(term)
            .zip(state)
            .map(|((r, t), s)| (r, t, s))
            .collect()
    })
}

/// How close (as a fraction of its longest edge) an event's triangle must come to the point
/// for the event to be the point's: the cloth moves between a recorded frame and a pass.
const EVENT_REACH: f64 = 0.1;

impl History {
    /// Whether an event whose triangle has `corners` holds the point, which is at `now` in
    /// the event's frame and at `before` in the frame before.
    fn touches(corners: &[[f64; 3]; 3], now: [f64; 3], before: [f64; 3]) -> bool {
        let longest = (0..3)
            .map(|k| {
                let d = [0, 1, 2].map(|i| corners[k][i] - corners[(k + 1) % 3][i]);
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            })
            .fold(0.0, f64::max);
        let reach = EVENT_REACH * longest;
        super::track::distance_to(*corners, now) <= reach
            || super::track::distance_to(*corners, before) <= reach
    }

    /// The history as text: the point and its triangle at the frame asked about, then one
    /// line per frame where the triangle's level, term, state or ratio band changes (and the
    /// first, last and asked frames), each followed by the events on the point since the
    /// frame before, with their reasons.
    pub fn report(&self) -> String {
        use super::decisions::{STATE_NAMES, TERM_NAMES, ratio_band};
        use std::fmt::Write;
        let mut s = String::new();
        let [x, y, z] = self.point;
        let _ = writeln!(
            s,
            "point ({x:.3}, {y:.3}, {z:.3}) m at frame {}: {:.1} mm from the cloth",
            self.frame,
            1e3 * self.distance
        );
        let _ = writeln!(
            s,
            "followed through {} frames (the same triangle while the mesh keeps its \
             topology, the nearest point of the new mesh after a remesh)",
            self.frames.len()
        );
        let _ = writeln!(s, "frame  time s  level  ratio  term       state");
        let last_frame = self.frames.keys().next_back().copied();
        let mut previous: Option<LineKey> = None;
        let mut before: Option<[f64; 3]> = None;
        for (&f, (place, mesh)) in &self.frames {
            let level = mesh.levels.get(place.triangle).copied().unwrap_or(0);
            let decision = mesh.decisions.get(place.triangle).copied();
            let key = (level, decision.map(|(r, t, st)| (ratio_band(r), t, st)));
            let events: Vec<&String> = mesh
                .events
                .iter()
                .filter_map(|(line, corners)| {
                    let c = corners.as_ref()?;
                    History::touches(c, place.position, before.unwrap_or(place.position))
                        .then_some(line)
                })
                .collect();
            let show = previous != Some(key)
                || f == self.frame
                || Some(f) == last_frame
                || !events.is_empty();
            if show {
                let time = mesh.sim_time.map_or("-".to_owned(), |t| format!("{t:.3}"));
                let what = match decision {
                    Some((r, t, st)) => format!(
                        "{r:>6.3}  {:<9}  {}",
                        TERM_NAMES.get(usize::from(t)).unwrap_or(&"?"),
                        STATE_NAMES.get(usize::from(st)).unwrap_or(&"?")
                    ),
                    None => "     -  -          (no decisions recorded)".to_owned(),
                };
                let mark = if f == self.frame { "  <- asked" } else { "" };
                let _ = writeln!(s, "{f:>5}  {time:>6}  {level:>5}  {what}{mark}");
                for line in events {
                    let _ = writeln!(s, "         {line}");
                }
            }
            previous = Some(key);
            before = Some(place.position);
        }
        s
    }
}
