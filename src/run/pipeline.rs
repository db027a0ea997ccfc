//! The per-step machinery of a run: the phases of a step (integrate, collide,
//! rollback, adapt), frame retries with halved steps, and the energy bound.

use super::{
    ENERGY_GAIN_TOLERANCE, EXPLOSION_FACTOR, MAX_ENERGY_HALVINGS, MAX_STEP_HALVINGS, RunError,
    StepFailure,
};
use crate::adapt::{Adapter, edge_angles};
use crate::collide::{Collider, CollisionStats, StepCloth};
use crate::math::{Scalar, Vector, deterministic_sum};
use crate::physics::Stepper;
use crate::world::World;

/// The per-run machinery that advances the world: the stepper (forces and
/// integration), the adapter (remeshing), and the global step counter.
pub(super) struct Pipeline {
    pub(super) stepper: Stepper,
    pub(super) adapter: Option<Adapter>,
    /// Steps completed (not counting retried ones).
    pub(super) steps_done: u64,
    /// Obstacle and self-collision passes (`None`: the scene has neither).
    pub(super) collider: Option<Collider>,
    /// What the collision passes did.
    pub(super) collision: CollisionStats,
    /// The user's fixed step, or `None` for `dt = "auto"`.
    pub(super) fixed_dt: Option<Scalar>,
    /// The automatic step for the current mesh (recomputed after remeshing,
    /// since refinement lowers the explicit stability limit).
    pub(super) auto_dt: Option<Scalar>,
    /// Smallest step taken so far.
    pub(super) min_dt: Scalar,
    /// Work done on the cloth by wind, moving air and moving pins so far, J
    /// (moving obstacles' is in `collision`).
    pub(super) external_work: Scalar,
    /// Power of the air at the end of the last step, W (`None`: not known).
    pub(super) air_power: Option<Scalar>,
    /// The energy bound the explosion check holds the cloth to.
    pub(super) bound: EnergyBound,
    /// Why the last rejected step failed.
    pub(super) failure: StepFailure,
    /// Largest `E(t) - E(0) - W(t)` at the end of a frame so far, J.
    pub(super) excess_max: Scalar,
    /// Frames retried because their energy rose ([`ENERGY_GAIN_TOLERANCE`]).
    pub(super) energy_retries: u64,
}

/// The energy the cloth may have: its initial total plus the external work, and the
/// scale against which an excess counts as an explosion.
#[derive(Debug, Clone, Copy)]
pub(super) struct EnergyBound {
    /// Total energy at the start, J.
    pub(super) initial: Scalar,
    /// `|E0| + KE0 + m |g| D` (D: the cloth's diagonal), J: the energies the run
    /// naturally trades (a fall through the cloth's own size).
    pub(super) scale: Scalar,
}

impl EnergyBound {
    pub(super) fn new(world: &World, stepper: &Stepper) -> EnergyBound {
        let e = stepper.energy(world);
        let mass = stepper.elements.total_mass();
        let g = stepper
            .model
            .external
            .gravity
            .unwrap_or(Vector::ZERO)
            .length();
        let (lo, hi) = world
            .x
            .iter()
            .fold((Vector::INFINITY, Vector::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let diagonal = (hi - lo).length();
        EnergyBound {
            initial: e.total(),
            scale: e.total().abs() + e.kinetic + mass * g * diagonal.max(0.0),
        }
    }
}

impl Pipeline {
    /// Advances one frame; on a non-finite state or an energy explosion, restores
    /// the frame's start (mesh included) and retries with the step halved (up to
    /// [`MAX_STEP_HALVINGS`] times). A frame whose energy rose above its bound by
    /// more than [`ENERGY_GAIN_TOLERANCE`] energy scales is retried the same way, up
    /// to [`MAX_ENERGY_HALVINGS`] times and only while halving helps (the gain at
    /// least halves), then accepted. Returns the number of retries, or the last
    /// step tried when all failed.
    pub(super) fn advance_frame(
        &mut self,
        world: &mut World,
        frame_interval: Scalar,
    ) -> Result<u64, RunError> {
        let start = world.clone();
        let adapter_start = self.adapter.clone();
        let steps_start = self.steps_done;
        let (work_start, collision_start) = (self.external_work, self.collision);
        let t0 = world.time;
        // E - W at the frame start: without numerical error it can only fall.
        let balance_start = self.stepper.energy(world).total() - self.work();
        let mut last_gain = Scalar::INFINITY;
        for halving in 0..=MAX_STEP_HALVINGS {
            let shrink = (1u64 << halving) as Scalar;
            let mut healthy = true;
            let mut done = 0.0;
            // Steps of the current mesh's size, the last ones evened out so the
            // frame ends exactly on its time.
            while done < frame_interval * (1.0 - 1e-12) {
                let remaining = frame_interval - done;
                let target = self.step_size(world) / shrink;
                let h = remaining / (remaining / target * (1.0 - 1e-12)).ceil().max(1.0);
                if !self.step(world, h)? {
                    healthy = false;
                    break;
                }
                self.min_dt = self.min_dt.min(h);
                done += h;
            }
            world.time = t0 + frame_interval;
            if healthy {
                let balance = self.stepper.energy(world).total() - self.work();
                let gain = balance - balance_start;
                let retry = gain > ENERGY_GAIN_TOLERANCE * self.bound.scale
                    && halving < MAX_ENERGY_HALVINGS
                    && gain < 0.75 * last_gain;
                if !retry {
                    self.excess_max = self.excess_max.max(balance - self.bound.initial);
                    return Ok(halving as u64);
                }
                last_gain = gain;
                self.energy_retries += 1;
            }
            *world = start.clone();
            self.adapter = adapter_start.clone();
            self.steps_done = steps_start;
            (self.external_work, self.collision) = (work_start, collision_start);
            self.mesh_changed(world);
        }
        let last_dt = self.step_size(world) / (1u64 << MAX_STEP_HALVINGS) as Scalar;
        Err(RunError::StepFailed {
            last_dt,
            failure: self.failure,
            step: self.steps_done + 1,
        })
    }

    /// The step for the current mesh: the fixed one, or the automatic estimate.
    pub(super) fn step_size(&mut self, world: &World) -> Scalar {
        if let Some(dt) = self.fixed_dt {
            return dt;
        }
        *self
            .auto_dt
            .get_or_insert_with(|| self.stepper.auto_dt(world))
    }

    /// One step, in phases: integrate (forces and integrator), health check,
    /// rollback (paper A: redo the step on a refined mesh when it bent past the
    /// upper threshold), adapt. Returns false when the state became non-finite.
    fn step(&mut self, world: &mut World, h: Scalar) -> Result<bool, RunError> {
        let rollback = self.adapter.as_ref().is_some_and(|a| a.config.rollback);
        let mut tries = 0;
        loop {
            let before = rollback.then(|| (world.x.clone(), world.v.clone(), world.time));
            if !self.integrate(world, h) {
                return Ok(false);
            }
            if let (Some(ad), Some((x, v, t))) = (self.adapter.as_mut(), before)
                && tries < ad.config.max_rollbacks
            {
                let marks = ad.refinement_marks(world, &edge_angles(world));
                if !marks.is_empty() {
                    (world.x, world.v, world.time) = (x, v, t);
                    ad.note_rollback(world, self.steps_done);
                    ad.refine(world, &marks, self.steps_done)?;
                    self.mesh_changed(world);
                    tries += 1;
                    continue;
                }
            }
            break;
        }
        self.steps_done += 1;
        if let Some(ad) = self.adapter.as_mut()
            && self.steps_done.is_multiple_of(ad.config.every)
            && ad.pass(world, self.steps_done)?
        {
            self.mesh_changed(world);
        }
        Ok(true)
    }

    /// The integrate and collide phases of a step; false when the state became
    /// non-finite. The contacts the last step ended in go to the implicit solve
    /// (filtered there, see [`crate::physics::implicit`]).
    fn integrate(&mut self, world: &mut World, h: Scalar) -> bool {
        let air0 = match self.air_power.take() {
            Some(p) => p,
            None => self.stepper.air_power(world),
        };
        let pinned = self.stepper.pinned_start(world);
        if let Some(c) = self.collider.as_mut() {
            c.begin_step(world);
            // Resting contacts from the last step: the vertices are on the surface now.
            self.stepper.contacts.clear();
            self.stepper.contacts.extend_from_slice(c.contacts());
        }
        if let Err(why) = self.stepper.step(world, h) {
            self.failure = StepFailure::Solver(why);
            return false;
        }
        if !is_finite(&world.x) {
            self.failure = StepFailure::NonFinite;
            return false;
        }
        // Before the collision passes too: an exploding state (finite but huge) must
        // not reach the geometry code.
        if self.collider.is_some() && !self.explosion_check(world) {
            return false;
        }
        if let Some(c) = self.collider.as_mut() {
            let cloth = StepCloth {
                pushed: &self.stepper.contact_push,
                mass: &self.stepper.elements.mass,
            };
            c.end_step(world, h, cloth, &mut self.collision);
        }
        let air1 = self.stepper.air_power(world);
        self.air_power = Some(air1);
        self.external_work += 0.5 * h * (air0 + air1) + self.stepper.pin_work(&pinned, world, h);
        self.explosion_check(world)
    }

    /// Work done on the cloth from outside so far, J.
    pub(super) fn work(&self) -> Scalar {
        self.external_work + self.collision.obstacle_work
    }

    /// False (and the failure noted) when the kinetic plus gravitational energy
    /// exceeds the bound by [`EXPLOSION_FACTOR`] scales. Elastic energy is left out
    /// (it is never negative, so the test stays sound) because it costs a pass over
    /// every element, where this costs one over the vertices.
    fn explosion_check(&mut self, world: &World) -> bool {
        let mass = &self.stepper.elements.mass;
        let g = self.stepper.model.external.gravity.unwrap_or(Vector::ZERO);
        let energy = deterministic_sum(world.x.len(), |i| {
            mass[i] * (0.5 * world.v[i].length_squared() - g.dot(world.x[i]))
        });
        let work = self.work();
        let bound = self.bound.initial + work + EXPLOSION_FACTOR * (self.bound.scale + work.abs());
        if energy > bound || !energy.is_finite() {
            self.failure = StepFailure::Explosion { energy, bound };
            return false;
        }
        true
    }

    /// After the world's mesh changed (remeshing, or a restored frame start): rebuild
    /// the force elements, forget the step size and the (now stale) contacts.
    fn mesh_changed(&mut self, world: &World) {
        self.stepper.rebuild(world);
        self.auto_dt = None;
        self.air_power = None;
        if let Some(c) = self.collider.as_mut() {
            c.forget_contacts();
        }
    }
}

/// True when every coordinate is finite (a NaN or infinity anywhere poisons the sum).
fn is_finite(x: &[Vector]) -> bool {
    deterministic_sum(x.len(), |i| x[i].x + x[i].y + x[i].z).is_finite()
}
