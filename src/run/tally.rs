//! Running statistics of a run, turned into its [`Summary`] at the end.

use std::path::PathBuf;

use crate::math::Scalar;
use crate::physics::{Energy, Model, Stepper};
use crate::scene::Pin;
use crate::sim::SimState;
use crate::summary::{
    AdaptiveDtSummary, Adaptivity, Collisions, Conservation, EnergySummary, Extent, Measurements,
    MeshSize, Range, RecordingSummary, SceneChecks, StepEffort, Stepping, Summary, WallTimes,
};
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
    pin_mismatches: Vec<crate::pins::PinMismatch>,
}

/// End-of-run facts handed to [`Tally::finish`].
pub(super) struct TallyEnd<'a> {
    pub(super) scene: String,
    pub(super) frames: u64,
    pub(super) sim_time: Scalar,
    pub(super) wall_time_s: Scalar,
    pub(super) sim_wall_s: Scalar,
    pub(super) record_wall_s: Scalar,
    pub(super) dt: Scalar,
    /// The largest step taken, s.
    pub(super) dt_max: Scalar,
    /// True with `dt = "adaptive"`.
    pub(super) adaptive_dt: bool,
    pub(super) interrupted: bool,
    pub(super) recording: Option<(PathBuf, u64, u64)>,
    /// The state at the end: its ledger, effort and adaptive counters.
    pub(super) state: &'a SimState,
    pub(super) mass_final: Scalar,
    pub(super) cusick: Option<crate::collide::cusick::CusickSummary>,
    pub(super) cantilever: Option<crate::cantilever::CantileverSummary>,
    /// The rest criterion's outcome, when the scene has one.
    pub(super) rest: Option<crate::summary::RestSummary>,
}

impl Tally {
    /// Starts the tally at the initial state; `pins` are the scene's pins,
    /// compared with the vertices they hold on the initial mesh.
    pub(super) fn new(model: &Model, world: &World, stepper: &Stepper, pins: &[Pin]) -> Tally {
        let e = stepper.energy(model, world).total();
        Tally {
            vertices: Range::empty(),
            triangles: Range::empty(),
            energy_initial: e,
            energy_final: e,
            energy_max: e,
            mass_initial: stepper.elements.total_mass(),
            max_level: 0,
            pin_mismatches: crate::pins::mismatches(pins, &world.mesh),
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

    /// The summary of the run that ended with `end`.
    pub(super) fn finish(&self, end: TallyEnd) -> Summary {
        let (ledger, effort) = (&end.state.ledger, &end.state.effort);
        let adapt = end.state.adapter.as_ref().map(|a| a.stats);
        let collision = ledger.collision;
        let world = &end.state.world;
        let stepping = self.stepping(&end);
        Summary {
            extent: Extent {
                scene: end.scene,
                frames: end.frames,
                steps: effort.solver.steps,
                sim_time: end.sim_time,
            },
            wall: WallTimes {
                wall_time_s: end.wall_time_s,
                simulation_wall_s: end.sim_wall_s,
                recording_wall_s: end.record_wall_s,
            },
            stepping,
            mesh: MeshSize {
                vertices: self.vertices,
                triangles: self.triangles,
            },
            conservation: Conservation {
                mass_initial: self.mass_initial,
                mass_final: end.mass_final,
                energy: EnergySummary {
                    initial: self.energy_initial,
                    r#final: self.energy_final,
                    max: self.energy_max,
                    external_work: ledger.work(),
                    excess_max: ledger.excess_max,
                },
            },
            effort: StepEffort {
                nan_recoveries: effort.step_halvings,
                energy_retries: effort.energy_retries,
                solver: effort.solver,
            },
            adaptivity: Adaptivity {
                splits: adapt.map_or(0, |a| a.splits),
                merges: adapt.map_or(0, |a| a.merges),
                rollbacks: adapt.map_or(0, |a| a.rollbacks),
                max_level: self.max_level,
                adapt,
            },
            collision: Collisions {
                max_penetration: collision.max_penetration,
                contacts: collision.mean_contacts(),
                self_pairs_tested: collision.mean_self_pairs_tested(),
                self_culled_fraction: collision.self_culled_fraction(),
                collision_wall_s: collision.collision_wall_s,
                self_collision_wall_s: collision.self_collision_wall_s,
            },
            measurements: Measurements {
                cusick: end.cusick,
                cantilever: end.cantilever,
            },
            checks: SceneChecks {
                pin_mismatches: self.pin_mismatches.clone(),
                seams: crate::summary::SeamSummary::of(&world.mesh, &end.state.seams, &world.x),
                rest: end.rest,
            },
            interrupted: end.interrupted,
            recording: end.recording.map(|(path, bytes, frames)| RecordingSummary {
                path,
                bytes,
                frames,
            }),
        }
    }

    /// The steps' sizes and rate at the end `end`.
    fn stepping(&self, end: &TallyEnd) -> Stepping {
        let (ledger, effort) = (&end.state.ledger, &end.state.effort);
        let vertex_steps = effort.solver.steps as Scalar * self.vertices.mean;
        Stepping {
            dt: end.dt,
            dt_max: end.dt_max,
            steps_accepted: ledger.steps_done,
            dt_mean: if ledger.steps_done > 0 {
                end.sim_time / ledger.steps_done as Scalar
            } else {
                0.0
            },
            adaptive_dt: end.adaptive_dt.then_some(AdaptiveDtSummary {
                max_dt: effort.max_dt,
                refused: effort.refused,
                largest_error: effort.largest_step_error,
            }),
            vertex_steps_per_s: if end.sim_wall_s > 0.0 {
                vertex_steps / end.sim_wall_s
            } else {
                0.0
            },
        }
    }
}
