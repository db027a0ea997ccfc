//! Paper A's pass on the adapter: the criterion's operations applied to the
//! refinement hierarchy (`red_green.rs`), closure, the world moved onto the
//! conforming mesh built from it, and an event with its reason for each
//! operation.

use super::decision::{Reading, Reason};
use super::red_green::{Applied, RedGreenOp};
use super::red_green_pass::{RedGreenState, vertex_position};
use super::{AdaptConfig, AdaptEvent, Adapter, EventKind, Measured, MethodState, edge_angles};
use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::world::World;

impl Adapter {
    /// One pass of paper A's method: the criterion's merges, then its splits,
    /// then closure; the merges the level rule refuses are logged when new.
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
        let marks = self.red_green().marks(c, world, angles, known);
        self.stats.passes += 1;
        if let Some(gate) = &c.gate
            && !gate.applies(&self.red_green().pass_size(world, &marks))
        {
            // Deferred: nothing changes, and the latest applied pass's merges
            // and refusals stay the ones the next applied pass is held to.
            self.stats.deferred_passes += 1;
            self.stats.note_levels(world, c.max_level);
            return Ok(false);
        }
        self.red_green().pass_merges.clear();
        let refusals = self.red_green().refusal_events(world, &marks, step);
        let mut ops: Vec<(RedGreenOp, Reason)> = marks
            .merges
            .iter()
            .map(|&(p, r)| (RedGreenOp::Merge(p), r))
            .collect();
        ops.extend(marks.splits.iter().map(|&(l, r)| (RedGreenOp::Split(l), r)));
        let changed = self.apply_reasons(c, world, &ops, step, false);
        if changed.is_ok() {
            self.events.extend(refusals);
        }
        let rg = self.red_green();
        rg.merged_last_pass = std::mem::take(&mut rg.pass_merges);
        rg.merged_last_pass.sort_unstable();
        self.stats.note_levels(world, c.max_level);
        changed
    }

    /// Records a rollback of step `step`, triggered by the leaves `marks` (from
    /// [`Adapter::rollback_marks`]): the event sits at the leaf with the largest
    /// reading (at the cloth's centre when there is none).
    pub fn note_rollback(&mut self, world: &World, marks: &[(u32, Reading)], step: u64) {
        self.stats.rollbacks += 1;
        let worst = marks
            .iter()
            .max_by(|a, b| a.1.ratio.total_cmp(&b.1.ratio).then(b.0.cmp(&a.0)));
        let corners = match (&self.method, worst) {
            (MethodState::RedGreen(rg), Some(&(leaf, _))) => {
                Some(rg.hierarchy.vertices(leaf).map(|v| world.x[v as usize]))
            }
            _ => None,
        };
        let position = match corners {
            Some(c) => (c[0] + c[1] + c[2]) / 3.0,
            None => world.x.iter().copied().sum::<Vector>() / world.x.len().max(1) as Scalar,
        };
        let reading = worst.map(|m| m.1).unwrap_or_default();
        self.events.push(AdaptEvent {
            kind: EventKind::Rollback,
            position,
            level: 0,
            angle: worst.map(|m| m.1.angle),
            step,
            reason: Reason::Rollback {
                reading,
                marked: marks.len(),
            },
            corners,
        });
    }

    /// The red-green state. Panics on an adapter of another method.
    pub(super) fn red_green(&mut self) -> &mut RedGreenState {
        match &mut self.method {
            MethodState::RedGreen(rg) => rg,
            _ => panic!("red-green operations on an adapter of the edge or tensor method"),
        }
    }

    /// Refines the leaves in `marks` (from [`Adapter::refinement_marks`], each
    /// with its angle) and rebuilds the world; used by rollback on the restored
    /// state: the splits are logged as a rollback's, and their triangles are
    /// held by rollback ([`super::TriangleState::HeldByRollback`]) until merged.
    pub fn refine(
        &mut self,
        config: &AdaptConfig,
        world: &mut World,
        marks: &[(u32, Scalar)],
        step: u64,
    ) -> Result<bool, MeshError> {
        let ops: Vec<_> = marks
            .iter()
            .map(|&(l, angle)| (RedGreenOp::Split(l), Reason::RollbackSplit { angle }))
            .collect();
        self.apply_reasons(config, world, &ops, step, true)
    }

    /// Applies operations (each with the angle that asked for it, if any),
    /// closes the mesh and moves the world onto it. Atomic: if the world cannot
    /// take the new mesh, the hierarchy's operations are undone (newest first,
    /// see [`super::red_green::RedGreen::undo`]) and the world, the counters and
    /// the events stay as they were. Red-green only: panics on an adapter of
    /// another method.
    pub fn apply(
        &mut self,
        config: &AdaptConfig,
        world: &mut World,
        ops: &[(RedGreenOp, Option<Scalar>)],
        step: u64,
    ) -> Result<bool, MeshError> {
        let ops: Vec<_> = ops
            .iter()
            .map(|&(op, angle)| (op, Reason::Given { angle }))
            .collect();
        self.apply_reasons(config, world, &ops, step, false)
    }

    /// [`Adapter::apply`] of operations each with its reason; `rollback`: the
    /// operations are a rollback's refinement.
    fn apply_reasons(
        &mut self,
        config: &AdaptConfig,
        world: &mut World,
        ops: &[(RedGreenOp, Reason)],
        step: u64,
        rollback: bool,
    ) -> Result<bool, MeshError> {
        let density = self.density;
        let rg = self.red_green();
        let mut applied: Vec<Applied> = Vec::new();
        let plain: Vec<RedGreenOp> = ops.iter().map(|o| o.0).collect();
        rg.hierarchy.apply(&plain, &mut applied);
        rg.hierarchy.close(&mut applied);
        if applied.is_empty() {
            return Ok(false);
        }
        let mut events: Vec<AdaptEvent> = applied
            .iter()
            .map(|a| {
                // Forced splits were not asked for: their reason is their own.
                let asked = ops.iter().find(|o| o.0 == a.op && !a.forced).map(|o| o.1);
                red_green_event(world, rg, a, asked, step)
            })
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
        rg.count(&applied, &mut events, &mut self.stats, rollback);
        self.events.extend(events);
        self.stats.changed_passes += 1;
        self.stats.max_ops_per_pass = self.stats.max_ops_per_pass.max(applied.len() as u64);
        self.debug_check(world);
        Ok(true)
    }
}

/// The event of one red-green operation, at the world's positions before the
/// remesh, with the reason that asked for it (`None` for a forced split, whose
/// reason is the neighbour that forced it or closure).
fn red_green_event(
    world: &World,
    rg: &RedGreenState,
    a: &Applied,
    asked: Option<Reason>,
    step: u64,
) -> AdaptEvent {
    let corners = a.vertices.map(|v| vertex_position(world, &rg.hierarchy, v));
    let centre = |c: [Vector; 3]| (c[0] + c[1] + c[2]) / 3.0;
    let kind = match a.op {
        RedGreenOp::Merge(_) => EventKind::Merge,
        RedGreenOp::Split(_) if a.forced => EventKind::ClosureSplit,
        RedGreenOp::Split(_) => EventKind::Split,
    };
    let reason = match (asked, a.neighbour) {
        (Some(r), _) => r,
        (None, Some(n)) => Reason::Neighbour {
            neighbour: centre(rg.node_corners(world, n)),
            level: rg.hierarchy.level(n),
        },
        (None, None) if a.forced => Reason::Closure,
        (None, None) => Reason::Given { angle: None },
    };
    let angle = match reason {
        Reason::Criterion { reading, .. } | Reason::Bounce { reading, .. } => Some(reading.angle),
        Reason::RollbackSplit { angle } => Some(angle),
        Reason::Given { angle } => angle,
        _ => None,
    };
    AdaptEvent {
        kind,
        position: centre(corners),
        level: a.level,
        angle,
        step,
        reason,
        corners: Some(corners),
    }
}
