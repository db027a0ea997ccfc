//! The machine-readable run summary (`--summary FILE.json`) and its one-paragraph
//! human form.

use std::path::PathBuf;

use serde::Serialize;

use crate::math::Scalar;
use crate::physics::StepStats;

/// Minimum, mean and maximum of a quantity sampled once per recorded frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Range {
    /// Smallest sample.
    pub min: Scalar,
    /// Mean of the samples.
    pub mean: Scalar,
    /// Largest sample.
    pub max: Scalar,
    #[serde(skip)]
    count: u64,
}

impl Range {
    /// No samples yet.
    pub fn empty() -> Range {
        Range {
            min: Scalar::INFINITY,
            mean: 0.0,
            max: Scalar::NEG_INFINITY,
            count: 0,
        }
    }

    /// Adds one sample.
    pub fn add(&mut self, x: Scalar) {
        self.count += 1;
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        self.mean += (x - self.mean) / self.count as Scalar;
    }
}

/// Total energy (kinetic + gravitational + elastic) at the start, the end, and its maximum, J.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergySummary {
    /// At t = 0.
    pub initial: Scalar,
    /// At the last recorded frame.
    pub r#final: Scalar,
    /// Largest over the recorded frames.
    pub max: Scalar,
    /// Work done on the cloth from outside over the run (wind and moving air, moving
    /// pins, moving obstacles), J. Gravity is in the potential energy; drag in still
    /// air, damping and friction only remove energy.
    pub external_work: Scalar,
    /// Largest excess of the total energy over its bound, `E(t) - E(0) - W(t)`, over
    /// every frame, J: zero or negative when the energy never rose above its initial
    /// value plus the external work.
    pub excess_max: Scalar,
}

/// What the adaptive step did (`dt = "adaptive"`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AdaptiveDtSummary {
    /// The largest step taken, s (the smallest is [`Summary::dt`]).
    pub max_dt: Scalar,
    /// Steps refused, by reason.
    pub refused: crate::sim::RefusedSteps,
    /// The largest error estimate of an accepted step, m.
    pub largest_error: Scalar,
}

/// Where the recording went.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordingSummary {
    /// The `.rrd` file.
    pub path: PathBuf,
    /// Its size in bytes.
    pub bytes: u64,
    /// Frames in the file (fewer than `frames` with `--record-every`).
    pub frames: u64,
}

/// Everything `--summary` writes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Recorded frames, including the initial one.
    pub frames: u64,
    /// Time steps taken (including retried ones).
    pub steps: u64,
    /// Simulated time reached, s.
    pub sim_time: Scalar,
    /// Wall time of the whole run, s.
    pub wall_time_s: Scalar,
    /// Wall time spent stepping, s.
    pub simulation_wall_s: Scalar,
    /// Wall time spent recording (and exporting OBJ), s.
    pub recording_wall_s: Scalar,
    /// The smallest time step taken, s (with `dt = "auto"` and adaptivity the
    /// step follows the finest triangles).
    pub dt: Scalar,
    /// The largest time step taken, s.
    pub dt_max: Scalar,
    /// Steps accepted: those the simulated time is made of (`steps` counts
    /// the retried and refused ones too).
    pub steps_accepted: u64,
    /// The mean accepted step, `sim_time / steps_accepted`, s (0 before the
    /// first step).
    pub dt_mean: Scalar,
    /// The adaptive step's figures, with `dt = "adaptive"`.
    pub adaptive_dt: Option<AdaptiveDtSummary>,
    /// Steps times mean vertices per second of stepping wall time.
    pub vertex_steps_per_s: Scalar,
    /// Vertex counts over the recorded frames.
    pub vertices: Range,
    /// Triangle counts over the recorded frames.
    pub triangles: Range,
    /// Total mass at the start, kg.
    pub mass_initial: Scalar,
    /// Total mass at the end, kg.
    pub mass_final: Scalar,
    /// Total energy.
    pub energy: EnergySummary,
    /// Frame attempts retried with halved steps: after a non-finite state, an energy
    /// explosion, or an energy gain above the tolerance (the key keeps its first name).
    pub nan_recoveries: u64,
    /// Of those retries, how many were for an energy gain above the tolerance
    /// (`run::ENERGY_GAIN_TOLERANCE`) rather than a NaN or an explosion.
    pub energy_retries: u64,
    /// CG iterations and capped solves of the implicit integrator.
    pub solver: StepStats,
    /// 1-4 splits made by adaptive meshing (including forced ones).
    pub splits: u64,
    /// Merges made by adaptive meshing.
    pub merges: u64,
    /// Steps redone by rollback.
    pub rollbacks: u64,
    /// Highest triangle level reached (0: never refined).
    pub max_level: u8,
    /// All adaptivity counters, when the scene adapts.
    pub adapt: Option<crate::adapt::AdaptStats>,
    /// Largest depth of a cloth vertex below an obstacle surface, measured after the
    /// collision response of every step, m (0 without obstacles).
    pub max_penetration: Scalar,
    /// Mean number of vertex-obstacle contacts per step.
    pub contacts: Scalar,
    /// Mean number of cloth triangle pairs given to the exact self-collision tests per step.
    pub self_pairs_tested: Scalar,
    /// Share of the triangles whose patch Volino culling spared its self-test (0..1).
    pub self_culled_fraction: Scalar,
    /// Wall time in the obstacle collision passes, s (part of `simulation_wall_s`).
    pub collision_wall_s: Scalar,
    /// Wall time in self-collision, s (part of `simulation_wall_s`).
    pub self_collision_wall_s: Scalar,
    /// Cusick drape measurements at the end, when the scene is a disk specimen on a
    /// vertical support cylinder (see `collide::cusick`).
    pub cusick: Option<crate::collide::cusick::CusickSummary>,
    /// Cantilever bending test measurements at the end, when the scene is a
    /// rectangle held by fixed pins over one end (see `cantilever`).
    pub cantilever: Option<crate::cantilever::CantileverSummary>,
    /// Box pin regions whose held vertices are not the cloth inside the box
    /// (a mesh without lines on the box's edges: a disk, an OBJ); absent
    /// from the JSON when every pin holds what the scene names.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pin_mismatches: Vec<crate::pins::PinMismatch>,
    /// A garment's seams at the end: welded (and when) or still open (and how
    /// wide); absent from the JSON for a cloth without seams.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub seams: Vec<SeamSummary>,
    /// Whether the run ended at rest (`simulation.rest`), and when; absent
    /// from the JSON for a scene without a rest criterion.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rest: Option<RestSummary>,
    /// True when Ctrl-C ended the run early.
    pub interrupted: bool,
    /// The recording, if one was written.
    pub recording: Option<RecordingSummary>,
}

fn seams_sentence(seams: &[SeamSummary]) -> String {
    if seams.is_empty() {
        return String::new();
    }
    let parts: Vec<String> = seams.iter().map(SeamSummary::describe).collect();
    format!(" Seams: {}.", parts.join(", "))
}

/// The rest criterion at the end of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RestSummary {
    /// True when the run ended at rest.
    pub at_rest: bool,
    /// When it came to rest, s (`None`: it did not).
    pub time: Option<Scalar>,
    /// The largest vertex speed at the end, m/s.
    pub speed: Scalar,
    /// The rest speed, m/s (`simulation.rest.speed`).
    pub threshold: Scalar,
    /// The rest window, s (`simulation.rest.window`).
    pub window: Scalar,
}

impl RestSummary {
    /// The rest criterion in words.
    fn sentence(&self) -> String {
        match self.time {
            Some(t) => format!(
                " At rest at t = {t:.3} s (every vertex under {} m/s for {} s).",
                self.threshold, self.window
            ),
            None => format!(
                " Not at rest: the fastest vertex moves at {:.4} m/s at the end (rest: under {} \
                 m/s for {} s with every seam welded).",
                self.speed, self.threshold, self.window
            ),
        }
    }
}

/// One seam of a garment at the end of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeamSummary {
    /// The seam's name.
    pub name: String,
    /// When it was welded, s (`None`: still open).
    pub welded_at: Option<Scalar>,
    /// Its largest pair gap at the end, m (0 once welded).
    pub gap: Scalar,
}

impl SeamSummary {
    /// The seams of `mesh` in the states `states` (one per seam), at
    /// positions `x`.
    pub fn of(
        mesh: &crate::mesh::Mesh,
        states: &[crate::sim::SeamState],
        x: &[crate::math::Vector],
    ) -> Vec<SeamSummary> {
        let Some(panels) = mesh.panels() else {
            return Vec::new();
        };
        panels
            .seams
            .iter()
            .zip(states)
            .map(|(s, state)| SeamSummary {
                name: s.name.clone(),
                welded_at: state.welded_at(),
                gap: s.gap(x),
            })
            .collect()
    }

    fn describe(&self) -> String {
        match self.welded_at {
            Some(t) => format!("`{}` welded at {t:.3} s", self.name),
            None => format!("`{}` open, gap {:.1} mm", self.name, 1e3 * self.gap),
        }
    }
}

impl Summary {
    /// True when the steps taken differ in size (by more than rounding): by
    /// level, automatic step, retried frames or the adaptive step.
    pub fn step_varied(&self) -> bool {
        self.dt_max - self.dt > 1e-9 * self.dt_max
    }

    /// The steps taken, in words: `N steps of DT s` for a steady step; for a
    /// varying one the range and the mean step. The count is of the accepted
    /// steps, so that it times the step (or the mean) is the simulated time;
    /// steps retried or refused are counted besides, and the adaptive step's
    /// refusals given.
    fn steps_in_words(&self) -> String {
        let redone = self.steps.saturating_sub(self.steps_accepted);
        if !self.step_varied() {
            return match redone {
                0 => format!("{} steps of {:.3e} s", self.steps, self.dt),
                n => format!(
                    "{} steps of {:.3e} s ({n} more retried or refused)",
                    self.steps_accepted, self.dt
                ),
            };
        }
        let besides = match redone {
            0 => String::new(),
            n => format!("; {n} more retried or refused"),
        };
        let adaptive = match &self.adaptive_dt {
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
            self.steps_accepted, self.dt, self.dt_max, self.dt_mean
        )
    }

    /// The one-paragraph summary printed at the end of a run.
    pub fn paragraph(&self) -> String {
        let rec = match &self.recording {
            Some(r) => format!(
                "Recording: {} ({:.1} MB).",
                r.path.display(),
                r.bytes as f64 / 1e6
            ),
            None => "No recording.".to_string(),
        };
        let end = if self.interrupted {
            " Interrupted by Ctrl-C."
        } else {
            ""
        };
        format!(
            "{}: {} frames, {} to t = {:.3} s in {:.2} s wall ({:.2} s stepping, {:.2} s recording); \
             {:.0} vertices, {:.0} triangles; {:.3e} vertex-steps/s. Mass {:.6} -> {:.6} kg; \
             energy {:.4e} -> {:.4e} J (max {:.4e}; external work {:.3e} J; largest excess over initial + work {:.3e} J); \
             {} recoveries (frame attempts retried with halved steps, {} for energy gain); {}.{}{}{}{} {}",
            self.scene,
            self.frames,
            self.steps_in_words(),
            self.sim_time,
            self.wall_time_s,
            self.simulation_wall_s,
            self.recording_wall_s,
            self.vertices.mean,
            self.triangles.mean,
            self.vertex_steps_per_s,
            self.mass_initial,
            self.mass_final,
            self.energy.initial,
            self.energy.r#final,
            self.energy.max,
            self.energy.external_work,
            self.energy.excess_max,
            self.nan_recoveries,
            self.energy_retries,
            self.solver.describe(),
            match &self.adapt {
                Some(a) if a.awaiting_welds => {
                    " Adaptive: not started, as remeshing waits until every seam is welded.".into()
                }
                Some(a) => format!(
                    " Adaptive: {} splits ({} forced), {} merges ({} bounced), {} rollbacks, max level {}{}.",
                    a.splits,
                    a.closure_splits,
                    a.merges,
                    a.bounces,
                    a.rollbacks,
                    self.max_level,
                    match a.started_at > 0.0 {
                        true => format!(
                            "; remeshing from t = {:.3} s, once every seam was welded",
                            a.started_at
                        ),
                        false => String::new(),
                    }
                ),
                None => String::new(),
            },
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
            },
            self.pin_mismatches
                .iter()
                .map(|m| format!(" Pin region differs from the scene: {}.", m.describe()))
                .collect::<String>()
                + &seams_sentence(&self.seams)
                + &self
                    .rest
                    .as_ref()
                    .map_or(String::new(), RestSummary::sentence),
            end,
            rec
        )
    }
}
