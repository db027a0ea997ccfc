//! The pipeline's sewing phase: an open seam whose every pair has closed to
//! within its weld gap becomes one surface ([`crate::world::World::weld_seam`]);
//! and an attachment whose release time has passed lets its sides go.

use super::Pipeline;
use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::sim::{SeamState, Setup, SimState};

/// A seam welded during the run, for the recording's events.
#[derive(Debug, Clone, PartialEq)]
pub struct WeldEvent {
    /// The seam's name.
    pub seam: String,
    /// Where: the centre of the seam's welded vertices, m.
    pub position: Vector,
    /// The largest gap between a pair just before the weld, m.
    pub gap: Scalar,
    /// The step after which it happened.
    pub step: u64,
}

impl Pipeline {
    /// Sew: welds every open seam that has closed. True when the mesh changed
    /// (the force elements are then rebuilt).
    pub(super) fn weld_closed_seams(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
    ) -> Result<bool, MeshError> {
        let mut welded = false;
        loop {
            let seams = state.world.mesh.seams();
            let x = &state.world.x;
            let weld_gap = setup.model.material.sewing.weld_gap;
            let closed = seams.iter().enumerate().find_map(|(s, seam)| {
                let gap = seam.gap(x);
                (seam.is_open() && gap < weld_gap).then_some((s, gap))
            });
            let Some((s, gap)) = closed else {
                return Ok(welded);
            };
            let seam = &seams[s];
            let centre = seam
                .pairs
                .iter()
                .map(|&[a, b]| (x[a as usize] + x[b as usize]) * 0.5)
                .sum::<Vector>()
                / seam.pairs.len() as Scalar;
            let name = seam.name.clone();
            let mass = self.stepper.elements.mass.clone();
            let before = self.stepper.energy(&setup.model, &state.world).total();
            state.world.weld_seam(s, &mass)?;
            mark_welded(state);
            state.welds.push(WeldEvent {
                seam: name,
                position: centre,
                gap,
                step: state.ledger.steps_done,
            });
            self.mesh_changed(setup, state);
            // Merging moves each pair to its centre of mass (storing a little
            // elastic energy), loses the pair's relative motion and the sewing
            // springs' energy: that change is the sewing's work on the cloth.
            let after = self.stepper.energy(&setup.model, &state.world).total();
            state.ledger.external_work += after - before;
            welded = true;
        }
    }
}

impl Pipeline {
    /// Release: once the time passes an attachment's release time (the step
    /// that began at `from` ended after it), the elements are rebuilt without
    /// it. The elastic energy it held goes with it, booked as external work,
    /// as a weld's change is. True when it rebuilt.
    pub(super) fn release_attachments(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        from: Scalar,
    ) -> bool {
        if !setup.model.releases_between(from, state.world.time) {
            return false;
        }
        let before = self.stepper.energy(&setup.model, &state.world).total();
        self.mesh_changed(setup, state);
        let after = self.stepper.energy(&setup.model, &state.world).total();
        state.ledger.external_work += after - before;
        true
    }
}

/// Marks welded, at the present time, every seam the state still has open
/// whose pairs the mesh has joined (the seam just welded, and any other whose
/// every pair that weld joined).
fn mark_welded(state: &mut SimState) {
    let time = state.world.time;
    for (seam, s) in state.world.mesh.seams().iter().zip(&mut state.seams) {
        if s.is_open() && !seam.is_open() {
            *s = SeamState::Welded { time };
        }
    }
}
