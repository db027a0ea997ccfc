//! A small writer of Rerun blueprint stores: containers and views logged as the blueprint
//! archetypes themselves, so that a view can carry properties (the 3D eye that tracks the
//! cloth) that rerun 0.36.3's Rust `Blueprint` builder keeps crate-private.
//!
//! The store is built in memory and sent with [`RecordingStream::send_blueprint`], as the
//! builder does. Container and view ids are UUIDs numbered in logging order, so the same
//! layout gives the same blueprint store.

use rerun::external::re_log_types::{BlueprintActivationCommand, LogMsg};
use rerun::external::re_sdk_types::Visualizer;
use rerun::external::re_sdk_types::blueprint::archetypes::{
    ActiveVisualizers, VisualizerInstruction,
};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    ContainerBlueprint, EyeControls3D, PanelBlueprint, TimePanelBlueprint, ViewBlueprint,
    ViewContents, ViewportBlueprint,
};
use rerun::external::re_sdk_types::blueprint::components::VisualizerInstructionId;
use rerun::external::re_sdk_types::blueprint::components::{
    AutoViews, ColumnShare, ContainerKind, IncludedContent, PanelState, QueryExpression,
    RootContainer, RowShare, ViewClass,
};
use rerun::external::re_sdk_types::datatypes::Uuid;
use rerun::{RecordingStream, RecordingStreamBuilder, RecordingStreamResult};

/// A view of the layout: its class, name, origin, contents and, for 3D views, the entity
/// its eye follows.
pub(super) struct ViewSpec {
    /// Rerun's view class identifier ("3D", "TextLog", "TextDocument", "TimeSeries").
    pub class: &'static str,
    /// Display name.
    pub name: String,
    /// Space origin (entity path).
    pub origin: String,
    /// Query expressions (`+ /path/**`, `- /path`); empty: everything under the origin.
    pub contents: Vec<String>,
    /// Where the 3D eye starts (3D views only).
    pub eye: Eye,
    /// Per-entity visualizer overrides in this view: the entity path and the visualizer
    /// carrying the overriding components (e.g. the cloth drawn in one faint colour).
    pub overrides: Vec<(String, Visualizer)>,
}

/// Where a 3D view's eye starts and what it follows.
pub(super) enum Eye {
    /// Rerun's default eye, for views that are not 3D.
    Default,
    /// Rerun's default placement, following the entity at this path as it moves.
    Tracking(String),
    /// At `position`, looking at `look_target` (both in metres, world frame).
    Fixed {
        /// The eye's position.
        position: [f32; 3],
        /// The point it looks at and orbits around.
        look_target: [f32; 3],
    },
}

/// One node of the layout tree: a container of nodes or a view.
pub(super) enum Node {
    /// Nodes side by side, with their column shares.
    Horizontal(Vec<Node>, Vec<f32>),
    /// Nodes stacked, with their row shares.
    Vertical(Vec<Node>, Vec<f32>),
    /// A view.
    View(ViewSpec),
}

/// A blueprint store under construction.
struct Writer {
    /// The in-memory blueprint stream.
    stream: RecordingStream,
    /// The next container or view number.
    next_id: u64,
}

/// A UUID-shaped id numbered `n`, with its hyphenated text form.
fn numbered_id(n: u64) -> (Uuid, String) {
    let mut bytes = [0u8; 16];
    bytes[8..].copy_from_slice(&n.to_be_bytes());
    bytes[6] = 0x40; // version 4 layout, as rerun's own ids
    bytes[8] |= 0x80; // RFC 4122 variant
    let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
    let text = format!(
        "{}-{}-{}-{}-{}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    );
    (Uuid { bytes }, text)
}

impl Writer {
    /// The next numbered id.
    fn next(&mut self) -> (Uuid, String) {
        let id = numbered_id(self.next_id);
        self.next_id += 1;
        id
    }

    /// Logs `node` and its children; returns its blueprint path and id.
    fn log(&mut self, node: &Node) -> RecordingStreamResult<(String, Uuid)> {
        let (uuid, text) = self.next();
        match node {
            Node::View(view) => {
                let path = format!("view/{text}");
                self.log_view(&path, view)?;
                Ok((path, uuid))
            }
            Node::Horizontal(children, shares) | Node::Vertical(children, shares) => {
                let mut paths = Vec::with_capacity(children.len());
                for child in children {
                    paths.push(IncludedContent::from(self.log(child)?.0.as_str()));
                }
                let (kind, arch) = match node {
                    Node::Horizontal(..) => (
                        ContainerKind::Horizontal,
                        ContainerBlueprint::new(ContainerKind::Horizontal)
                            .with_col_shares(shares.iter().map(|&s| ColumnShare(s.into()))),
                    ),
                    _ => (
                        ContainerKind::Vertical,
                        ContainerBlueprint::new(ContainerKind::Vertical)
                            .with_row_shares(shares.iter().map(|&s| RowShare(s.into()))),
                    ),
                };
                let path = format!("container/{text}");
                let arch = arch.with_container_kind(kind).with_contents(paths);
                self.stream.log(path.as_str(), &arch)?;
                Ok((path, uuid))
            }
        }
    }

    /// Logs one view: its contents, its blueprint, its eye and its overrides.
    fn log_view(&mut self, path: &str, view: &ViewSpec) -> RecordingStreamResult<()> {
        let contents = if view.contents.is_empty() {
            vec!["+ $origin/**".to_owned()]
        } else {
            view.contents.clone()
        };
        self.stream.log(
            format!("{path}/ViewContents"),
            &ViewContents::new(contents.into_iter().map(|q| QueryExpression(q.into()))),
        )?;
        let arch = ViewBlueprint::new(ViewClass(view.class.into()))
            .with_display_name(view.name.as_str())
            .with_space_origin(view.origin.as_str());
        self.stream.log(path, &arch)?;
        let eye = match &view.eye {
            Eye::Default => None,
            Eye::Tracking(entity) => {
                Some(EyeControls3D::new().with_tracking_entity(entity.as_str()))
            }
            Eye::Fixed {
                position,
                look_target,
            } => Some(
                EyeControls3D::new()
                    .with_position(*position)
                    .with_look_target(*look_target),
            ),
        };
        if let Some(eye) = eye {
            self.stream.log(format!("{path}/EyeControls3D"), &eye)?;
        }
        for (entity, visualizer) in &view.overrides {
            self.log_override(path, entity, visualizer)?;
        }
        Ok(())
    }

    /// Logs one entity's visualizer override in the view at `path`, where rerun's own
    /// blueprint builder puts it (`<view>/ViewContents/overrides/<entity>/visualizers/<id>`),
    /// with a numbered instead of a random instruction id.
    fn log_override(
        &mut self,
        path: &str,
        entity: &str,
        visualizer: &Visualizer,
    ) -> RecordingStreamResult<()> {
        let base = format!(
            "{path}/ViewContents/overrides/{}/visualizers",
            entity.trim_start_matches('/')
        );
        let (uuid, text) = self.next();
        let instruction_path = format!("{base}/{text}");
        self.stream.log(
            instruction_path.as_str(),
            &VisualizerInstruction::new(visualizer.visualizer_type.clone()),
        )?;
        self.stream.log_serialized_batches(
            instruction_path.as_str(),
            false,
            visualizer.overrides.iter().cloned(),
        )?;
        self.stream.log(
            base.as_str(),
            &ActiveVisualizers::new([VisualizerInstructionId(uuid)]),
        )?;
        Ok(())
    }
}

/// Sends the blueprint whose root container is `root` to `recording`, made active and
/// default, with the blueprint and selection panels collapsed and the time panel collapsed
/// to its play controls.
pub(super) fn send(recording: &RecordingStream, root: &Node) -> RecordingStreamResult<()> {
    let app = recording
        .store_info()
        .map_or_else(|| "drape".into(), |info| info.application_id().clone());
    let (stream, storage) = RecordingStreamBuilder::new(app)
        .enabled(true)
        .blueprint()
        .memory()?;
    stream.set_time_sequence("blueprint", 0);
    let mut writer = Writer { stream, next_id: 1 };
    let (_, root_id) = writer.log(root)?;
    let stream = &writer.stream;
    stream.log(
        "viewport",
        &ViewportBlueprint::new()
            .with_root_container(RootContainer(root_id))
            .with_auto_views(AutoViews(false.into())),
    )?;
    let collapsed = PanelBlueprint::new().with_state(PanelState::Collapsed);
    stream.log("blueprint_panel", &collapsed)?;
    stream.log("selection_panel", &collapsed)?;
    stream.log(
        "time_panel",
        &TimePanelBlueprint::new().with_state(PanelState::Collapsed),
    )?;
    let msgs: Vec<LogMsg> = storage.take();
    let Some(blueprint_id) = msgs.first().map(|m| m.store_id().clone()) else {
        return Ok(());
    };
    recording.send_blueprint(
        msgs,
        BlueprintActivationCommand {
            blueprint_id,
            make_active: true,
            make_default: true,
        },
    );
    Ok(())
}
