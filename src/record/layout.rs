//! The default blueprint sent with every recording: the 3D scene beside the plots and the
//! event log.

use rerun::blueprint::{
    Blueprint, BlueprintActivation, ContainerLike, Horizontal, Spatial3DView, TextLogView,
    TimeSeriesView, Vertical,
};
use rerun::{RecordingStream, RecordingStreamError};

use super::{ENTITY_EVENT_LOG, ENTITY_PLOTS};

/// Sends the default blueprint: a 3D view of the whole scene (two thirds of the width) beside a
/// column with one time-series view per top-level plot group (the first segment of the scalar
/// names, alphabetically) and the event log at the bottom.
///
/// rerun 0.36.3's `Blueprint::send` builds an internal stream that honours `RERUN=off` and then
/// panics on its empty output, so the blueprint is skipped in that case.
pub(super) fn send_blueprint(
    stream: &RecordingStream,
    scalar_names: &[&str],
) -> Result<(), RecordingStreamError> {
    if !rerun::decide_logging_enabled(true) {
        return Ok(());
    }
    let mut groups: Vec<&str> = scalar_names
        .iter()
        .filter_map(|name| name.split('/').find(|s| !s.is_empty()))
        .collect();
    groups.sort_unstable();
    groups.dedup();
    let scene: ContainerLike = Spatial3DView::new("cloth").with_origin("/").into();
    let plots = groups.iter().map(|g| {
        TimeSeriesView::new(*g)
            .with_origin(format!("{ENTITY_PLOTS}/{g}"))
            .into()
    });
    let log: ContainerLike = TextLogView::new("events")
        .with_origin(ENTITY_EVENT_LOG)
        .into();
    let root: ContainerLike = Horizontal::new([scene, Vertical::new(plots.chain([log])).into()])
        .with_column_shares([2.0_f32, 1.0])
        .into();
    Blueprint::new(root).with_auto_views(false).send(
        stream,
        BlueprintActivation {
            make_active: true,
            make_default: true,
        },
    )
}
