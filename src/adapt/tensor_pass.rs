//! The tensor method's pass on the adapter (`tensor.rs`): measures the grid
//! lines' turns, inserts and removes lines, moves the world onto the new grid
//! and reports one event per line.

use super::tensor::{AxisOps, Thresholds};
use super::transfer::transfer;
use super::{AdaptConfig, AdaptEvent, Adapter, EventKind, MethodState, Reading, Reason};
use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::spec::AdaptCriterion;
use crate::world::World;

impl Adapter {
    /// One pass of the tensor method on `world` after step `step`; true when
    /// the mesh changed. Atomic: if the world refuses the new mesh, the grid,
    /// the world, the events and the counters other than `passes` stay as
    /// they were.
    pub(super) fn tensor_pass(
        &mut self,
        c: &AdaptConfig,
        world: &mut World,
        step: u64,
    ) -> Result<bool, MeshError> {
        let MethodState::Tensor(grid) = &mut self.method else {
            unreachable!("the tensor pass runs on an adapter with a tensor grid");
        };
        let sizing = c.criterion == AdaptCriterion::Sizing;
        let refine = c.refine_angle.to_radians();
        let th = Thresholds {
            sizing,
            refine,
            coarsen: if sizing {
                refine / c.hysteresis
            } else {
                c.coarsen_angle.to_radians()
            },
            max_halvings: c.max_level / 2,
            min_edge: c.min_edge_length,
        };
        self.stats.passes += 1;
        assert_eq!(
            grid.counts().0 * grid.counts().1,
            world.x.len(),
            "tensor grid out of step with the world"
        );
        let measures = grid.measures(&world.x, sizing);
        let ops = grid.marks(&measures, &th);
        let count =
            ops.0.splits.len() + ops.0.merges.len() + ops.1.splits.len() + ops.1.merges.len();
        // The finest level a triangle can reach (levels are even here).
        let top = 2 * (c.max_level / 2);
        if count == 0 {
            self.stats.note_levels(world, top);
            return Ok(false);
        }
        let events = line_events(world, &ops, grid, (refine, step));
        let before = grid.clone();
        let remeshed = grid.apply(&ops);
        match transfer(world, self.density, remeshed) {
            Ok(origins) => self.last_origins = origins,
            Err(e) => {
                *grid = before;
                return Err(e);
            }
        }
        for e in &events {
            match e.kind {
                EventKind::Merge => self.stats.merges += 1,
                EventKind::ClosureSplit => {
                    self.stats.splits += 1;
                    self.stats.closure_splits += 1;
                }
                _ => self.stats.splits += 1,
            }
        }
        self.events.extend(events);
        self.stats.changed_passes += 1;
        self.stats.max_ops_per_pass = self.stats.max_ops_per_pass.max(count as u64);
        self.stats.note_levels(world, top);
        self.debug_check(world);
        Ok(true)
    }

    /// The tensor method's grid (`None` for the other methods).
    pub fn tensor_grid(&self) -> Option<&super::tensor::TensorGrid> {
        match &self.method {
            MethodState::Tensor(grid) => Some(grid),
            _ => None,
        }
    }
}

/// One event per inserted or removed line, at the mean of the old world
/// positions along it (an inserted line: along the two lines it falls
/// between). The angle is the measure that asked for a split, in degrees for
/// the angle criterion and as `kappa h` in degrees for the sizing one.
fn line_events(
    world: &World,
    ops: &(AxisOps, AxisOps),
    grid: &super::tensor::TensorGrid,
    (refine, step): (Scalar, u64),
) -> Vec<AdaptEvent> {
    let (nu, nv) = grid.counts();
    let mean_u = |lines: &[usize]| {
        let s: Vector = (0..nv)
            .flat_map(|j| lines.iter().map(move |&i| world.x[j * nu + i]))
            .sum();
        s / (nv * lines.len()) as Scalar
    };
    let mean_v = |lines: &[usize]| {
        let s: Vector = lines
            .iter()
            .flat_map(|&j| world.x[j * nu..(j + 1) * nu].iter().copied())
            .sum();
        s / (nu * lines.len()) as Scalar
    };
    let (lu, lv) = grid.column_levels();
    let mut events = Vec::new();
    axis_events((&ops.0, refine), &lu, mean_u, step, &mut events);
    axis_events((&ops.1, refine), &lv, mean_v, step, &mut events);
    events
}

/// The events of one axis's operations (`level`: each column's level before
/// the pass, in halvings; `mean`: the mean old position along some lines;
/// `refine`: the threshold a split's measure is read against, radians).
fn axis_events(
    (ops, refine): (&AxisOps, Scalar),
    level: &[u8],
    mean: impl Fn(&[usize]) -> Vector,
    step: u64,
    out: &mut Vec<AdaptEvent>,
) {
    for &(col, asked) in &ops.splits {
        out.push(AdaptEvent {
            kind: if asked.is_some() {
                EventKind::Split
            } else {
                EventKind::ClosureSplit
            },
            position: mean(&[col, col + 1]),
            level: (level[col] + 1).saturating_mul(2),
            angle: asked.map(Scalar::to_degrees),
            step,
            reason: match asked {
                Some(a) => Reason::Criterion {
                    reading: Reading::of_angle(a, refine),
                    limit: 1.0,
                },
                None => Reason::Closure,
            },
            corners: None,
        });
    }
    // A removed line's columns are at its level; their parent one coarser.
    for &m in &ops.merges {
        out.push(AdaptEvent {
            kind: EventKind::Merge,
            position: mean(&[m]),
            level: level[m - 1].saturating_sub(1).saturating_mul(2),
            angle: None,
            step,
            reason: Reason::Flat,
            corners: None,
        });
    }
}
