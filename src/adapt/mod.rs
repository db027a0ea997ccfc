//! Adaptive meshing (SPEC section 4): the papers' `angle` criterion (refine where
//! the angle between the normals at an interior edge exceeds the upper threshold,
//! coarsen where every angle around is below the lower one) or `sizing.rs`.
//!
//! An adaptation pass: measure angles -> choose operations -> apply them to the
//! refinement hierarchy -> close the mesh -> transfer the state onto the new
//! topology -> report events. The stepper must rebuild its elements afterwards.

mod check;
pub mod edge;
mod edge_pass;
mod marks;
pub mod proximity;
pub mod red_green;
pub mod sizing;
pub mod soup;
pub mod tensor;
mod tensor_pass;
pub mod transfer;
mod tri_list;

pub use check::{ConsistencyError, boundary_length, check_consistency};
pub use marks::{edge_angles, edge_angles_into};

use std::collections::HashMap;

use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::spec::{
    Adapt, AdaptCriterion, AdaptEvery, AdaptMethod, DEFAULT_HYSTERESIS, RedDiagonals,
};
use crate::world::World;
use red_green::{Applied, RedGreen, RedGreenOp};
use transfer::{Origin, VertexOrder, compact, transfer};

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
            refine_strain: a.refine_strain,
            refine_obstacle: a.refine_obstacle,
            alternate_diagonals: a.diagonals.unwrap_or_default() == RedDiagonals::Alternating,
        })
    }
}

/// The adaptive state of a run: settings, refinement hierarchy, counters, and the
/// events not yet taken by the recorder.
#[derive(Debug, Clone)]
pub struct Adapter {
    /// Settings.
    pub config: AdaptConfig,
    /// Counters.
    pub stats: AdaptStats,
    /// Events since the last [`Adapter::take_events`].
    events: Vec<AdaptEvent>,
    hierarchy: RedGreen,
    /// Leaf of the hierarchy that owns each triangle of the world's mesh.
    owner: Vec<u32>,
    /// The parents the latest pass merged, sorted (a split of one of them by
    /// the criterion before the next pass is a bounce).
    merged_last_pass: Vec<u32>,
    /// The parents [`Adapter::apply`] merged since the pass began.
    pass_merges: Vec<u32>,
    /// Per parent: how many of its merges bounced (its sizing hysteresis is
    /// doubled that many times; dropped when the parent itself merges away).
    bounces: HashMap<u32, u32>,
    density: Scalar,
    /// Limits of the edge method (`None` for the others).
    edge: Option<edge::Limits>,
    /// The tensor method's grid (`None` for the others).
    tensor: Option<tensor::TensorGrid>,
    /// Rest area and boundary length of the cloth, for [`Adapter::check`].
    area: Scalar,
    boundary: Scalar,
    /// Where the vertices of the latest remesh came from (empty before the
    /// first): [`Adapter::last_origins`].
    last_origins: Vec<Origin>,
}

impl Adapter {
    /// Starts adapting `world`'s mesh (its current triangles become level 0).
    /// Fails only for the tensor method on a mesh that is not a rectangle's
    /// grid (scene validation refuses that combination first).
    pub fn new(
        config: AdaptConfig,
        world: &World,
        density: Scalar,
    ) -> Result<Adapter, tensor::NotAGrid> {
        let hierarchy = RedGreen::new(&world.mesh.triangles, &world.mesh.material);
        let owner = (0..world.mesh.triangles.len() as u32).collect();
        let m = &world.mesh;
        let edge = (config.method == AdaptMethod::Edge).then(|| {
            edge::Limits::for_mesh(
                &m.material,
                &m.triangles,
                config.max_level,
                config.min_edge_length,
            )
        });
        let tensor = match config.method {
            AdaptMethod::Tensor => Some(tensor::TensorGrid::from_mesh(m)?),
            _ => None,
        };
        Ok(Adapter {
            config,
            stats: AdaptStats::default(),
            events: Vec::new(),
            hierarchy,
            owner,
            merged_last_pass: Vec::new(),
            pass_merges: Vec::new(),
            bounces: HashMap::new(),
            density,
            edge,
            tensor,
            area: m.total_rest_area(),
            boundary: boundary_length(m),
            last_origins: Vec::new(),
        })
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
        check_consistency(world, self.density, self.area, self.boundary)?;
        if let Some(grid) = &self.tensor {
            grid.check(&world.mesh).map_err(ConsistencyError::Tables)?;
        }
        self.hierarchy
            .check_tables()
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

    /// The refinement hierarchy (for tests and inspection).
    pub fn hierarchy(&self) -> &RedGreen {
        &self.hierarchy
    }

    /// One adaptation pass on `world` after step `step`: merges, then splits,
    /// then closure; returns true when the mesh changed.
    pub fn pass(&mut self, world: &mut World, step: u64) -> Result<bool, MeshError> {
        self.pass_near(world, step, None, &[])
    }

    /// [`Adapter::pass`] given the world's current [`edge_angles`] (the rollback
    /// check has just measured them): the same pass without measuring again.
    pub fn pass_measured(
        &mut self,
        world: &mut World,
        step: u64,
        angles: &[Scalar],
    ) -> Result<bool, MeshError> {
        self.pass_near(world, step, Some(angles), &[])
    }

    /// [`Adapter::pass`] with the world's current [`edge_angles`] when they are
    /// known, and the tangent planes of the obstacle points nearest to its
    /// vertices (one per vertex, from `Collider::nearest_planes`; empty: no
    /// obstacles), which the sizing criterion's obstacle term measures
    /// (`proximity.rs`; unused without `refine_obstacle`).
    pub fn pass_near(
        &mut self,
        world: &mut World,
        step: u64,
        angles: Option<&[Scalar]>,
        planes: &[proximity::ObstaclePlane],
    ) -> Result<bool, MeshError> {
        if self.tensor.is_some() {
            return self.tensor_pass(world, step);
        }
        if let Some(limits) = self.edge {
            return self.edge_pass(world, step, limits);
        }
        let measured;
        let angles = match angles {
            Some(a) => a,
            None => {
                measured = edge_angles(world);
                &measured
            }
        };
        debug_assert_eq!(angles.len(), world.mesh.edges.len(), "stale edge angles");
        let (merges, splits) = match self.config.criterion {
            AdaptCriterion::Angle => (
                self.merge_marks(world, angles),
                self.refinement_marks(world, angles),
            ),
            AdaptCriterion::Sizing => {
                let curv = self.leaf_curvatures(world, angles, planes);
                let merges = self.sizing_merge_marks(&curv);
                (merges, self.sizing_refinement_marks(&curv))
            }
        };
        self.stats.passes += 1;
        self.pass_merges.clear();
        let mut ops: Vec<(RedGreenOp, Option<Scalar>)> = merges
            .iter()
            .map(|&(p, a)| (RedGreenOp::Merge(p), Some(a)))
            .collect();
        ops.extend(splits.iter().map(|&(l, a)| (RedGreenOp::Split(l), Some(a))));
        let changed = self.apply(world, &ops, step);
        self.merged_last_pass = std::mem::take(&mut self.pass_merges);
        self.merged_last_pass.sort_unstable();
        self.stats.note_levels(world, self.config.max_level);
        changed
    }

    /// Refines the leaves in `marks` (from [`Adapter::refinement_marks`]) and
    /// rebuilds the world; used by rollback on the restored state.
    pub fn refine(
        &mut self,
        world: &mut World,
        marks: &[(u32, Scalar)],
        step: u64,
    ) -> Result<bool, MeshError> {
        let ops: Vec<_> = marks
            .iter()
            .map(|&(l, a)| (RedGreenOp::Split(l), Some(a)))
            .collect();
        self.apply(world, &ops, step)
    }

    /// Records a rollback of step `step`.
    pub fn note_rollback(&mut self, world: &World, step: u64) {
        self.stats.rollbacks += 1;
        let centre = world.x.iter().copied().sum::<Vector>() / world.x.len().max(1) as Scalar;
        self.events.push(AdaptEvent {
            kind: EventKind::Rollback,
            position: centre,
            level: 0,
            angle: None,
            step,
        });
    }

    /// Applies operations (each with the angle that asked for it), closes the
    /// mesh and moves the world onto it. Atomic: if the world cannot take the
    /// new mesh, the hierarchy's operations are undone (newest first, see
    /// [`RedGreen::undo`]) and the world, the counters and the events stay as
    /// they were. Red-green only: panics on an adapter of the tensor method,
    /// whose grid the operations would leave out of step with the world.
    pub fn apply(
        &mut self,
        world: &mut World,
        ops: &[(RedGreenOp, Option<Scalar>)],
        step: u64,
    ) -> Result<bool, MeshError> {
        assert!(
            self.tensor.is_none(),
            "red-green operations on an adapter of the tensor method"
        );
        let mut applied: Vec<Applied> = Vec::new();
        let plain: Vec<RedGreenOp> = ops.iter().map(|o| o.0).collect();
        self.hierarchy.apply(&plain, &mut applied);
        // The angle that asked for each operation (forced splits have none).
        let asked_for = |op: RedGreenOp| ops.iter().find(|o| o.0 == op).and_then(|o| o.1);
        let mut asked: Vec<Option<Scalar>> = applied.iter().map(|a| asked_for(a.op)).collect();
        let before = applied.len();
        self.hierarchy.close(&mut applied);
        asked.extend(std::iter::repeat_n(None, applied.len() - before));
        if applied.is_empty() {
            return Ok(false);
        }
        let mut events: Vec<AdaptEvent> = applied
            .iter()
            .zip(asked)
            .map(|(a, angle)| red_green_event(world, a, angle, step))
            .collect();
        if let Err(e) = self.rebuild_world(world) {
            for a in applied.iter().rev() {
                self.hierarchy.undo(a);
            }
            return Err(e);
        }
        for (a, event) in applied.iter().zip(events.iter_mut()) {
            match a.op {
                RedGreenOp::Merge(n) => {
                    self.stats.merges += 1;
                    self.pass_merges.push(n);
                    for c in a.children {
                        self.bounces.remove(&c);
                    }
                }
                RedGreenOp::Split(l) => {
                    self.stats.splits += 1;
                    self.stats.closure_splits += a.forced as u64;
                    if !a.forced && self.merged_last_pass.binary_search(&l).is_ok() {
                        *self.bounces.entry(l).or_default() += 1;
                        self.stats.bounces += 1;
                        event.kind = EventKind::Bounce;
                    }
                }
            }
        }
        self.events.extend(events);
        self.stats.changed_passes += 1;
        self.stats.max_ops_per_pass = self.stats.max_ops_per_pass.max(applied.len() as u64);
        self.debug_check(world);
        Ok(true)
    }

    /// Builds the conforming mesh from the hierarchy, compacts the vertices and
    /// transfers the world's state onto it (the world is unchanged on error).
    fn rebuild_world(&mut self, world: &mut World) -> Result<(), MeshError> {
        let (tris, levels, owner) = self.hierarchy.build(self.config.alternate_diagonals);
        let (first_new, created) = self.hierarchy.created();
        let (map, remeshed) = compact(
            self.hierarchy.material(),
            (first_new, created),
            &tris,
            levels,
            VertexOrder::FirstUse,
        );
        let material = remeshed.material.clone();
        self.last_origins = transfer(world, self.density, remeshed)?;
        self.hierarchy.remap(&map, &material);
        self.owner = owner;
        Ok(())
    }
}

/// The event of one red-green operation, at the world's positions before the
/// remesh (the node's corners are vertices of the old mesh).
fn red_green_event(world: &World, a: &Applied, angle: Option<Scalar>, step: u64) -> AdaptEvent {
    let centre = a
        .vertices
        .iter()
        .map(|&v| world.x[v as usize])
        .sum::<Vector>()
        / 3.0;
    let kind = match a.op {
        RedGreenOp::Merge(_) => EventKind::Merge,
        RedGreenOp::Split(_) if a.forced => EventKind::ClosureSplit,
        RedGreenOp::Split(_) => EventKind::Split,
    };
    AdaptEvent {
        kind,
        position: centre,
        level: a.level,
        angle: if a.forced { None } else { angle },
        step,
    }
}
