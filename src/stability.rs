//! The stability suite (`docs/stability.md`, "Criteria"): hard cases run with
//! every integrator they allow and with adaptivity on and off, each judged on
//! four criteria: no numerical failure, no energy gain beyond the external work
//! (within a tolerance), no tunneling through obstacles, and mass conserved.
//!
//! The cases are the scenes of `scenes/hard/`, built into the binary; [`CASES`]
//! says which integrators each allows and how `--quick` shortens it. A
//! [`Suite`] is those cases or the scenes of another folder. See
//! `docs/stability.md`.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

mod cases;
mod suite;

pub use cases::{CASES, Case, OTHER};
pub use suite::{Suite, SuiteCase};

use crate::math::Scalar;
use crate::run::{FrameState, RunError, RunOptions, run_observed};
use crate::scene::{Integrator, Scene, SceneError, TimeStep};
use crate::summary::Summary;

/// Largest allowed energy excess `E(t) - E(0) - W(t)`, as a share of the
/// case's energy scale `S = |E(0)| + m |g| D` (see [`energy_scale`]).
pub const ENERGY_TOLERANCE: Scalar = 0.05;

/// Largest allowed relative change of the total mass.
pub const MASS_TOLERANCE: Scalar = 1e-9;

/// Why the suite could not run (a failing case is not an error: it is a row).
#[derive(Debug, thiserror::Error)]
pub enum StabilityError {
    /// `--case` named no case of the suite.
    #[error("no hard case named `{name}`; the cases are: {known}")]
    UnknownCase {
        /// The name given.
        name: String,
        /// The case names, comma-separated.
        known: String,
    },
    /// The `--suite` folder could not be listed.
    #[error("cannot read the suite folder {}: {source}", dir.display())]
    ReadSuite {
        /// The folder.
        dir: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The `--suite` folder holds no scene file.
    #[error("the suite folder {} holds no scene file (*.toml)", dir.display())]
    EmptySuite {
        /// The folder.
        dir: PathBuf,
    },
    /// A file a built-in scene reads could not be written to the temporary folder.
    #[error("cannot write {}: {source}", path.display())]
    Files {
        /// The file or folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A case's scene file could not be loaded.
    #[error("{0}")]
    Scene(#[from] SceneError),
    /// A run failed for another reason than a numerical failure.
    #[error("case {case}: {source}")]
    Run {
        /// The case.
        case: String,
        /// What went wrong.
        source: RunError,
    },
}

/// One run of the suite: a case with one integrator and adaptivity on or off.
#[derive(Debug, Clone, Copy)]
pub struct Variant<'a> {
    /// The case.
    pub case: &'a SuiteCase,
    /// The integrator.
    pub integrator: Integrator,
    /// Adaptivity on (the scene's `[adapt]`) or off.
    pub adaptive: bool,
}

/// The result of one [`Variant`].
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// Integrator name.
    pub integrator: String,
    /// Adaptivity on.
    pub adaptive: bool,
    /// Steps taken.
    pub steps: u64,
    /// Frames retried with halved steps.
    pub retries: u64,
    /// Energy scale S = |E(0)| + m |g| D, J.
    pub energy_scale: Scalar,
    /// Largest `E(t) - E(0) - W(t)` divided by S (pass: at most [`ENERGY_TOLERANCE`]).
    pub excess_ratio: Scalar,
    /// Largest depth below an obstacle surface, m (`None`: no obstacles).
    pub max_penetration: Option<Scalar>,
    /// Thinnest obstacle thickness, m (`None`: no obstacles).
    pub thickness: Option<Scalar>,
    /// |m_final - m_initial| / m_initial.
    pub mass_drift: Scalar,
    /// Wall time, s.
    pub wall_s: Scalar,
    /// The numerical failure that stopped the run, if any.
    pub failure: Option<String>,
    /// A hash of the f64 bits of every position of every frame.
    pub hash: u64,
}

impl Row {
    /// Reasons the row fails (empty: it passes).
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(f) = &self.failure {
            out.push(f.clone());
        }
        if self.energy_scale.is_nan() {
            // The run panicked: there is no summary to judge.
            if out.is_empty() {
                out.push("no energy scale (NaN)".to_string());
            }
            return out;
        }
        if !at_most(self.excess_ratio, ENERGY_TOLERANCE) {
            out.push(format!(
                "energy excess {:.3} S > {ENERGY_TOLERANCE} S",
                self.excess_ratio
            ));
        }
        if let (Some(p), Some(t)) = (self.max_penetration, self.thickness)
            && !below(p, t)
        {
            out.push(format!("penetration {p:.2e} m >= thickness {t:.2e} m"));
        }
        if !at_most(self.mass_drift, MASS_TOLERANCE) {
            out.push(format!("mass drift {:.2e}", self.mass_drift));
        }
        out
    }

    /// True when every criterion holds.
    pub fn passed(&self) -> bool {
        self.failures().is_empty()
    }
}

/// `x <= limit`; false for NaN.
fn at_most(x: Scalar, limit: Scalar) -> bool {
    x <= limit
}

/// `x < limit`; false for NaN.
fn below(x: Scalar, limit: Scalar) -> bool {
    x < limit
}

/// The integrator's name as written in scene files.
pub fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::SymplecticEuler => "symplectic_euler",
        Integrator::Rk4 => "rk4",
        Integrator::Implicit => "implicit",
    }
}

impl Variant<'_> {
    /// The scene of this run, shortened with `quick`. The explicit integrators
    /// always take their automatic (stable) step; the implicit one keeps the
    /// scene's step.
    pub fn scene(&self, quick: bool) -> Scene {
        let plan = self.case.plan;
        let mut scene = self.case.scene.clone();
        if quick {
            scene.simulation.duration = scene.simulation.duration.min(plan.quick_duration);
            if let Some(r) = plan.quick_resolution {
                scene.cloth.resolution = Some(r);
            }
        }
        scene.simulation.integrator = self.integrator;
        if self.integrator != Integrator::Implicit {
            scene.simulation.dt = TimeStep::Auto;
        }
        if !self.adaptive {
            scene.adapt = None;
        }
        scene
    }
}

/// The energy scale of a run: `S = |E(0)| + m |g| D`, with m the cloth's mass,
/// g the gravity and D the diagonal of the cloth's material-space bounds.
pub fn energy_scale(summary: &Summary, gravity: [Scalar; 3], diagonal: Scalar) -> Scalar {
    let g = gravity.iter().map(|x| x * x).sum::<Scalar>().sqrt();
    summary.conservation.energy.initial.abs() + summary.conservation.mass_initial * g * diagonal
}

/// FNV-1a over 64-bit words.
fn fnv(hash: u64, word: u64) -> u64 {
    let mut h = hash;
    for b in word.to_le_bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// Runs one variant of `scene` with `threads` worker threads and judges it.
pub fn run_variant(
    scene: &Scene,
    variant: &Variant<'_>,
    threads: Option<usize>,
) -> Result<Row, StabilityError> {
    let opts = RunOptions {
        record: None,
        threads,
        ..Default::default()
    };
    let interrupt = AtomicBool::new(false);
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    let mut diagonal: Scalar = 0.0;
    let mut observe = |f: &FrameState| {
        if f.frame == 0 {
            let (mut lo, mut hi) = (f.material[0], f.material[0]);
            for m in f.material {
                lo = lo.min(*m);
                hi = hi.max(*m);
            }
            diagonal = lo.distance(hi);
        }
        hash = fnv(hash, f.frame);
        for p in f.positions {
            for x in p.to_array() {
                hash = fnv(hash, x.to_bits());
            }
        }
    };
    let start = Instant::now();
    // An engine panic is a bug, but it must not take the rest of the suite down:
    // it becomes a FAIL row naming the panic.
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        run_observed(scene, &opts, &interrupt, &mut |_| {}, &mut observe)
    }));
    let wall_s = start.elapsed().as_secs_f64();
    let outcome = match outcome {
        Ok(outcome) => outcome,
        Err(payload) => return Ok(panicked_row(variant, wall_s, payload.as_ref())),
    };
    let (summary, failure) = match outcome {
        Ok(s) => (s, None),
        Err(e) => match &e {
            RunError::Numerical { summary, .. } => (
                summary.as_ref().clone(),
                Some(format!("numerical failure: {e}")),
            ),
            _ => {
                return Err(StabilityError::Run {
                    case: variant.case.name.clone(),
                    source: e,
                });
            }
        },
    };
    let s = energy_scale(&summary, scene.simulation.gravity, diagonal);
    let thickness = scene
        .obstacle
        .iter()
        .map(|o| o.thickness)
        .reduce(Scalar::min);
    Ok(Row {
        case: variant.case.name.clone(),
        integrator: integrator_name(variant.integrator).to_string(),
        adaptive: variant.adaptive,
        steps: summary.extent.steps,
        retries: summary.effort.nan_recoveries,
        energy_scale: s,
        excess_ratio: summary.conservation.energy.excess_max / s,
        max_penetration: thickness.map(|_| summary.collision.max_penetration),
        thickness,
        mass_drift: (summary.conservation.mass_final - summary.conservation.mass_initial).abs()
            / summary.conservation.mass_initial,
        wall_s,
        failure,
        hash,
    })
}

/// The FAIL row of a run that panicked (an engine bug).
fn panicked_row(
    variant: &Variant<'_>,
    wall_s: Scalar,
    payload: &(dyn std::any::Any + Send),
) -> Row {
    let message = payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied())
        .unwrap_or("(no message)");
    Row {
        case: variant.case.name.clone(),
        integrator: integrator_name(variant.integrator).to_string(),
        adaptive: variant.adaptive,
        steps: 0,
        retries: 0,
        energy_scale: Scalar::NAN,
        excess_ratio: Scalar::NAN,
        max_penetration: None,
        thickness: None,
        mass_drift: Scalar::NAN,
        wall_s,
        failure: Some(format!("the engine panicked: {message}")),
        hash: 0,
    }
}

/// The table of `rows` as Markdown (also readable as plain text).
pub fn table(rows: &[Row]) -> String {
    let mut out = String::from(
        "| case | integrator | adaptive | steps | retries | excess/S | max penetration (m) | mass drift | wall (s) | result |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let pen = match (r.max_penetration, r.thickness) {
            (Some(p), Some(t)) => format!("{p:.2e} (< {t:.0e})"),
            _ => "-".to_string(),
        };
        let failures = r.failures();
        let verdict = if failures.is_empty() {
            "pass".to_string()
        } else {
            format!("FAIL: {}", failures.join("; "))
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {:.2e} | {} | {:.1e} | {:.1} | {} |",
            r.case,
            r.integrator,
            if r.adaptive { "on" } else { "off" },
            r.steps,
            r.retries,
            r.excess_ratio,
            pen,
            r.mass_drift,
            r.wall_s,
            verdict
        );
    }
    let failed = rows.iter().filter(|r| !r.passed()).count();
    let _ = writeln!(
        out,
        "\n{} runs, {} passed, {} failed. excess/S: largest E(t) - E(0) - W(t) over the run divided by S = |E(0)| + m|g|D (pass: <= {ENERGY_TOLERANCE}); mass drift: |m_end - m_0| / m_0 (pass: <= {MASS_TOLERANCE:.0e}); penetration must stay below the obstacle thickness.",
        rows.len(),
        rows.len() - failed,
        failed
    );
    out
}

/// True when every row passes (the exit status of `drape stability`).
pub fn all_passed(rows: &[Row]) -> bool {
    rows.iter().all(Row::passed)
}
