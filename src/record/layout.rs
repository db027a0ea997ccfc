//! The default blueprint sent with every recording: two 3D views (refinement levels or
//! panels, dihedral angles) above the event log, beside a column of plots; and the legend.

use std::fmt::Write as _;

use rerun::{RecordingStream, RecordingStreamError};

use rerun::external::re_sdk_types::VisualizableArchetype as _;

use crate::math::Vector;

use super::blueprint::{self, Eye, Node, ViewSpec};
use super::camera::{self, Camera};
use super::edges::ANGLE_STOPS;
use super::garment::{PANEL_COLOUR_NAMES, PANEL_PALETTE, SEAM_OPEN_RGB, SEAM_WELDED_RGB};
use super::{
    ENTITY_EDGES, ENTITY_EVENT_LOG, ENTITY_LEGEND, ENTITY_MESH, ENTITY_PLOTS, ENTITY_SEAMS,
    LEVEL_PALETTE,
};

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

/// The colour the cloth is drawn in under the edges of the `angles` view: a pale grey that
/// every colour of the angle scale stands out on, so the segments read as folds of a surface
/// and the cloth hides the edges behind it.
pub(super) const ANGLES_CLOTH_RGB: [u8; 3] = [0xE4, 0xE4, 0xE4];

/// `#RRGGBB`.
pub(super) fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02X}{g:02X}{b:02X}")
}

/// What the legend names for the cloth's colours.
#[derive(Debug, Clone, Copy)]
pub(super) enum ClothLegend<'a> {
    /// The refinement levels.
    Levels,
    /// The garment's panels, by name.
    Panels(&'a [String]),
    /// The criterion's ratio bands.
    Ratio,
    /// The decision states.
    State,
}

/// The legend shown beside the event log (markdown): the cloth's colours (refinement levels,
/// or with `panels` each panel's name and colour), the angle scale, the seam colours (when
/// `seams`: a garment) and the event point colours.
pub(super) fn legend_markdown(cloth: ClothLegend, seams: bool) -> String {
    let mut s = String::new();
    match cloth {
        ClothLegend::Ratio => s.push_str(&super::decisions::legend(false)),
        ClothLegend::State => s.push_str(&super::decisions::legend(true)),
        ClothLegend::Panels(names) => {
            s.push_str("**cloth: panel**\n\n");
            for (p, name) in names.iter().enumerate() {
                let k = p % PANEL_PALETTE.len();
                let _ = writeln!(
                    s,
                    "- {name}: {} `{}`",
                    PANEL_COLOUR_NAMES[k],
                    hex(PANEL_PALETTE[k])
                );
            }
        }
        ClothLegend::Levels => {
            s.push_str("**cloth: refinement level**\n\n");
            let last = LEVEL_PALETTE.len() - 1;
            for (l, (c, name)) in LEVEL_PALETTE.iter().zip(LEVEL_NAMES).enumerate() {
                let more = if l == last { " and deeper" } else { "" };
                let _ = writeln!(s, "- level {l}{more}: {name} `{}`", hex(*c));
            }
        }
    }
    let _ = writeln!(
        s,
        "\n**angles: dihedral angle per edge** (linear between stops), on the cloth in pale \
         grey `{}`\n",
        hex(ANGLES_CLOTH_RGB)
    );
    for ((a, c), name) in ANGLE_STOPS.iter().zip(ANGLE_NAMES) {
        let _ = writeln!(s, "- {a} deg: {name} `{}`", hex(*c));
    }
    if seams {
        let _ = writeln!(
            s,
            "\n**seams**: open orange `{}` (each pair being sewn), welded green `{}` (the \
             seam's edges)",
            hex(SEAM_OPEN_RGB),
            hex(SEAM_WELDED_RGB)
        );
    }
    s.push_str(
        "\n**events**: split orange, closure split yellow, bounce purple, merge or collapse \
         blue, refused merge light blue, flip grey, rollback red, weld green\n",
    );
    s
}

/// Sends the default blueprint:
///
/// - left (two thirds of the width): the 3D view `cloth` (everything but `cloth/edges`: the
///   mesh coloured by level or panel, seams, pins, events, obstacles) beside the 3D view
///   `angles` (the edges coloured by dihedral angle, with the seams, the event points and
///   obstacles), and below them
///   the text log view `events` and the text document view `legend`;
/// - right: one time-series view per top-level plot group (the first segment of the scalar
///   names, alphabetically).
///
/// With [`Camera::Follow`] (the default) the eyes of both 3D views follow the cloth
/// (`cloth/mesh`: the whole cloth, also where the angles view draws only some edges), so the cloth stays framed while a body carries it or a
/// pin drags it away; another camera places both eyes where it says, framing the cloth's
/// `first_positions` (`camera.rs`). The `angles` view draws `cloth/mesh` in one pale colour
/// ([`ANGLES_CLOTH_RGB`], a visualizer override) under the edges.
///
/// The blueprint and selection panels start collapsed and the time panel collapsed to its
/// play controls, so the views get the window; all can be reopened in the viewer.
pub(super) fn send_blueprint(
    stream: &RecordingStream,
    scalar_names: &[&str],
    camera: Camera,
    first_positions: &[Vector],
) -> Result<(), RecordingStreamError> {
    let eye_on = |entity: &str| camera::eye(camera, first_positions, &format!("/{entity}"));
    let scenes = scene_views(eye_on(ENTITY_MESH), eye_on(ENTITY_MESH));
    let root = Node::Horizontal(vec![scenes, plot_views(scalar_names)], vec![2.0, 1.0]);
    blueprint::send(stream, &root)
}

/// A view of class `class` named `name`, rooted at `origin`, showing `contents`
/// (all under `origin` when empty) from `eye`, without overrides.
fn view(
    class: &'static str,
    name: &str,
    origin: &str,
    contents: Vec<String>,
    eye: Eye,
) -> ViewSpec {
    ViewSpec {
        class,
        name: name.to_owned(),
        origin: origin.to_owned(),
        contents,
        eye,
        overrides: Vec::new(),
    }
}

/// The blueprint's left part: the 3D views `cloth` (from `cloth_eye`) and `angles`
/// (from `angles_eye`) side by side, over the text views `events` and `legend`.
fn scene_views(cloth_eye: Eye, angles_eye: Eye) -> Node {
    let cloth = view(
        "3D",
        "cloth",
        "/",
        vec![
            "+ /**".to_owned(),
            format!("- /{ENTITY_EDGES}"),
            format!("- /{ENTITY_LEGEND}"),
        ],
        cloth_eye,
    );
    let mut angles = view(
        "3D",
        "angles",
        "/",
        vec![
            format!("+ /{ENTITY_EDGES}"),
            format!("+ /{ENTITY_MESH}"),
            format!("+ /{ENTITY_SEAMS}"),
            "+ /events/points".to_owned(),
            "+ /obstacles/**".to_owned(),
        ],
        angles_eye,
    );
    angles.overrides.push((
        format!("/{ENTITY_MESH}"),
        rerun::Mesh3D::update_fields()
            .with_vertex_colors([ANGLES_CLOTH_RGB])
            .visualizer(),
    ));
    let (cloth, angles) = (Node::View(cloth), Node::View(angles));
    let log = Node::View(view(
        "TextLog",
        "events",
        ENTITY_EVENT_LOG,
        Vec::new(),
        Eye::Default,
    ));
    let legend = Node::View(view(
        "TextDocument",
        "legend",
        ENTITY_LEGEND,
        Vec::new(),
        Eye::Default,
    ));
    let bottom = Node::Horizontal(vec![log, legend], vec![3.0, 1.0]);
    Node::Vertical(
        vec![
            Node::Horizontal(vec![cloth, angles], vec![1.0, 1.0]),
            bottom,
        ],
        vec![3.0, 1.0],
    )
}

/// The blueprint's right part: one time-series view per top-level group of
/// `scalar_names` (their first segment, alphabetically), stacked.
fn plot_views(scalar_names: &[&str]) -> Node {
    let mut groups: Vec<&str> = scalar_names
        .iter()
        .filter_map(|name| name.split('/').find(|s| !s.is_empty()))
        .collect();
    groups.sort_unstable();
    groups.dedup();
    let plots = groups
        .iter()
        .map(|g| {
            Node::View(view(
                "TimeSeries",
                g,
                &format!("{ENTITY_PLOTS}/{g}"),
                Vec::new(),
                Eye::Default,
            ))
        })
        .collect::<Vec<_>>();
    let shares = vec![1.0; plots.len()];
    Node::Vertical(plots, shares)
}
