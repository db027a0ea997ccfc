//! The default blueprint sent with every recording: two 3D views (refinement levels, dihedral
//! angles) above the event log, beside a column of plots.

use rerun::blueprint::components::PanelState;
use std::fmt::Write as _;

use rerun::blueprint::{
    Blueprint, BlueprintActivation, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel,
    Spatial3DView, TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};
use rerun::{RecordingStream, RecordingStreamError};

use super::edges::ANGLE_STOPS;
use super::{ENTITY_EDGES, ENTITY_EVENT_LOG, ENTITY_LEGEND, ENTITY_PLOTS, LEVEL_PALETTE};

/// Names of the palette colours, in [`LEVEL_PALETTE`] order.
const LEVEL_NAMES: [&str; 8] = [
    "steel blue",
    "teal",
    "green",
    "yellow",
    "orange",
    "deep orange",
    "red",
    "crimson",
];
/// Names of the angle scale's colours, in [`ANGLE_STOPS`] order.
const ANGLE_NAMES: [&str; 4] = ["dark slate", "violet", "orange", "yellow"];

/// The legend shown beside the event log (markdown): level colours, the angle scale, and the
/// event point colours.
pub(super) fn legend_markdown() -> String {
    let hex = |[r, g, b]: [u8; 3]| format!("#{r:02X}{g:02X}{b:02X}");
    let mut s = String::from("**cloth: refinement level**\n\n");
    let last = LEVEL_PALETTE.len() - 1;
    for (l, (c, name)) in LEVEL_PALETTE.iter().zip(LEVEL_NAMES).enumerate() {
        let more = if l == last { " and deeper" } else { "" };
        let _ = writeln!(s, "- level {l}{more}: {name} `{}`", hex(*c));
    }
    s.push_str("\n**angles: dihedral angle per edge** (linear between stops)\n\n");
    for ((a, c), name) in ANGLE_STOPS.iter().zip(ANGLE_NAMES) {
        let _ = writeln!(s, "- {a} deg: {name} `{}`", hex(*c));
    }
    s.push_str(
        "\n**events**: split orange, closure split yellow, merge or collapse blue, \
         flip grey, rollback red\n",
    );
    s
}

/// Sends the default blueprint:
///
/// - left (two thirds of the width): the 3D view `cloth` (everything but `cloth/edges`: the
///   mesh coloured by level, pins, events, obstacles) beside the 3D view `angles` (the
///   edges coloured by dihedral angle, with the event points and obstacles), and below them
///   the text log view `events` and the text document view `legend`;
/// - right: one time-series view per top-level plot group (the first segment of the scalar
///   names, alphabetically).
///
/// The blueprint and selection panels start collapsed and the time panel collapsed to its
/// play controls, so the views get the window; all can be reopened in the viewer.
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
    let cloth: ContainerLike = Spatial3DView::new("cloth")
        .with_origin("/")
        .with_contents([
            "+ /**".to_owned(),
            format!("- /{ENTITY_EDGES}"),
            format!("- /{ENTITY_LEGEND}"),
        ])
        .into();
    let angles: ContainerLike = Spatial3DView::new("angles")
        .with_origin("/")
        .with_contents([
            format!("+ /{ENTITY_EDGES}"),
            "+ /events/points".to_owned(),
            "+ /obstacles/**".to_owned(),
        ])
        .into();
    let log: ContainerLike = TextLogView::new("events")
        .with_origin(ENTITY_EVENT_LOG)
        .into();
    let legend: ContainerLike = TextDocumentView::new("legend")
        .with_origin(ENTITY_LEGEND)
        .into();
    let bottom: ContainerLike = Horizontal::new([log, legend])
        .with_column_shares([3.0_f32, 1.0])
        .into();
    let scenes: ContainerLike = Vertical::new([Horizontal::new([cloth, angles]).into(), bottom])
        .with_row_shares([3.0_f32, 1.0])
        .into();
    let plots = groups.iter().map(|g| {
        TimeSeriesView::new(*g)
            .with_origin(format!("{ENTITY_PLOTS}/{g}"))
            .into()
    });
    let root: ContainerLike = Horizontal::new([scenes, Vertical::new(plots).into()])
        .with_column_shares([2.0_f32, 1.0])
        .into();
    Blueprint::new(root)
        .with_auto_views(false)
        .with_blueprint_panel(BlueprintPanel::from_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::from_state(PanelState::Collapsed))
        .with_time_panel(TimePanel::new().with_state(PanelState::Collapsed))
        .send(
            stream,
            BlueprintActivation {
                make_active: true,
                make_default: true,
            },
        )
}
