//! The decoded contents of a recording as comparable rows, for reproducibility tests.
//!
//! Rerun stamps every row and chunk with a time-based random id (`RowId`, `ChunkId`, TUIDs)
//! and batches rows into chunks on a wall-clock tick, so two runs of the same scene never give
//! byte-identical files. What must be identical is the data: per entity, in logging order,
//! every row's timeline values and component arrays.

use std::path::Path;

use rerun::external::arrow::array::{Array, ArrayData};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

/// What holds wall-clock readings, which differ between runs by nature: entities starting with
/// `/plots/timing/` (wall time per frame) and the `start_time` property of the recording.
pub const WALL_CLOCK: &[&str] = &["/plots/timing/", "RecordingInfo:start_time"];

/// One decoded row: entity, timeline values (name, value) and component arrays (name, data).
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub entity: String,
    pub times: Vec<(String, i64)>,
    pub components: Vec<(String, ArrayData)>,
}

/// Every row of the recording store (blueprint left out), sorted by entity, then in logging
/// order; entities starting with one of `skip`, and components named in it, are left out.
pub fn rows(path: &Path, skip: &[&str]) -> Vec<Row> {
    let file = std::fs::File::open(path).expect("open rrd");
    let decoder = DecoderApp::decode_eager(std::io::BufReader::new(file)).expect("rrd header");
    let mut rows = Vec::new();
    for msg in decoder {
        let msg = msg.expect("decodable message");
        if msg.store_id().kind() != rerun::StoreKind::Recording {
            continue;
        }
        let LogMsg::ArrowMsg(_, arrow) = &msg else {
            continue;
        };
        let chunk = Chunk::from_arrow_msg(arrow).expect("chunk");
        let entity = chunk.entity_path().to_string();
        if skip.iter().any(|s| entity.starts_with(s)) {
            continue;
        }
        let mut names: Vec<_> = chunk.component_descriptors().map(|d| d.component).collect();
        names.sort_by(|a, b| a.as_str().cmp(b.as_str()));
        for (i, row_id) in chunk.row_ids().enumerate() {
            let mut times: Vec<(String, i64)> = chunk
                .timelines()
                .iter()
                .map(|(n, col)| (n.as_str().to_owned(), col.times_raw()[i]))
                .collect();
            times.sort();
            let components = names
                .iter()
                .filter(|c| !skip.contains(&c.as_str()))
                .filter_map(|&c| {
                    let a = chunk.components().get_array(c)?;
                    a.is_valid(i)
                        .then(|| (c.as_str().to_owned(), a.value(i).to_data()))
                })
                .collect();
            rows.push((
                entity.clone(),
                row_id,
                Row {
                    entity: entity.clone(),
                    times,
                    components,
                },
            ));
        }
    }
    rows.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
    rows.into_iter().map(|(_, _, r)| r).collect()
}

/// Asserts two row lists are equal, naming the first difference.
pub fn assert_same(a: &[Row], b: &[Row]) {
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        let differing: Vec<&str> = x
            .components
            .iter()
            .zip(&y.components)
            .filter(|(c, d)| c != d)
            .map(|(c, _)| c.0.as_str())
            .collect();
        assert!(
            x == y,
            "row {i} differs: {} {:?} vs {} {:?}; components {differing:?}",
            x.entity,
            x.times,
            y.entity,
            y.times
        );
    }
    assert_eq!(a.len(), b.len(), "row counts");
}
