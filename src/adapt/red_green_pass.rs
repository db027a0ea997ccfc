//! Paper A's pass on the adapter: the criterion's marks, the operations on the
//! refinement hierarchy (`red_green.rs`), closure, and the world moved onto the
//! conforming mesh built from it.

use std::collections::HashMap;

use super::red_green::{Applied, RedGreen, RedGreenOp};
use super::transfer::{Origin, PanelCorners, VertexOrder, compact, transfer};
use super::{AdaptConfig, AdaptEvent, Adapter, EventKind, Measured, MethodState, edge_angles};
use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::spec::AdaptCriterion;
use crate::world::World;

/// Nodes of the hierarchy to merge or split, each with the angle that asked.
type Marks = Vec<(u32, Scalar)>;

/// What the red-green method keeps between passes: the hierarchy, which leaf
/// owns each triangle of the world's mesh, and what decides bounces.
#[derive(Debug, Clone)]
pub(super) struct RedGreenState {
    pub(super) hierarchy: RedGreen,
    /// Leaf of the hierarchy that owns each triangle of the world's mesh.
    pub(super) owner: Vec<u32>,
    /// The parents the latest pass merged, sorted (a split of one of them by
    /// the criterion before the next pass is a bounce).
    pub(super) merged_last_pass: Vec<u32>,
    /// The parents [`Adapter::apply`] merged since the pass began.
    pub(super) pass_merges: Vec<u32>,
    /// Per parent: how many of its merges bounced (its sizing hysteresis is
    /// doubled that many times; dropped when the parent itself merges away).
    pub(super) bounces: HashMap<u32, u32>,
}

impl RedGreenState {
    /// The hierarchy of `world`'s mesh, its triangles at level 0.
    pub(super) fn new(world: &World) -> RedGreenState {
        let m = &world.mesh;
        let hierarchy = match m.panels() {
            None => RedGreen::new(&m.triangles, &m.material),
            Some(p) => {
                RedGreen::with_corners(&m.triangles, &m.material, &p.corners, &p.of_triangle)
            }
        };
        RedGreenState {
            hierarchy,
            owner: (0..world.mesh.triangles.len() as u32).collect(),
            merged_last_pass: Vec::new(),
            pass_merges: Vec::new(),
            bounces: HashMap::new(),
        }
    }

    /// The merges and the splits the criterion asks for, each with its angle.
    fn marks(
        &self,
        c: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
        known: Measured,
    ) -> (Marks, Marks) {
        match c.criterion {
            AdaptCriterion::Angle => (
                self.merge_marks(c, world, angles),
                self.refinement_marks(c, world, angles),
            ),
            AdaptCriterion::Sizing => {
                let curv = self.leaf_curvatures(c, world, angles, known.obstacle_planes);
                let merges = self.sizing_merge_marks(c, &curv);
                (merges, self.sizing_refinement_marks(c, &curv))
            }
        }
    }

    /// Builds the conforming mesh from the hierarchy, compacts the vertices and
    /// transfers the world's state onto it; returns where the new vertices came
    /// from (the world and the hierarchy are unchanged on error).
    fn rebuild_world(
        &mut self,
        world: &mut World,
        density: Scalar,
        alternate_diagonals: bool,
    ) -> Result<Vec<Origin>, MeshError> {
        let built = self.hierarchy.build_with_corners(alternate_diagonals);
        let (first_new, created) = self.hierarchy.created();
        let (map, mut remeshed) = compact(
            self.hierarchy.material(),
            (first_new, created),
            &built.triangles,
            built.levels,
            VertexOrder::FirstUse,
        );
        if world.mesh.panels().is_some() {
            remeshed.corners = Some(PanelCorners {
                corners: built.corners,
                of_triangle: built.panels,
            });
        }
        let origins = transfer(world, density, remeshed)?;
        // A garment's home coordinates are chosen by the transfer.
        self.hierarchy.remap(&map, &world.mesh.material);
        self.owner = built.owner;
        Ok(origins)
    }

    /// Counts the applied operations (merges, splits, bounces) and turns the
    /// events of the criterion's splits that undo a merge into bounces.
    fn count(
        &mut self,
        applied: &[Applied],
        events: &mut [AdaptEvent],
        stats: &mut super::AdaptStats,
    ) {
        for (a, event) in applied.iter().zip(events.iter_mut()) {
            match a.op {
                RedGreenOp::Merge(n) => {
                    stats.merges += 1;
                    self.pass_merges.push(n);
                    for c in a.children {
                        self.bounces.remove(&c);
                    }
                }
                RedGreenOp::Split(l) => {
                    stats.splits += 1;
                    stats.closure_splits += a.forced as u64;
                    if !a.forced && self.merged_last_pass.binary_search(&l).is_ok() {
                        *self.bounces.entry(l).or_default() += 1;
                        stats.bounces += 1;
                        event.kind = EventKind::Bounce;
                    }
                }
            }
        }
    }
}

impl Adapter {
    /// One pass of paper A's method: the criterion's merges, then its splits,
    /// then closure.
    pub(super) fn red_green_pass(
        &mut self,
        c: &AdaptConfig,
        world: &mut World,
        step: u64,
        known: Measured,
    ) -> Result<bool, MeshError> {
        let measured;
        let angles = match known.angles {
            Some(a) => a,
            None => {
                measured = edge_angles(world);
                &measured
            }
        };
        debug_assert_eq!(angles.len(), world.mesh.edges.len(), "stale edge angles");
        let (merges, splits) = self.red_green().marks(c, world, angles, known);
        self.stats.passes += 1;
        self.red_green().pass_merges.clear();
        let mut ops: Vec<(RedGreenOp, Option<Scalar>)> = merges
            .iter()
            .map(|&(p, a)| (RedGreenOp::Merge(p), Some(a)))
            .collect();
        ops.extend(splits.iter().map(|&(l, a)| (RedGreenOp::Split(l), Some(a))));
        let changed = self.apply(c, world, &ops, step);
        let rg = self.red_green();
        rg.merged_last_pass = std::mem::take(&mut rg.pass_merges);
        rg.merged_last_pass.sort_unstable();
        self.stats.note_levels(world, c.max_level);
        changed
    }

    /// The red-green state. Panics on an adapter of another method.
    fn red_green(&mut self) -> &mut RedGreenState {
        match &mut self.method {
            MethodState::RedGreen(rg) => rg,
            _ => panic!("red-green operations on an adapter of the edge or tensor method"),
        }
    }

    /// Refines the leaves in `marks` (from [`Adapter::refinement_marks`]) and
    /// rebuilds the world; used by rollback on the restored state.
    pub fn refine(
        &mut self,
        config: &AdaptConfig,
        world: &mut World,
        marks: &[(u32, Scalar)],
        step: u64,
    ) -> Result<bool, MeshError> {
        let ops: Vec<_> = marks
            .iter()
            .map(|&(l, a)| (RedGreenOp::Split(l), Some(a)))
            .collect();
        self.apply(config, world, &ops, step)
    }

    /// Applies operations (each with the angle that asked for it), closes the
    /// mesh and moves the world onto it. Atomic: if the world cannot take the
    /// new mesh, the hierarchy's operations are undone (newest first, see
    /// [`RedGreen::undo`]) and the world, the counters and the events stay as
    /// they were. Red-green only: panics on an adapter of another method.
    pub fn apply(
        &mut self,
        config: &AdaptConfig,
        world: &mut World,
        ops: &[(RedGreenOp, Option<Scalar>)],
        step: u64,
    ) -> Result<bool, MeshError> {
        let density = self.density;
        let rg = self.red_green();
        let mut applied: Vec<Applied> = Vec::new();
        let plain: Vec<RedGreenOp> = ops.iter().map(|o| o.0).collect();
        rg.hierarchy.apply(&plain, &mut applied);
        // The angle that asked for each operation (forced splits have none).
        let asked_for = |op: RedGreenOp| ops.iter().find(|o| o.0 == op).and_then(|o| o.1);
        let mut asked: Vec<Option<Scalar>> = applied.iter().map(|a| asked_for(a.op)).collect();
        let before = applied.len();
        rg.hierarchy.close(&mut applied);
        asked.extend(std::iter::repeat_n(None, applied.len() - before));
        if applied.is_empty() {
            return Ok(false);
        }
        let mut events: Vec<AdaptEvent> = applied
            .iter()
            .zip(asked)
            .map(|(a, angle)| red_green_event(world, a, angle, step))
            .collect();
        match rg.rebuild_world(world, density, config.alternate_diagonals) {
            Ok(origins) => self.last_origins = origins,
            Err(e) => {
                let rg = self.red_green();
                for a in applied.iter().rev() {
                    rg.hierarchy.undo(a);
                }
                return Err(e);
            }
        }
        let MethodState::RedGreen(rg) = &mut self.method else {
            unreachable!("checked above");
        };
        rg.count(&applied, &mut events, &mut self.stats);
        self.events.extend(events);
        self.stats.changed_passes += 1;
        self.stats.max_ops_per_pass = self.stats.max_ops_per_pass.max(applied.len() as u64);
        self.debug_check(world);
        Ok(true)
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
