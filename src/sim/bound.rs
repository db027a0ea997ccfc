//! The energy bound a step is held to, and why a step is rejected.

use super::step_control::Refusal;
use crate::math::{Scalar, Vector, deterministic_sum};
use crate::physics::{Model, SolveFailure, Stepper};
use crate::world::World;

/// A step "explodes" when the cloth's kinetic plus gravitational energy exceeds the
/// physical bound (initial energy plus the work of wind, pins and moving obstacles)
/// by this many times the run's energy scale ([`EnergyBound`]): far beyond any
/// discretisation error, only an instability gets there.
pub const EXPLOSION_FACTOR: Scalar = 1.0;

/// Why a step was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepFailure {
    /// A position became NaN or infinite.
    NonFinite,
    /// The implicit step's equations could not be solved.
    Solver(SolveFailure),
    /// The energy exceeded its bound by [`EXPLOSION_FACTOR`] energy scales.
    Explosion {
        /// Kinetic plus gravitational energy after the step, J.
        energy: Scalar,
        /// The bound it exceeded, J.
        bound: Scalar,
    },
    /// An adaptive step (`dt = "adaptive"`) at its smallest size still exceeded
    /// a tolerance.
    AboveTolerance(Refusal),
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepFailure::NonFinite => write!(f, "positions became NaN or infinite"),
            StepFailure::Solver(why) => write!(f, "{why}"),
            StepFailure::Explosion { energy, bound } => write!(
                f,
                "the energy exploded (kinetic + gravitational {energy:.4e} J, above the explosion limit {bound:.4e} J)"
            ),
            StepFailure::AboveTolerance(reason) => match reason {
                Refusal::Error(e) => write!(
                    f,
                    "at the smallest adaptive step (simulation.adaptive_dt.min) the error estimate {e:.3e} m exceeds simulation.adaptive_dt.tolerance"
                ),
                Refusal::Penetration(p) => write!(
                    f,
                    "at the smallest adaptive step (simulation.adaptive_dt.min) the cloth ends {p:.3e} m below an obstacle surface, deeper than simulation.adaptive_dt.penetration"
                ),
                Refusal::Failed => write!(
                    f,
                    "at the smallest adaptive step (simulation.adaptive_dt.min) the step failed"
                ),
            },
        }
    }
}

/// The energy the cloth may have: its initial total plus the external work, and the
/// scale against which an excess counts as an explosion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyBound {
    /// Total energy at the start, J.
    pub initial: Scalar,
    /// `|E0| + KE0 + m |g| D` (D: the cloth's diagonal), J: the energies the run
    /// naturally trades (a fall through the cloth's own size).
    pub scale: Scalar,
}

impl EnergyBound {
    /// The bound of a run of `model` starting from `world`.
    pub fn new(world: &World, stepper: &Stepper, model: &Model) -> EnergyBound {
        let e = stepper.energy(model, world);
        let mass = stepper.elements.total_mass();
        let g = model.external.gravity.unwrap_or(Vector::ZERO).length();
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

    /// `Err` (the failure) when the kinetic plus gravitational energy of `world`
    /// exceeds the bound by [`EXPLOSION_FACTOR`] scales, given the external work `work`
    /// so far. Elastic energy is left out (it is never negative, so the test stays
    /// sound) because it costs a pass over every element, where this costs one over
    /// the vertices.
    pub fn check(
        &self,
        world: &World,
        stepper: &Stepper,
        model: &Model,
        work: Scalar,
    ) -> Result<(), StepFailure> {
        let mass = &stepper.elements.mass;
        let g = model.external.gravity.unwrap_or(Vector::ZERO);
        let energy = deterministic_sum(world.x.len(), |i| {
            mass[i] * (0.5 * world.v[i].length_squared() - g.dot(world.x[i]))
        });
        let bound = self.initial + work + EXPLOSION_FACTOR * (self.scale + work.abs());
        if energy > bound || !energy.is_finite() {
            return Err(StepFailure::Explosion { energy, bound });
        }
        Ok(())
    }
}

/// True when every coordinate is finite (a NaN or infinity anywhere poisons the sum).
pub(super) fn is_finite(x: &[Vector]) -> bool {
    deterministic_sum(x.len(), |i| x[i].x + x[i].y + x[i].z).is_finite()
}
