//! Running statistics of a run, turned into its [`Summary`] at the end.

use std::path::PathBuf;

use crate::adapt::AdaptStats;
use crate::collide::CollisionStats;
use crate::math::Scalar;
use crate::physics::{Energy, Stepper};
use crate::summary::{EnergySummary, Range, RecordingSummary, Summary};
use crate::world::World;

/// Running statistics for the summary.
pub(super) struct Tally {
    vertices: Range,
    triangles: Range,
    energy_initial: Scalar,
    energy_final: Scalar,
    energy_max: Scalar,
    mass_initial: Scalar,
    max_level: u8,
}

/// End-of-run facts handed to [`Tally::finish`].
pub(super) struct TallyEnd<'a> {
    pub(super) scene: String,
    pub(super) frames: u64,
    pub(super) steps: u64,
    pub(super) sim_time: Scalar,
    pub(super) wall_time_s: Scalar,
    pub(super) sim_wall_s: Scalar,
    pub(super) record_wall_s: Scalar,
    pub(super) dt: Scalar,
    pub(super) nan_recoveries: u64,
    pub(super) interrupted: bool,
    pub(super) recording: Option<(PathBuf, u64, u64)>,
    pub(super) stepper: &'a Stepper,
    pub(super) adapt: Option<AdaptStats>,
    pub(super) collision: CollisionStats,
    pub(super) cusick: Option<crate::collide::cusick::CusickSummary>,
    pub(super) cantilever: Option<crate::cantilever::CantileverSummary>,
    pub(super) external_work: Scalar,
    pub(super) excess_max: Scalar,
    pub(super) energy_retries: u64,
}

impl Tally {
    pub(super) fn new(world: &World, stepper: &Stepper) -> Tally {
        let e = stepper.energy(world).total();
        Tally {
            vertices: Range::empty(),
            triangles: Range::empty(),
            energy_initial: e,
            energy_final: e,
            energy_max: e,
            mass_initial: stepper.elements.total_mass(),
            max_level: 0,
        }
    }

    pub(super) fn observe(&mut self, world: &World, e: Energy) {
        self.max_level = self
            .max_level
            .max(world.mesh.levels.iter().copied().max().unwrap_or(0));
        self.vertices.add(world.x.len() as Scalar);
        self.triangles.add(world.mesh.triangles.len() as Scalar);
        self.energy_final = e.total();
        self.energy_max = self.energy_max.max(e.total());
    }

    pub(super) fn finish(self, end: TallyEnd) -> Summary {
        let vertex_steps = end.steps as Scalar * self.vertices.mean;
        Summary {
            scene: end.scene,
            frames: end.frames,
            steps: end.steps,
            sim_time: end.sim_time,
            wall_time_s: end.wall_time_s,
            simulation_wall_s: end.sim_wall_s,
            recording_wall_s: end.record_wall_s,
            dt: end.dt,
            vertex_steps_per_s: if end.sim_wall_s > 0.0 {
                vertex_steps / end.sim_wall_s
            } else {
                0.0
            },
            vertices: self.vertices,
            triangles: self.triangles,
            mass_initial: self.mass_initial,
            mass_final: end.stepper.elements.total_mass(),
            energy: EnergySummary {
                initial: self.energy_initial,
                r#final: self.energy_final,
                max: self.energy_max,
                external_work: end.external_work,
                excess_max: end.excess_max,
            },
            nan_recoveries: end.nan_recoveries,
            energy_retries: end.energy_retries,
            solver: end.stepper.stats,
            interrupted: end.interrupted,
            splits: end.adapt.map_or(0, |a| a.splits),
            merges: end.adapt.map_or(0, |a| a.merges),
            rollbacks: end.adapt.map_or(0, |a| a.rollbacks),
            max_level: self.max_level,
            adapt: end.adapt,
            max_penetration: end.collision.max_penetration,
            contacts: end.collision.mean_contacts(),
            self_pairs_tested: end.collision.mean_self_pairs_tested(),
            self_culled_fraction: end.collision.self_culled_fraction(),
            collision_wall_s: end.collision.collision_wall_s,
            self_collision_wall_s: end.collision.self_collision_wall_s,
            cusick: end.cusick,
            cantilever: end.cantilever,
            recording: end.recording.map(|(path, bytes, frames)| RecordingSummary {
                path,
                bytes,
                frames,
            }),
        }
    }
}
