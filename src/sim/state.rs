//! [`SimState`]: everything a run's result depends on that changes as it runs.

use crate::adapt::Adapter;
use crate::collide::CollisionStats;
use crate::math::{Scalar, Vector};
use crate::physics::{Contact, StepStats};
use crate::world::World;

use super::{EnergyBound, Pipeline, Setup, StepControl, WeldEvent};

/// The simulation state: one cloneable value (see the [module docs](super)).
///
/// Restoring a saved state ([`SimState::restore`]) brings back everything but the
/// [`Effort`] counters, which measure the computer's work rather than the cloth's:
/// a retried frame's cost stays counted.
#[derive(Debug)]
pub struct SimState {
    /// Mesh, positions, velocities, time and pins.
    pub world: World,
    /// The adaptive hierarchy, its counters and its pending events (`None`: the
    /// scene does not adapt).
    pub adapter: Option<Adapter>,
    /// The obstacle contacts the last step ended in, one per vertex (empty before
    /// the first step, after a remesh, or without obstacles); the next implicit
    /// step filters them (see [`crate::physics::implicit`]).
    pub contacts: Vec<Contact>,
    /// The implicit solver's first guess for the next step: the last step's
    /// velocity change, one per vertex (empty before the first implicit step,
    /// after a remesh or a restored frame start, or with explicit integrators).
    /// State rather than scratch: it steers the next solve, so a pipeline rebuilt
    /// from this state continues exactly as the old one would have.
    pub warm_start: Vec<Vector>,
    /// The energy accounting and the accepted steps.
    pub ledger: Ledger,
    /// What the computer did, retried work included.
    pub effort: Effort,
    /// Each seam of a garment, open or welded (empty without panels).
    pub seams: Vec<SeamState>,
    /// Seams welded since the recording last took them.
    pub welds: Vec<WeldEvent>,
    /// The adaptive step's proposal for the next step (read with
    /// `dt = "adaptive"` only).
    pub step_control: StepControl,
}

/// Whether a seam is open (sewing springs pull it) or welded into one surface.
/// The mesh says which vertices a seam pairs (one vertex per pair once
/// welded, [`crate::mesh::Seam::is_open`]); the state adds when it was welded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SeamState {
    /// The sides are separate vertices, pulled together by sewing springs.
    Open,
    /// The sides are one surface since the given simulated time, s.
    Welded {
        /// When the seam was welded, s (0 for a seam welded when the run
        /// starts).
        time: Scalar,
    },
}

impl SeamState {
    /// The state of each seam of `world`'s mesh at the start of a run: open
    /// where its pairs are apart, welded at time 0 where they are one vertex.
    pub fn at_start(world: &World) -> Vec<SeamState> {
        world
            .mesh
            .seams()
            .iter()
            .map(|s| {
                if s.is_open() {
                    SeamState::Open
                } else {
                    SeamState::Welded { time: 0.0 }
                }
            })
            .collect()
    }

    /// True while the seam is open.
    pub fn is_open(self) -> bool {
        self == SeamState::Open
    }

    /// When the seam was welded, s (`None` while it is open).
    pub fn welded_at(self) -> Option<Scalar> {
        match self {
            SeamState::Open => None,
            SeamState::Welded { time } => Some(time),
        }
    }
}

/// The energy accounting of a run: the work done on the cloth from outside, the
/// collision passes' counters and the bound the explosion check holds it to.
/// Restored with the state, so a rejected attempt leaves no trace in it.
#[derive(Debug, Clone, Copy)]
pub struct Ledger {
    /// Steps accepted so far.
    pub steps_done: u64,
    /// Work done on the cloth by wind, moving air and moving pins so far, J
    /// (moving obstacles' is in `collision`).
    pub external_work: Scalar,
    /// What the collision passes did (moving obstacles' work included).
    pub collision: CollisionStats,
    /// The energy bound of the run, fixed at its start.
    pub bound: EnergyBound,
    /// Largest `E(t) - E(0) - W(t)` at the end of an accepted frame so far, J.
    pub excess_max: Scalar,
}

impl Ledger {
    /// Work done on the cloth from outside so far (wind, pins, moving obstacles), J.
    pub fn work(&self) -> Scalar {
        self.external_work + self.collision.obstacle_work
    }
}

/// Counters of the computer's work: kept across restores.
#[derive(Debug, Clone, Copy)]
pub struct Effort {
    /// The stepper's counters (steps taken, retried ones included; solves; timings).
    pub solver: StepStats,
    /// Smallest step taken so far, s (infinite before the first).
    pub min_dt: Scalar,
    /// Frames retried because their energy rose.
    pub energy_retries: u64,
    /// Halvings spent on frames that failed or gained energy.
    pub step_halvings: u64,
    /// Largest step taken so far, s (zero before the first).
    pub max_dt: Scalar,
    /// Adaptive steps refused, by reason (`dt = "adaptive"`).
    pub refused: RefusedSteps,
    /// Largest error estimate of an accepted adaptive step, m.
    pub largest_step_error: Scalar,
}

/// Adaptive steps refused by the controller ([`super::step_control`]), by reason.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct RefusedSteps {
    /// The error estimate exceeded its tolerance.
    pub error: u64,
    /// The cloth ended deeper below an obstacle surface than its tolerance.
    pub penetration: u64,
    /// The step failed (solve, finiteness, energy) and was retried smaller.
    pub failed: u64,
}

impl RefusedSteps {
    /// All refusals.
    pub fn total(&self) -> u64 {
        self.error + self.penetration + self.failed
    }
}

impl Default for Effort {
    fn default() -> Effort {
        Effort {
            solver: StepStats::default(),
            min_dt: Scalar::INFINITY,
            energy_retries: 0,
            step_halvings: 0,
            max_dt: 0.0,
            refused: RefusedSteps::default(),
            largest_step_error: 0.0,
        }
    }
}

impl SimState {
    /// The state at the start of a run of `setup` (no steps taken) on `world`.
    pub fn new(
        setup: &Setup,
        world: World,
        adapter: Option<Adapter>,
        pipeline: &Pipeline,
    ) -> SimState {
        let bound = EnergyBound::new(&world, pipeline.stepper(), &setup.model);
        let seams = SeamState::at_start(&world);
        SimState {
            world,
            adapter,
            contacts: Vec::new(),
            warm_start: Vec::new(),
            ledger: Ledger {
                steps_done: 0,
                external_work: 0.0,
                collision: CollisionStats::default(),
                bound,
                excess_max: 0.0,
            },
            effort: Effort::default(),
            seams,
            welds: Vec::new(),
            step_control: StepControl::default(),
        }
    }

    /// Makes `self` a copy of `saved`, keeping its own [`Effort`] and reusing its
    /// buffers.
    pub fn restore(&mut self, saved: &SimState) {
        let effort = self.effort;
        self.clone_from(saved);
        self.effort = effort;
    }
}

impl Clone for SimState {
    fn clone(&self) -> SimState {
        SimState {
            world: self.world.clone(),
            adapter: self.adapter.clone(),
            contacts: self.contacts.clone(),
            warm_start: self.warm_start.clone(),
            ledger: self.ledger,
            effort: self.effort,
            seams: self.seams.clone(),
            welds: self.welds.clone(),
            step_control: self.step_control,
        }
    }

    /// Reuses the position, velocity, contact and warm-start buffers: the frame
    /// retry saves a state every frame.
    fn clone_from(&mut self, source: &SimState) {
        // Destructured so that a new field cannot be forgotten here.
        let SimState {
            world,
            adapter,
            contacts,
            warm_start,
            ledger,
            effort,
            seams,
            welds,
            step_control,
        } = source;
        let World {
            mesh,
            x,
            v,
            time,
            pins,
        } = world;
        self.world.mesh.clone_from(mesh);
        self.world.x.clone_from(x);
        self.world.v.clone_from(v);
        self.world.time = *time;
        self.world.pins.clone_from(pins);
        self.adapter.clone_from(adapter);
        self.contacts.clone_from(contacts);
        self.warm_start.clone_from(warm_start);
        self.ledger = *ledger;
        self.effort = *effort;
        self.seams.clone_from(seams);
        self.welds.clone_from(welds);
        self.step_control = *step_control;
    }
}
