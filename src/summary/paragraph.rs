//! The one-paragraph human form of a [`Summary`], printed at the end of a run:
//! one sentence per part, the parts with nothing to report left out.

use super::{
    Adaptivity, Measurements, RecordingSummary, RestSummary, SceneChecks, SeamSummary, Summary,
};

impl Summary {
    /// The one-paragraph summary printed at the end of a run.
    pub fn paragraph(&self) -> String {
        let end = if self.interrupted {
            " Interrupted by Ctrl-C."
        } else {
            ""
        };
        format!(
            "{}{}{}{}{} {}",
            self.run_sentence(),
            self.adaptivity.sentence(),
            self.measurements.sentence(),
            self.checks.sentences(),
            end,
            recording_sentence(self.recording.as_ref())
        )
    }

    /// The run's extent, wall times, mesh size, conservation and effort: the
    /// paragraph's first sentences.
    fn run_sentence(&self) -> String {
        let (run, wall, mass) = (&self.extent, &self.wall, &self.conservation);
        let energy = &mass.energy;
        format!(
            "{}: {} frames, {} to t = {:.3} s in {:.2} s wall ({:.2} s stepping, {:.2} s recording); \
             {:.0} vertices, {:.0} triangles; {:.3e} vertex-steps/s. Mass {:.6} -> {:.6} kg; \
             energy {:.4e} -> {:.4e} J (max {:.4e}; external work {:.3e} J; largest excess over initial + work {:.3e} J); \
             {} recoveries (frame attempts retried with halved steps, {} for energy gain); {}.",
            run.scene,
            run.frames,
            self.steps_in_words(),
            run.sim_time,
            wall.wall_time_s,
            wall.simulation_wall_s,
            wall.recording_wall_s,
            self.mesh.vertices.mean,
            self.mesh.triangles.mean,
            self.stepping.vertex_steps_per_s,
            mass.mass_initial,
            mass.mass_final,
            energy.initial,
            energy.r#final,
            energy.max,
            energy.external_work,
            energy.excess_max,
            self.effort.nan_recoveries,
            self.effort.energy_retries,
            self.effort.solver.describe(),
        )
    }

    /// The steps taken, in words: `N steps of DT s` for a steady step; for a
    /// varying one the range and the mean step. The count is of the accepted
    /// steps, so that it times the step (or the mean) is the simulated time;
    /// steps retried or refused are counted besides, and the adaptive step's
    /// refusals given.
    fn steps_in_words(&self) -> String {
        let (steps, s) = (self.extent.steps, &self.stepping);
        let redone = steps.saturating_sub(s.steps_accepted);
        if !self.step_varied() {
            return match redone {
                0 => format!("{} steps of {:.3e} s", steps, s.dt),
                n => format!(
                    "{} steps of {:.3e} s ({n} more retried or refused)",
                    s.steps_accepted, s.dt
                ),
            };
        }
        let besides = match redone {
            0 => String::new(),
            n => format!("; {n} more retried or refused"),
        };
        let adaptive = match &s.adaptive_dt {
            None => String::new(),
            Some(a) => format!(
                "; adaptive: {} refused, {} for the error, {} for penetration, {} failed; largest accepted error estimate {:.3e} m",
                a.refused.total(),
                a.refused.error,
                a.refused.penetration,
                a.refused.failed,
                a.largest_error
            ),
        };
        format!(
            "{} steps of {:.3e} to {:.3e} s (mean {:.3e} s{besides}{adaptive})",
            s.steps_accepted, s.dt, s.dt_max, s.dt_mean
        )
    }
}

impl Adaptivity {
    /// What adaptive meshing did, in words (nothing when the scene does not adapt).
    fn sentence(&self) -> String {
        match &self.adapt {
            Some(a) if a.awaiting_welds => {
                " Adaptive: not started, as remeshing waits until every seam is welded.".into()
            }
            Some(a) => format!(
                " Adaptive: {} splits ({} forced), {} merges ({} bounced), {} rollbacks, max level {}{}{}.",
                a.splits,
                a.closure_splits,
                a.merges,
                a.bounces,
                a.rollbacks,
                self.max_level,
                match a.deferred_passes {
                    0 => String::new(),
                    d => format!(
                        "; {} of {} passes applied, {d} deferred (min_change)",
                        a.passes - d,
                        a.passes
                    ),
                },
                match a.started_at > 0.0 {
                    true => format!(
                        "; remeshing from t = {:.3} s, once every seam was welded",
                        a.started_at
                    ),
                    false => String::new(),
                }
            ),
            None => String::new(),
        }
    }
}

impl Measurements {
    /// The cantilever measurements in words (nothing for other scenes; the
    /// Cusick figures are in the JSON only).
    fn sentence(&self) -> String {
        match &self.cantilever {
            Some(c) => format!(
                " Cantilever: overhang {:.4} m, chord angle {:.2} deg (elastica for the material: {:.2} deg), bending length {:.4} m (material {:.4} m; Peirce's formula {:.4} m).",
                c.overhang,
                c.chord_angle_deg,
                c.elastica_chord_angle_deg,
                c.bending_length,
                c.material_bending_length,
                c.bending_length_peirce
            ),
            None => String::new(),
        }
    }
}

impl SceneChecks {
    /// One sentence per pin region that differs from the scene, the seams and
    /// the rest criterion (each left out when there is nothing to report).
    fn sentences(&self) -> String {
        self.pin_mismatches
            .iter()
            .map(|m| format!(" Pin region differs from the scene: {}.", m.describe()))
            .collect::<String>()
            + &seams_sentence(&self.seams)
            + &self
                .rest
                .as_ref()
                .map_or(String::new(), RestSummary::sentence)
    }
}

/// The seams at the end in words (nothing without seams).
fn seams_sentence(seams: &[SeamSummary]) -> String {
    if seams.is_empty() {
        return String::new();
    }
    let parts: Vec<String> = seams.iter().map(SeamSummary::describe).collect();
    format!(" Seams: {}.", parts.join(", "))
}

/// Where the recording went, in words.
fn recording_sentence(recording: Option<&RecordingSummary>) -> String {
    match recording {
        Some(r) => format!(
            "Recording: {} ({:.1} MB).",
            r.path.display(),
            r.bytes as f64 / 1e6
        ),
        None => "No recording.".to_string(),
    }
}
