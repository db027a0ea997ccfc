//! The pipeline's remeshing phases: paper A's rollback (redo a step that bent
//! too far on a refined mesh) and the adaptation pass, after a step or at the
//! end of a frame.

use super::Pipeline;
use std::time::Instant;

use crate::adapt::transfer::carry_contacts;
use crate::adapt::{Measured, edge_angles_into};
use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::sim::{Ledger, Setup, SimState};
use crate::spec::AdaptEvery;

/// What a rollback or a refused adaptive step restores: the step's start
/// positions, velocities, time and ledger (so the rejected attempt's work and
/// collision counts leave no trace), and for a refused step the resting
/// contacts and the warm start it began with.
#[derive(Default)]
pub(super) struct StepStart {
    x: Vec<Vector>,
    v: Vec<Vector>,
    time: Scalar,
    ledger: Option<Ledger>,
    contacts: Vec<crate::physics::Contact>,
    warm_start: Vec<Vector>,
}

impl Pipeline {
    /// Saves what a rollback or a refused step restores.
    pub(super) fn remember_step_start(&mut self, state: &SimState) {
        let s = &mut self.step_start;
        s.x.clone_from(&state.world.x);
        s.v.clone_from(&state.world.v);
        s.time = state.world.time;
        s.ledger = Some(state.ledger);
        s.contacts.clone_from(&state.contacts);
        s.warm_start.clone_from(&state.warm_start);
    }

    /// The positions, velocities and time the step started from (saved by
    /// [`Pipeline::remember_step_start`]).
    pub(super) fn step_start_motion(&self) -> (&[Vector], &[Vector], Scalar) {
        let s = &self.step_start;
        (&s.x, &s.v, s.time)
    }

    /// Puts the state back at the step's start, mesh unchanged (a refused
    /// adaptive step): positions, velocities, time, ledger, resting contacts
    /// and warm start. The air power cache is forgotten (it is recomputed from
    /// the restored state, to the same value).
    pub(super) fn restore_step_start(&mut self, state: &mut SimState) {
        let s = &mut self.step_start;
        debug_assert_eq!(s.x.len(), state.world.x.len(), "restoring another mesh");
        state.world.x.clone_from(&s.x);
        state.world.v.clone_from(&s.v);
        state.world.time = s.time;
        if let Some(ledger) = s.ledger {
            state.ledger = ledger;
        }
        state.contacts.clone_from(&s.contacts);
        state.warm_start.clone_from(&s.warm_start);
        self.air_power = None;
        self.angles_fresh = false;
    }

    /// Rollback (paper A): when the step bent an edge past the upper threshold and
    /// rollbacks are left, restores the step's start (positions, velocities, time,
    /// ledger and resting contacts), refines the marked edges and returns true
    /// (redo the step).
    pub(super) fn rollback(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        tries: &mut u32,
    ) -> Result<bool, MeshError> {
        let (Some(ad), Some(config)) = (state.adapter.as_mut(), &setup.settings.adapt) else {
            return Ok(false);
        };
        if *tries >= config.max_rollbacks {
            return Ok(false);
        }
        edge_angles_into(&state.world, &mut self.angles);
        self.angles_fresh = true;
        // Nearly every step bends no edge past the threshold: answered without
        // allocating; the marks are collected only for a rollback.
        if !ad.needs_refinement(config, &state.world, &self.angles) {
            return Ok(false);
        }
        let readings = ad.rollback_marks(config, &state.world, &self.angles);
        let marks: Vec<(u32, crate::math::Scalar)> =
            readings.iter().map(|&(l, r)| (l, r.angle)).collect();
        self.angles_fresh = false;
        let s = &mut self.step_start;
        std::mem::swap(&mut state.world.x, &mut s.x);
        std::mem::swap(&mut state.world.v, &mut s.v);
        state.world.time = s.time;
        debug_assert!(s.ledger.is_some(), "rollback without a saved step start");
        if let Some(ledger) = s.ledger {
            state.ledger = ledger;
        }
        ad.note_rollback(&state.world, &readings, state.ledger.steps_done);
        // The contacts the rejected step started from fit the restored start;
        // they go through the refinement like the vertices (`remesh` below).
        let start_contacts = std::mem::take(&mut self.stepper.contacts);
        let old_vertices = state.world.x.len();
        let had_contacts = !start_contacts.is_empty();
        let steps_done = state.ledger.steps_done;
        let started = Instant::now();
        let carried = if ad.refine(config, &mut state.world, &marks, steps_done)? {
            carry_contacts(&start_contacts, old_vertices, ad.last_origins())
        } else {
            Some(start_contacts).filter(|c| c.len() == old_vertices)
        };
        state.effort.solver.remesh_s += started.elapsed().as_secs_f64();
        self.mesh_changed_with(setup, state, carried, had_contacts);
        *tries += 1;
        Ok(true)
    }

    /// Adapt: the remeshing pass after every `adapt.every` accepted steps. True
    /// when it changed the mesh.
    pub(super) fn adapt(&mut self, setup: &Setup, state: &mut SimState) -> Result<bool, MeshError> {
        match &setup.settings.adapt {
            Some(c) if c.every.after_step(state.ledger.steps_done) => self.remesh(setup, state),
            _ => Ok(false),
        }
    }

    /// Adapt, with `adapt.every = "frame"`: the remeshing pass once the frame's
    /// steps are accepted. True when it changed the mesh.
    pub(super) fn adapt_at_frame_end(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
    ) -> Result<bool, MeshError> {
        match &setup.settings.adapt {
            Some(c) if c.every == AdaptEvery::Frame => self.remesh(setup, state),
            _ => Ok(false),
        }
    }

    /// The remeshing pass on the state as it is (reusing the edge angles the
    /// rollback check measured on it, when it did). True when it changed the mesh.
    pub(super) fn remesh(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
    ) -> Result<bool, MeshError> {
        let (Some(ad), Some(config)) = (state.adapter.as_mut(), &setup.settings.adapt) else {
            return Ok(false);
        };
        let step = state.ledger.steps_done;
        // The criterion's obstacle planes are part of the pass's cost.
        let started = Instant::now();
        self.obstacle_planes.clear();
        if config.refine_obstacle.is_some() {
            let w = &state.world;
            let planes = &mut self.obstacle_planes;
            setup.obstacles.nearest_planes(&w.x, w.time, planes);
        }
        let known = Measured {
            angles: self.angles_fresh.then_some(self.angles.as_slice()),
            obstacle_planes: &self.obstacle_planes,
        };
        let old_vertices = state.world.x.len();
        let changed = ad.remesh_with(config, &mut state.world, step, known)?;
        self.angles_fresh = false;
        if !changed {
            state.effort.solver.remesh_s += started.elapsed().as_secs_f64();
        }
        if changed {
            // The contacts the last step ended in, carried onto the new mesh:
            // the next implicit step filters them as it would have (see
            // `crate::adapt::transfer::carry_contacts`).
            let carried = carry_contacts(&state.contacts, old_vertices, ad.last_origins());
            state.effort.solver.remesh_s += started.elapsed().as_secs_f64();
            let had_contacts = !state.contacts.is_empty();
            self.mesh_changed_with(setup, state, carried, had_contacts);
        }
        Ok(changed)
    }

    /// [`Pipeline::mesh_changed`], then the resting contacts carried onto the
    /// new mesh. Contacts that could not be carried (`None`) while there were
    /// some (`had_contacts`) are a broken invariant: one contact per old
    /// vertex, origins in range. Release builds then go on without them, as
    /// every remesh did before contacts were carried.
    fn mesh_changed_with(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        carried: Option<Vec<crate::physics::Contact>>,
        had_contacts: bool,
    ) {
        debug_assert!(
            carried.is_some() || !had_contacts,
            "resting contacts that do not fit the mesh they were carried from"
        );
        self.mesh_changed(setup, state);
        if let Some(contacts) = carried {
            state.contacts = contacts;
        }
    }
}
