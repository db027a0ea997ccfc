//! Adaptive meshing (`docs/model.md`, "Adaptive meshing"): the papers' `angle`
//! criterion (refine where the angle between the normals at an interior edge
//! exceeds the upper threshold, coarsen where every angle around is below the
//! lower one) or `sizing.rs`.
//!
//! An adaptation pass: measure angles -> choose operations -> apply them to the
//! refinement hierarchy -> close the mesh -> transfer the state onto the new
//! topology -> report events. The stepper must rebuild its elements afterwards.

mod check;
pub mod decision;
pub mod edge;
mod edge_collapse;
mod edge_pass;
pub mod gate;
mod marks;
pub mod proximity;
mod readings;
pub mod red_green;
mod red_green_apply;
mod red_green_pass;
pub mod sizing;
pub mod soup;
pub mod tensor;
mod tensor_pass;
pub mod transfer;
mod transfer_panels;
mod tri_list;

pub use check::{ConsistencyError, boundary_length, check_consistency};
pub use decision::{Reading, Reason, Refusal, Term, TriangleDecision, TriangleState};
pub use gate::RemeshGate;
pub use marks::{edge_angles, edge_angles_into};

use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::spec::{
    Adapt, AdaptCriterion, AdaptEvery, AdaptMethod, DEFAULT_HYSTERESIS, RedDiagonals,
};
use crate::world::World;
use red_green::RedGreen;
use red_green_pass::RedGreenState;
use transfer::Origin;

/// What happened, for the recording and the counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// A 1-4 split asked for by the angle criterion.
    Split,
    /// A 1-4 split forced by closure (two hanging nodes) or by 1-irregularity.
    ClosureSplit,
    /// A split asked for by the criterion that undoes a merge of the latest
    /// pass (a bounce: `sizing.rs`, "Bounces"); counted among the splits.
    Bounce,
    /// Four children merged back into their parent.
    Merge,
    /// A merge the criterion asked for that the level rule refused (logged
    /// when a parent is first refused, not again while it stays refused).
    MergeRefused,
    /// A step restored, refined and integrated again.
    Rollback,
    /// An edge flipped for quality (edge method).
    Flip,
    /// An edge collapsed (edge method).
    Collapse,
}

/// One remeshing event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptEvent {
    /// What happened.
    pub kind: EventKind,
    /// Where (world position of the affected triangle's centroid), m.
    pub position: Vector,
    /// Level of the triangles created.
    pub level: u8,
    /// The largest angle at the triangle's edges that triggered it, degrees
    /// (`None` for forced splits).
    pub angle: Option<Scalar>,
    /// The step after which it happened.
    pub step: u64,
    /// Why it happened.
    pub reason: Reason,
    /// The world positions of the corners of the triangle it split, merged
    /// into or refused (red-green; the leaf that triggered a rollback), m.
    pub corners: Option<[Vector; 3]>,
}

/// Counters over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct AdaptStats {
    /// 1-4 splits (asked for and forced); with the tensor method, grid lines
    /// inserted.
    pub splits: u64,
    /// Of those, forced by closure or 1-irregularity.
    pub closure_splits: u64,
    /// Merges (red_green), edge collapses (edge) or grid lines removed
    /// (tensor).
    pub merges: u64,
    /// Edge flips (edge method).
    pub flips: u64,
    /// Steps redone after refining.
    pub rollbacks: u64,
    /// Adaptation passes run.
    pub passes: u64,
    /// Passes that changed the mesh.
    pub changed_passes: u64,
    /// Passes the remesh gate deferred (`adapt.min_change`: too small a change
    /// and no urgent split); they changed nothing. The passes applied are
    /// `passes - deferred_passes`.
    pub deferred_passes: u64,
    /// Largest number of operations in one pass.
    pub max_ops_per_pass: u64,
    /// Merges that the criterion split again before the next pass had run
    /// (red-green; with the sizing criterion each one doubles that parent's
    /// hysteresis: `sizing.rs`, "Bounces").
    pub bounces: u64,
    /// Mean over the passes of the fraction of triangles at `max_level` or
    /// finer (closure triangles of the finest red level included).
    pub top_level_fraction_mean: Scalar,
    /// That fraction after the last pass.
    pub top_level_fraction_final: Scalar,
    /// Mean over the passes of the share of the cloth's rest area that those
    /// triangles cover (a level-4 region has 16 times the triangles of the same
    /// area at level 0, so this is the smaller, and the one that says how much
    /// of the cloth is refined).
    pub top_level_area_fraction_mean: Scalar,
    /// That share after the last pass.
    pub top_level_area_fraction_final: Scalar,
    /// True while a garment's remeshing waits for every seam to be welded
    /// (at the end of a run: it never started).
    pub awaiting_welds: bool,
    /// Simulated time at which remeshing started, s: 0, or when a garment's
    /// last seam was welded.
    pub started_at: Scalar,
}

impl AdaptStats {
    /// Adds the fraction of `world`'s triangles at level `top` or finer to the
    /// running mean (called once per pass).
    fn note_levels(&mut self, world: &World, top: u8) {
        let levels = &world.mesh.levels;
        let at_top = levels.iter().filter(|&&l| l >= top).count();
        let f = at_top as Scalar / levels.len().max(1) as Scalar;
        let m = &world.mesh;
        let top_area: Scalar = (0..levels.len())
            .filter(|&t| levels[t] >= top)
            .map(|t| m.rest_area(t))
            .sum();
        let total = m.total_rest_area();
        let a = if total > 0.0 { top_area / total } else { 0.0 };
        let n = self.passes.max(1) as Scalar;
        self.top_level_fraction_mean += (f - self.top_level_fraction_mean) / n;
        self.top_level_fraction_final = f;
        self.top_level_area_fraction_mean += (a - self.top_level_area_fraction_mean) / n;
        self.top_level_area_fraction_final = a;
    }
}

/// Adaptivity settings (the scene's `[adapt]`, resolved).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptConfig {
    /// The remeshing method (`red_green`, `edge` or `tensor`).
    pub method: AdaptMethod,
    /// Upper threshold, degrees.
    pub refine_angle: Scalar,
    /// Lower threshold, degrees.
    pub coarsen_angle: Scalar,
    /// Finest level.
    pub max_level: u8,
    /// Shortest edge refinement may create (material space), m.
    pub min_edge_length: Scalar,
    /// When the adaptation pass runs.
    pub every: AdaptEvery,
    /// Redo steps that bent too far.
    pub rollback: bool,
    /// Rollbacks per step.
    pub max_rollbacks: u32,
    /// What decides where to refine and coarsen.
    pub criterion: AdaptCriterion,
    /// Sizing criterion: merge when the parent carries at most
    /// `refine_angle / hysteresis` (see `sizing.rs`); unused by the angle one.
    pub hysteresis: Scalar,
    /// Sizing criterion: also split where the strain jumps across an edge by
    /// more than this (`None`: curvature alone; see `sizing.rs`).
    pub refine_strain: Option<Scalar>,
    /// Sizing criterion: also split where an edge leans towards the nearest
    /// obstacle by more than this fraction of its height (`None`: no obstacle
    /// term; see `proximity.rs`).
    pub refine_obstacle: Option<Scalar>,
    /// Red-green: flip the corner squares of red splits so that refined grids
    /// alternate their diagonals (`red_green/mesh.rs`, "Alternating diagonals").
    pub alternate_diagonals: bool,
    /// Red-green: apply a pass only when it changes enough (`gate.rs`; `None`:
    /// every pass is applied).
    pub gate: Option<RemeshGate>,
}

impl AdaptConfig {
    /// The configuration of a scene's `[adapt]`, or `None` when it does not adapt.
    pub fn from_scene(a: Option<&Adapt>) -> Option<AdaptConfig> {
        let a = a?;
        (a.method != AdaptMethod::None).then(|| AdaptConfig {
            method: a.method,
            refine_angle: a.refine_angle,
            coarsen_angle: a.coarsen_angle,
            max_level: a.max_level.min(254) as u8,
            min_edge_length: a.min_edge_length,
            every: a.every,
            rollback: a.rollback,
            max_rollbacks: a.max_rollbacks,
            criterion: a.criterion,
            hysteresis: a.hysteresis.unwrap_or(DEFAULT_HYSTERESIS),
            refine_strain: a.refine_strain.filter(|s| *s != 0.0),
            refine_obstacle: a.refine_obstacle.filter(|r| *r != 0.0),
            alternate_diagonals: a.diagonals.unwrap_or_default() == RedDiagonals::Alternating,
            gate: (a.min_change > 0.0).then_some(RemeshGate {
                min_change: a.min_change,
                urgent_ratio: a.urgent_ratio,
            }),
        })
    }
}

/// The adaptive state of a run: the remeshing method's own state, the
/// counters, and the events not yet taken by the recorder. Its settings are not
/// part of it: every call that remeshes is given the [`AdaptConfig`] (in a run,
/// the one in [`crate::sim::Settings`]).
#[derive(Debug, Clone)]
pub struct Adapter {
    /// Counters.
    pub stats: AdaptStats,
    /// Events since the last [`Adapter::take_events`].
    events: Vec<AdaptEvent>,
    /// What the method keeps between passes.
    method: MethodState,
    density: Scalar,
    /// Rest area and boundary length of the cloth, for [`Adapter::check`].
    area: Scalar,
    boundary: Scalar,
    /// Where the vertices of the latest remesh came from (empty before the
    /// first): [`Adapter::last_origins`].
    last_origins: Vec<Origin>,
}

/// What each remeshing method keeps between passes.
#[derive(Debug, Clone)]
enum MethodState {
    /// Paper A's refinement hierarchy (boxed: far larger than the others).
    RedGreen(Box<RedGreenState>),
    /// Paper B's limits (its mesh is the world's).
    Edge(edge::Limits),
    /// The rectangle's grid lines.
    Tensor(tensor::TensorGrid),
    /// A garment whose seams are still being sewn: remeshing starts, on the
    /// welded mesh as its level 0, once every seam is welded (a split of an
    /// open seam's side would leave a vertex without a partner).
    AwaitingWelds,
}

/// What the caller has measured on the world already, for
/// [`Adapter::remesh_with`] (the default: nothing).
#[derive(Debug, Clone, Copy, Default)]
pub struct Measured<'a> {
    /// The world's current [`edge_angles`] (the rollback check has just
    /// measured them), so the pass does not measure them again.
    pub angles: Option<&'a [Scalar]>,
    /// The tangent planes of the obstacle points nearest to the world's
    /// vertices (one per vertex, from `Obstacles::nearest_planes`; empty: no
    /// obstacles), which the sizing criterion's obstacle term measures
    /// (`proximity.rs`; unused without `refine_obstacle`).
    pub obstacle_planes: &'a [crate::collide::ObstaclePlane],
}

/// Why adaptive remeshing cannot start on a world's mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AdaptSetupError {
    /// The tensor method needs a generated rectangle's grid.
    #[error("{0}")]
    NotAGrid(#[from] tensor::NotAGrid),
    /// The cloth is a garment and the method cannot remesh one.
    #[error(
        "the {0} method cannot remesh a garment (a cloth with panels or seams): \
         use method = \"red_green\" or \"edge\""
    )]
    Garment(&'static str),
}

impl Adapter {
    /// Starts adapting `world`'s mesh with `config`'s method (its current
    /// triangles become level 0; `AdaptMethod::None`, which a scene never
    /// hands over, adapts as red-green). Fails only for the tensor method on a
    /// mesh that is not a rectangle's grid (scene validation refuses that
    /// combination first).
    pub fn new(
        config: &AdaptConfig,
        world: &World,
        density: Scalar,
    ) -> Result<Adapter, AdaptSetupError> {
        let m = &world.mesh;
        let awaiting = m.has_open_seam();
        let method = match awaiting {
            // Checked now, so that a refusal comes before the run.
            true => Adapter::method_state(config, world).map(|_| MethodState::AwaitingWelds)?,
            false => Adapter::method_state(config, world)?,
        };
        Ok(Adapter {
            stats: AdaptStats {
                awaiting_welds: awaiting,
                ..AdaptStats::default()
            },
            events: Vec::new(),
            method,
            density,
            area: m.total_rest_area(),
            boundary: boundary_length(m),
            last_origins: Vec::new(),
        })
    }

    /// The state of `config`'s method on `world`'s mesh as level 0.
    fn method_state(config: &AdaptConfig, world: &World) -> Result<MethodState, AdaptSetupError> {
        let m = &world.mesh;
        Ok(match config.method {
            AdaptMethod::Tensor if m.panels().is_some() => {
                return Err(AdaptSetupError::Garment("tensor"));
            }
            AdaptMethod::Edge => MethodState::Edge(edge::Limits::for_mesh(
                m,
                config.max_level,
                config.min_edge_length,
            )),
            AdaptMethod::Tensor => MethodState::Tensor(tensor::TensorGrid::from_mesh(m)?),
            AdaptMethod::RedGreen | AdaptMethod::None => {
                MethodState::RedGreen(Box::new(RedGreenState::new(world)))
            }
        })
    }

    /// True while the adapter waits for a garment's seams to be welded.
    pub fn awaiting_welds(&self) -> bool {
        matches!(self.method, MethodState::AwaitingWelds)
    }

    /// Starts remeshing a garment whose seams are now all welded: its current
    /// triangles become level 0, and its area and boundary the ones the checks
    /// hold it to. False while a seam is still open.
    fn start_after_welds(
        &mut self,
        config: &AdaptConfig,
        world: &World,
    ) -> Result<bool, MeshError> {
        let m = &world.mesh;
        if m.has_open_seam() {
            return Ok(false);
        }
        // `Adapter::new` built this method's state once already.
        self.method = Adapter::method_state(config, world).map_err(|_| MeshError::PanelTables)?;
        self.area = m.total_rest_area();
        self.boundary = boundary_length(m);
        self.stats.awaiting_welds = false;
        self.stats.started_at = world.time;
        Ok(true)
    }

    /// Where each vertex of the world's mesh came from in the latest remesh
    /// that changed it (for state kept outside the world, such as the resting
    /// contacts: [`transfer::carry_contacts`]); empty before the first.
    pub fn last_origins(&self) -> &[Origin] {
        &self.last_origins
    }

    /// Checks the adapted world (manifold, conforming, positive rest areas,
    /// exact mass: [`check_consistency`] against the cloth this adapter
    /// started from), the tensor method's grid against the world's mesh, and
    /// the red-green tables against a rebuild. Runs after
    /// every remesh in debug builds; tests call it in release builds too.
    pub fn check(&self, world: &World) -> Result<(), ConsistencyError> {
        if self.awaiting_welds() {
            // Nothing remeshed yet, and each weld shortens the boundary: the
            // mesh is checked against itself.
            let m = &world.mesh;
            return check_consistency(world, self.density, m.total_rest_area(), boundary_length(m));
        }
        check_consistency(world, self.density, self.area, self.boundary)?;
        match &self.method {
            MethodState::Tensor(grid) => grid.check(&world.mesh),
            MethodState::RedGreen(rg) => rg.hierarchy.check_tables(),
            MethodState::Edge(_) | MethodState::AwaitingWelds => Ok(()),
        }
        .map_err(ConsistencyError::Tables)
    }

    /// [`Adapter::check`] as a debug assertion (no cost in release builds).
    fn debug_check(&self, world: &World) {
        if cfg!(debug_assertions)
            && let Err(e) = self.check(world)
        {
            panic!("after remeshing: {e}");
        }
    }

    /// Events since the last call.
    pub fn take_events(&mut self) -> Vec<AdaptEvent> {
        std::mem::take(&mut self.events)
    }

    /// The refinement hierarchy (for tests and inspection; `None` for the edge
    /// and tensor methods).
    pub fn hierarchy(&self) -> Option<&RedGreen> {
        match &self.method {
            MethodState::RedGreen(rg) => Some(&rg.hierarchy),
            _ => None,
        }
    }

    /// One adaptation pass of `config`'s method on `world` after step `step`
    /// (red-green: merges, then splits, then closure); true when the mesh
    /// changed.
    pub fn remesh(
        &mut self,
        config: &AdaptConfig,
        world: &mut World,
        step: u64,
    ) -> Result<bool, MeshError> {
        self.remesh_with(config, world, step, Measured::default())
    }

    /// [`Adapter::remesh`] given what the caller has measured on the world
    /// already ([`Measured`]).
    pub fn remesh_with(
        &mut self,
        config: &AdaptConfig,
        world: &mut World,
        step: u64,
        known: Measured,
    ) -> Result<bool, MeshError> {
        if self.awaiting_welds() && !self.start_after_welds(config, world)? {
            return Ok(false);
        }
        match &self.method {
            MethodState::AwaitingWelds => Ok(false),
            MethodState::Tensor(_) => self.tensor_pass(config, world, step),
            MethodState::Edge(limits) => {
                let limits = *limits;
                self.edge_pass(config, world, step, limits)
            }
            MethodState::RedGreen(_) => self.red_green_pass(config, world, step, known),
        }
    }
}
