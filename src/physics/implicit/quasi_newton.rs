//! The quasi-Newton solver (`solver = "quasi_newton"`): L-BFGS on the backward
//! Euler equations with the scalar Laplacian factor as the initial inverse
//! Hessian (Liu, Bouaziz and Kavan 2017, "Quasi-Newton methods for real-time
//! simulation of hyperelastic materials").
//!
//! # The equations
//! The step solves `g(v) = M (v - v0) - h f(x0 + h v, v) = 0` for the velocity
//! `v` at the end of the step, the equations the Newton iterations solve
//! ([`super`], "Newton iterations"), with wind explicit as there. Without
//! damping, `g` is the gradient of the incremental potential
//! `E(v) = |v - v0|_M^2 / 2 + W(x0 + h v)` (`h^2` times Liu's, in velocities;
//! `W` holds the elastic, gravitational, drag and wind terms). The damping of
//! the springs and membranes has no potential: it stays in `g` at the current
//! iterate, so the solver converges to exactly the Newton iterations' solution.
//!
//! # The iteration
//! Each iteration takes the L-BFGS direction `p = -H g` from the last
//! [`HISTORY`] pairs `(s, y)` of steps and residual changes (the two-loop
//! recursion), whose initial inverse Hessian `H0^-1` is a solve with the scalar
//! factor of [`crate::physics::laplacian`], taken from the projected matrix
//! `A_s` of the direct solver (pins and contact normals decoupled), and with the
//! pin and contact filters applied to its input and output (`S H0^-1 S`, `S` as
//! in the direct solver). The prescribed parts of the first guess (pins,
//! contact normals) are therefore kept.
//!
//! # The line search
//! The step `alpha p` starts at `alpha = 1` and is halved, at most
//! [`HALVINGS`] times, until the change of the energy along it, estimated by
//! the trapezoid rule on the residual, `alpha (g(v) . p + g(v + alpha p) . p) / 2`,
//! meets Armijo's sufficient decrease `<= c alpha g(v) . p` (`c` =
//! [`ARMIJO`]). The estimate is exact for a quadratic energy, needs no energy
//! evaluation (only the residual, which the next iteration needs anyway) and
//! counts the damping's dissipation, which no potential holds.
//!
//! # Stopping
//! The iteration stops once `|S g|` falls below `newton_tolerance` times the
//! first linearisation's `|S b|` (the Newton iterations' test). A step that has
//! not converged after `quasi_newton_iterations` iterations, or whose line search
//! finds no acceptable step, fails with
//! [`SolveFailure::QuasiNewtonNotConverged`] and is retried with halved steps.
//!
//! # The factor
//! The Laplacian factor is made at the first step on a mesh, whenever the step
//! size differs from the factored one, and after a step that needed more than
//! `refactor_iterations` iterations beyond the step right after the last
//! factorization (the iterations an older factor costs outweigh a
//! factorization, counted as in the direct solver). Counts only, never clock
//! time, so the choice is the same on every machine and thread count.

use std::collections::VecDeque;
use std::time::Instant;

use rayon::prelude::*;

use super::cg::dot;
use super::{SolveFailure, contact_push_from, direct, update_state, without};
use crate::math::{Scalar, Vector};
use crate::physics::cholesky::FactorError;
use crate::physics::forces::{PAR_MIN, element_pass, gather};
use crate::physics::laplacian::LaplacianFactor;
use crate::physics::{ExternalForces, Model, Stepper};
use crate::world::World;

/// Pairs `(s, y)` the L-BFGS direction keeps.
pub const HISTORY: usize = 8;
/// Halvings of the line search before an unconverged step fails.
pub const HALVINGS: u32 = 12;
/// Armijo's sufficient decrease constant of the line search.
pub const ARMIJO: Scalar = 1e-4;

/// One L-BFGS pair: a step `s`, the residual change `y` along it and `1 / s.y`.
#[derive(Debug, Clone, Default)]
struct Pair {
    s: Vec<Vector>,
    y: Vec<Vector>,
    rho: Scalar,
}

/// The quasi-Newton solver's scratch: the factor, the history and the vectors.
#[derive(Debug, Default, Clone)]
pub(super) struct QuasiNewtonScratch {
    laplacian: LaplacianFactor,
    /// The step size the factor was made for (`None`: no factor).
    factored_h: Option<Scalar>,
    /// Iterations of the step right after the last factorization.
    fresh_iterations: Option<u32>,
    /// Set by a step whose iterations outweighed a factorization.
    stale: bool,
    history: VecDeque<Pair>,
    /// Pairs no longer in the history, kept for their buffers.
    spare: Vec<Pair>,
    /// The residual `S g` at the current iterate and at the trial one.
    g: Vec<Vector>,
    g_trial: Vec<Vector>,
    /// The unfiltered residual at the trial iterate (the contact impulses).
    g_full: Vec<Vector>,
    /// Per vertex: the wind's explicit force times `h`, from the start of the step.
    wind: Vec<Vector>,
    p: Vec<Vector>,
    q: Vec<Vector>,
    z: Vec<Vector>,
    alpha: Vec<Scalar>,
    dv_trial: Vec<Vector>,
}

impl QuasiNewtonScratch {
    /// Forgets the factor (the mesh changed).
    pub(super) fn mesh_changed(&mut self) {
        self.laplacian.reset();
        self.factored_h = None;
        self.fresh_iterations = None;
        self.stale = false;
    }

    /// Whether the step of size `h` factors anew (module docs, "The factor"),
    /// and so needs the block matrix assembled.
    pub(super) fn wants_factor(&self, h: Scalar) -> bool {
        self.stale || self.factored_h != Some(h) || !self.laplacian.is_valid()
    }
}

/// Solves the step's equations (module docs) from the first guess `dv`, whose
/// prescribed parts are kept, and leaves the state at the solution in `w`;
/// `reference`: the norm the tolerance is relative to.
pub(super) fn solve(
    st: &mut Stepper,
    model: &Model,
    w: &mut World,
    h: Scalar,
    held: &[bool],
    reference: Scalar,
) -> Result<(), SolveFailure> {
    if st.implicit.quasi.wants_factor(h) {
        factor(st, held, h)?;
    }
    let started = Instant::now();
    wind_share(st, model);
    let outcome = iterate(st, model, w, h, held, reference);
    let q = &mut st.implicit.quasi;
    if let Ok(iterations) = outcome {
        match q.fresh_iterations {
            None => q.fresh_iterations = Some(iterations),
            Some(fresh) => {
                q.stale = iterations > fresh + model.solver.refactor_iterations;
            }
        }
    }
    let s = &st.implicit;
    // The normal impulse each contact needed: the normal part of the residual.
    let minus_g: &[Vector] = &s.quasi.g_full;
    contact_push_from(
        &s.filter,
        None,
        minus_g,
        &st.elements.mass,
        &mut st.contact_push,
    );
    st.stats.newton_iterations += 1;
    st.stats.solve_s += started.elapsed().as_secs_f64();
    outcome.map(|_| ())
}

/// Assembles the projected matrix `A_s` at the start of the step (the
/// linearisation gathered its blocks) and factors its scalar Laplacian.
fn factor(st: &mut Stepper, held: &[bool], h: Scalar) -> Result<(), SolveFailure> {
    let pattern = direct::assemble(st, held);
    let started = Instant::now();
    let q = &mut st.implicit.quasi;
    let map = |e: FactorError| match e {
        FactorError::NotPositiveDefinite => SolveFailure::NotPositiveDefinite,
        FactorError::Setup => SolveFailure::Setup,
    };
    if !q.laplacian.is_analysed() {
        q.laplacian.analyse(&pattern).map_err(map)?;
        st.stats.symbolic_analyses += 1;
    }
    let system = st.implicit.direct.system();
    let q = &mut st.implicit.quasi;
    let result = q.laplacian.factor(&pattern, system, &st.elements.mass);
    st.stats.factorizations += 1;
    st.stats.factorization_s += started.elapsed().as_secs_f64();
    result.map_err(map)?;
    q.factored_h = Some(h);
    q.fresh_iterations = None;
    q.stale = false;
    Ok(())
}

/// Per vertex: the wind's force at the start of the step times `h` (the
/// linearisation's triangle shares), or nothing without wind.
fn wind_share(st: &mut Stepper, model: &Model) {
    let (el, s) = (&st.elements, &mut st.implicit);
    s.quasi.wind.clear();
    if model.external.wind.is_none() {
        return;
    }
    let slots = &s.tri_slot;
    s.quasi.wind.resize(el.mass.len(), Vector::ZERO);
    s.quasi
        .wind
        .par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, f)| {
            for &t in el.vertex_triangles.of(i) {
                *f += slots[t as usize];
            }
        });
}

/// The L-BFGS iterations; returns how many were taken.
fn iterate(
    st: &mut Stepper,
    model: &Model,
    w: &mut World,
    h: Scalar,
    held: &[bool],
    reference: Scalar,
) -> Result<u32, SolveFailure> {
    let tolerance = model.solver.newton_tolerance;
    let goal = tolerance * reference.max(Scalar::MIN_POSITIVE);
    let n = w.x.len();
    {
        let q = &mut st.implicit.quasi;
        let spare = &mut q.spare;
        spare.extend(q.history.drain(..));
        for buf in [&mut q.g, &mut q.g_trial, &mut q.p, &mut q.q, &mut q.z] {
            buf.resize(n, Vector::ZERO);
        }
        q.dv_trial.clone_from(&st.implicit.dv);
    }
    let mut norm = residual(st, model, w, h, held);
    swap_trial(st);
    let mut iterations = 0u32;
    loop {
        if norm <= goal {
            return Ok(iterations);
        }
        let failed = |iterations, norm: Scalar| SolveFailure::QuasiNewtonNotConverged {
            iterations,
            residual: norm / reference.max(Scalar::MIN_POSITIVE),
            tolerance,
        };
        if iterations >= model.solver.quasi_newton_iterations {
            return Err(failed(iterations, norm));
        }
        let slope = direction(st, held);
        let Some(trial_norm) = line_search(st, model, w, (h, held), slope) else {
            return Err(failed(iterations, norm));
        };
        remember(&mut st.implicit.quasi);
        swap_trial(st);
        norm = trial_norm;
        iterations += 1;
        st.stats.quasi_newton_iterations += 1;
    }
}

/// Into `p`: the L-BFGS direction `-H g` (two-loop recursion), or the
/// steepest descent of `H0` when that is not a descent direction (the history
/// is then forgotten). Returns the slope `g . p` (negative).
fn direction(st: &mut Stepper, held: &[bool]) -> Scalar {
    let s = &mut st.implicit;
    let q = &mut s.quasi;
    q.q.clone_from(&q.g);
    q.alpha.clear();
    for pair in q.history.iter().rev() {
        let a = pair.rho * dot(&pair.s, &q.q);
        axpy(&mut q.q, -a, &pair.y);
        q.alpha.push(a);
    }
    initial_inverse(q, &s.filter, held);
    for (pair, a) in q.history.iter().zip(q.alpha.iter().rev()) {
        let b = pair.rho * dot(&pair.y, &q.z);
        axpy(&mut q.z, a - b, &pair.s);
    }
    q.p.par_iter_mut()
        .zip(q.z.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|(p, z)| *p = -*z);
    let slope = dot(&q.g, &q.p);
    if slope < 0.0 || q.history.is_empty() {
        return slope;
    }
    q.spare.extend(q.history.drain(..));
    q.q.clone_from(&q.g);
    initial_inverse(q, &s.filter, held);
    q.p.par_iter_mut()
        .zip(q.z.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|(p, z)| *p = -*z);
    dot(&q.g, &q.p)
}

/// `z = S H0^-1 S q` (module docs, "The iteration").
fn initial_inverse(q: &mut QuasiNewtonScratch, filter: &[Vector], held: &[bool]) {
    let project = |i: usize, v: Vector| {
        if held[i] {
            Vector::ZERO
        } else {
            without(filter[i], v)
        }
    };
    q.q.par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, v)| *v = project(i, *v));
    q.laplacian.solve(&q.q, &mut q.z);
    q.z.par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, v)| *v = project(i, *v));
}

/// Backtracking from `alpha = 1` along `p` (module docs, "The line search"):
/// leaves the accepted iterate in `dv_trial`, its residual in `g_trial` and
/// the step taken in `p`. Returns the residual's filtered norm there, or
/// `None` when no step is acceptable.
fn line_search(
    st: &mut Stepper,
    model: &Model,
    w: &mut World,
    (h, held): (Scalar, &[bool]),
    slope: Scalar,
) -> Option<Scalar> {
    // Not a descent direction (or not a number): no step is acceptable.
    if slope.is_nan() || slope >= 0.0 {
        return None;
    }
    let mut alpha = 1.0;
    for _ in 0..=HALVINGS {
        {
            let s = &mut st.implicit;
            let q = &mut s.quasi;
            q.dv_trial
                .par_iter_mut()
                .zip(s.dv.par_iter().zip(q.p.par_iter()))
                .with_min_len(PAR_MIN)
                .for_each(|(t, (d, p))| *t = *d + *p * alpha);
        }
        let norm = residual(st, model, w, h, held);
        let q = &mut st.implicit.quasi;
        let end_slope = dot(&q.g_trial, &q.p);
        if norm.is_finite() && end_slope <= (2.0 * ARMIJO - 1.0) * slope {
            q.p.par_iter_mut()
                .with_min_len(PAR_MIN)
                .for_each(|p| *p *= alpha);
            return Some(norm);
        }
        alpha *= 0.5;
    }
    None
}

/// Adds the accepted step's pair `(s, y) = (p, g_trial - g)` to the history
/// when its curvature `s . y` is positive (else the pair is skipped).
fn remember(q: &mut QuasiNewtonScratch) {
    let mut pair = q.spare.pop().unwrap_or_default();
    pair.s.clone_from(&q.p);
    pair.y.clear();
    pair.y
        .extend(q.g_trial.iter().zip(&q.g).map(|(a, b)| *a - *b));
    let sy = dot(&pair.s, &pair.y);
    let scale = dot(&pair.s, &pair.s).sqrt() * dot(&pair.y, &pair.y).sqrt();
    if sy.is_nan() || sy <= 1e-12 * scale {
        q.spare.push(pair);
        return;
    }
    pair.rho = 1.0 / sy;
    if q.history.len() == HISTORY {
        q.spare.extend(q.history.pop_front());
    }
    q.history.push_back(pair);
}

/// Makes the trial iterate the current one: `dv`, `g`.
fn swap_trial(st: &mut Stepper) {
    let s = &mut st.implicit;
    std::mem::swap(&mut s.dv, &mut s.quasi.dv_trial);
    std::mem::swap(&mut s.quasi.g, &mut s.quasi.g_trial);
}

/// The residual at `v = v0 + dv_trial`: the state moved there (`w`), its
/// unfiltered negative `h f - M (v - v0)` into `g_full` and `S g` into
/// `g_trial`. Returns `|S g|`.
fn residual(st: &mut Stepper, model: &Model, w: &mut World, h: Scalar, held: &[bool]) -> Scalar {
    let s = &mut st.implicit;
    std::mem::swap(&mut s.dv, &mut s.quasi.dv_trial);
    update_state(s, w, h);
    std::mem::swap(&mut s.dv, &mut s.quasi.dv_trial);
    let ext = ExternalForces {
        wind: None,
        ..model.external
    };
    let el = &st.elements;
    element_pass(el, &ext, &w.mesh.triangles, &w.x, &w.v, &mut st.forces);
    let q = &mut s.quasi;
    let (forces, wind, mass, v0) = (&st.forces, &q.wind, &el.mass, &s.v0);
    let (filter, x_v) = (&s.filter, &w.v);
    q.g_full.resize(x_v.len(), Vector::ZERO);
    q.g_full
        .par_iter_mut()
        .zip(q.g_trial.par_iter_mut())
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, (full, g))| {
            let mut b = gather(el, &ext, forces, i, x_v[i]) * h - (x_v[i] - v0[i]) * mass[i];
            if let Some(f) = wind.get(i) {
                b += *f;
            }
            *full = b;
            *g = if held[i] {
                Vector::ZERO
            } else {
                -without(filter[i], b)
            };
        });
    dot(&q.g_trial, &q.g_trial).sqrt()
}

/// `a += c b`.
fn axpy(a: &mut [Vector], c: Scalar, b: &[Vector]) {
    a.par_iter_mut()
        .zip(b.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|(a, b)| *a += *b * c);
}
