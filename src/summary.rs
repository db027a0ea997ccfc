//! The machine-readable run summary (`--summary FILE.json`) and its one-paragraph
//! human form.

use std::path::PathBuf;

use serde::Serialize;

use crate::math::Scalar;
use crate::physics::StepStats;

mod paragraph;

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
    /// The largest step taken, s (the smallest is [`Stepping::dt`]).
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

/// Everything `--summary` writes, in parts that each say one thing. Every part
/// is flattened into the JSON, whose keys keep the order of the fields here.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// What ran and how far.
    #[serde(flatten)]
    pub extent: Extent,
    /// Where the wall time went.
    #[serde(flatten)]
    pub wall: WallTimes,
    /// The sizes of the steps and their rate.
    #[serde(flatten)]
    pub stepping: Stepping,
    /// The mesh's size over the recorded frames.
    #[serde(flatten)]
    pub mesh: MeshSize,
    /// Mass and energy.
    #[serde(flatten)]
    pub conservation: Conservation,
    /// Frame attempts retried and the implicit solver's work.
    #[serde(flatten)]
    pub effort: StepEffort,
    /// What adaptive meshing did.
    #[serde(flatten)]
    pub adaptivity: Adaptivity,
    /// Contacts with obstacles and self-collision, and their cost.
    #[serde(flatten)]
    pub collision: Collisions,
    /// The standard tests' measurements at the end.
    #[serde(flatten)]
    pub measurements: Measurements,
    /// What the scene asks of the cloth against what the run did.
    #[serde(flatten)]
    pub checks: SceneChecks,
    /// True when Ctrl-C ended the run early.
    pub interrupted: bool,
    /// The recording, if one was written.
    pub recording: Option<RecordingSummary>,
}

/// What ran and how far it went.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Extent {
    /// Scene name.
    pub scene: String,
    /// Recorded frames, including the initial one.
    pub frames: u64,
    /// Time steps taken (including retried ones).
    pub steps: u64,
    /// Simulated time reached, s.
    pub sim_time: Scalar,
}

/// Where the wall time went, s.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WallTimes {
    /// Wall time of the whole run, s.
    pub wall_time_s: Scalar,
    /// Wall time spent stepping, s.
    pub simulation_wall_s: Scalar,
    /// Wall time spent recording (and exporting OBJ), s.
    pub recording_wall_s: Scalar,
}

/// The steps taken: their sizes, their count and their rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stepping {
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
}

/// The mesh's size over the recorded frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeshSize {
    /// Vertex counts over the recorded frames.
    pub vertices: Range,
    /// Triangle counts over the recorded frames.
    pub triangles: Range,
}

/// Mass and energy at the start and the end.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Conservation {
    /// Total mass at the start, kg.
    pub mass_initial: Scalar,
    /// Total mass at the end, kg.
    pub mass_final: Scalar,
    /// Total energy.
    pub energy: EnergySummary,
}

/// What stepping took beyond one try per step: retried frame attempts and the
/// implicit solver's work.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepEffort {
    /// Frame attempts retried with halved steps: after a non-finite state, an energy
    /// explosion, or an energy gain above the tolerance (the key keeps its first name).
    pub nan_recoveries: u64,
    /// Of those retries, how many were for an energy gain above the tolerance
    /// (`run::ENERGY_GAIN_TOLERANCE`) rather than a NaN or an explosion.
    pub energy_retries: u64,
    /// CG iterations and capped solves of the implicit integrator.
    pub solver: StepStats,
}

/// What adaptive meshing did (zeros and `null` when the scene does not adapt).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Adaptivity {
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
}

/// Contacts with obstacles and self-collision, and their wall time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Collisions {
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
}

/// The standard tests' measurements at the end, for the scenes that set them up.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measurements {
    /// Cusick drape measurements at the end, when the scene is a disk specimen on a
    /// vertical support cylinder (see `collide::cusick`).
    pub cusick: Option<crate::collide::cusick::CusickSummary>,
    /// Cantilever bending test measurements at the end, when the scene is a
    /// rectangle held by fixed pins over one end (see `cantilever`).
    pub cantilever: Option<crate::cantilever::CantileverSummary>,
}

/// What the scene asks of the cloth against what the run did: the pin regions
/// hold the cloth they name, the seams close, the cloth comes to rest. Each
/// part is absent from the JSON when there is nothing to report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneChecks {
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
}

/// The rest criterion at the end of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RestSummary {
    /// True when the run ended at rest.
    pub at_rest: bool,
    /// When it came to rest, s (`None`: it did not).
    pub time: Option<Scalar>,
    /// The largest vertex speed over the last frame, m/s (`None`, `null` in
    /// the JSON, when the last frame changed the mesh, as a weld does, or
    /// the run ended before its first frame).
    pub speed: Option<Scalar>,
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
            None => {
                let speed = match self.speed {
                    Some(speed) => format!("the fastest vertex moves at {speed:.4} m/s at the end"),
                    None => "the last frame changed the mesh (a weld), so no speed is measured"
                        .to_string(),
                };
                format!(
                    " Not at rest: {speed} (rest: under {} m/s for {} s with every seam welded).",
                    self.threshold, self.window
                )
            }
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
        mesh.seams()
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
        self.stepping.dt_max - self.stepping.dt > 1e-9 * self.stepping.dt_max
    }
}

#[cfg(test)]
mod rest_sentence_tests {
    use super::RestSummary;

    fn not_at_rest(speed: Option<f64>) -> String {
        RestSummary {
            at_rest: false,
            time: None,
            speed,
            threshold: 0.05,
            window: 0.5,
        }
        .sentence()
    }

    #[test]
    fn a_run_whose_last_frame_welded_says_no_speed_was_measured_not_inf() {
        let s = not_at_rest(None);
        assert!(s.contains("no speed is measured"), "{s}");
        assert!(!s.contains("inf"), "{s}");
    }

    #[test]
    fn a_run_not_at_rest_gives_its_fastest_vertex() {
        let s = not_at_rest(Some(0.125));
        assert!(s.contains("moves at 0.1250 m/s"), "{s}");
    }
}
