//! Implicit backward Euler (Baraff and Witkin 1998), with optional Newton iterations.
//!
//! The first (and by default only) Newton step solves `A dv = b` with
//! `A = M + h (D + drag) + h^2 K` and `b = h f(x0, v0) - h^2 K v0`,
//! then `v1 = v0 + dv`, `x1 = x0 + h v1`. Here `K = -df/dx` and `D = -df/dv`.
//!
//! * Spring `e = (a, b)`, unit axis `n`, length `l`, rest `L`:
//!   `K_e = k (n n^T + max(0, 1 - L/l) (I - n n^T))`. The transverse term is
//!   clamped at zero under compression (Choi and Ko 2002) so `K` stays positive
//!   semi-definite; `D_e = c n n^T`. Both act on `p_a - p_b`.
//! * Dihedral hinge with gradient `g` of its angle: Gauss-Newton `K_h = k g g^T`
//!   (the curvature term of the exact Hessian is dropped; it is indefinite).
//! * Shape triangle (`shape.rs`), energy `theta^T M theta / 2` over its three edge
//!   angles with Jacobian `J` (rows: angle gradients): Gauss-Newton `K_t = J^T M J`
//!   (constant `M`; the curvature term is dropped as for the hinges).
//! * Membrane triangle (`membrane.rs`): `K_t = J^T C J + S+ (x) I` (the
//!   Gauss-Newton part plus the positive part of the geometric term, exact in
//!   tension), `D_t = damping J^T C J`.
//! * Wind is treated explicitly (only in `b`, evaluated at the start of the step).
//!
//! # Newton iterations
//! With `newton_iterations` > 1, the step goes on to solve the backward Euler
//! equations `g(v) = M (v - v0) - h f(x0 + h v, v) = 0` themselves: iteration k
//! linearises at the current iterate, `A(x_k, v_k) dv = h f(x_k, v_k) - M (v_k - v0)`,
//! and stops when `|g|` (pinned and contact-filtered rows left out) falls below
//! `newton_tolerance` times the first right-hand side's norm. A step that has not
//! converged after `newton_iterations` fails (see below).
//!
//! # Linear solvers
//! * `direct` (default, [`direct`]): `A` assembled into a fixed block pattern and
//!   factored by a sparse Cholesky; the factor is kept and used to precondition
//!   conjugate gradients in the following steps, and the matrix is factored anew
//!   when the iterations the older factor costs outweigh a factorization, worth
//!   `refactor_iterations` of them ([`refactor`] module docs) (the stiffer the cloth and the
//!   larger the step, the more Jacobi-preconditioned CG needs; a factor of a nearby
//!   matrix needs a few iterations whatever the stiffness).
//! * `cg` ([`cg`]): matrix-free conjugate gradients with the diagonal of `A` as the
//!   preconditioner, applied with the same element pass + per-vertex gather as the
//!   forces.
//! * `quasi_newton` ([`quasi_newton`]): no linear solve; L-BFGS on the backward
//!   Euler equations themselves (as with Newton iterations, to
//!   `newton_tolerance`), with a scalar Laplacian factor of `A` as the initial
//!   Hessian and a line search (Liu, Bouaziz and Kavan 2017).
//!
//! A linear solve that does not reach `cg_tolerance` (relative residual) within
//! `cg_max_iterations`, a matrix that is not positive definite, or Newton iterations
//! that do not converge make the step fail with a [`SolveFailure`]: the run retries
//! the frame with halved steps, and stops with a message when that does not help.
//! No unconverged solve is ever accepted.
//!
//! # Pins and contacts
//! Pinned vertices are handled by filtering (their `dv` is prescribed by the pin
//! script and their residual is zeroed).
//!
//! Obstacle contact is filtered the same way, one direction instead of three
//! (Baraff and Witkin 1998, section 5): a vertex the collision pass left in contact
//! with an obstacle ([`Contact`]) whose right-hand side presses it into the surface
//! (`b . n < 0`) gets its normal velocity prescribed to the obstacle's
//! (`(v0 + dv) . n = u_n`) and its residual, search direction and operator rows
//! projected by `S = I - n n^T`, so the solve moves it only along the surface. Left
//! to the post-step response alone, a large step solves the cloth as if such a
//! vertex could sink in, then moves it back: the neighbours' velocities are those of
//! a cloth that sank, and each step of resting contact stretches the springs around
//! it (with 4 ms steps a tablecloth gained more energy than it started with). A
//! vertex pulled away from the surface (`b . n >= 0`) is left free, so cloth lifts off,
//! unless the last step held it and the surface pushed on it then
//! ([`Contact::pressed`]): such a vertex is held again, and released once the
//! solve finds the surface pulling (its contact impulse not positive), a step
//! later than `b` alone would release it (Baraff and Witkin's release rule).
//! Deciding by `b` alone, whose `-h^2 K v0` term carries the neighbours'
//! velocities, held a vertex under a fold only every other step: the fold
//! pressed it in, was let go, sank and sprang back, and the cloth on a ball
//! never came to rest (test
//! `resting_contact::a_sheet_lying_on_a_ball_settles_without_two_step_jitter`).
//! The direct solver factors the projected matrix `S A S + (I - S) m`, which is
//! positive definite on all of space and whose solution has the prescribed parts
//! unchanged.

mod cg;
mod direct;
mod linearise;
mod quasi_newton;
mod refactor;

use linearise::linearise;
pub use quasi_newton::HISTORY as QUASI_NEWTON_HISTORY;

use rayon::prelude::*;

use super::elements::Elements;
use super::forces::PAR_MIN;
use super::kinds::KindLinear;
use super::{Contact, Model, Preconditioner, Stepper};
use crate::math::{Scalar, Vector, deterministic_sum};
use crate::spec::Solver;
use crate::world::World;

/// Why an implicit step could not be solved.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum SolveFailure {
    /// The linear solve stopped at its iteration cap above its tolerance.
    #[error(
        "the linear solve did not converge (relative residual {residual:.3e} after {iterations} iterations, tolerance {tolerance:.1e})"
    )]
    NotConverged {
        /// Iterations done.
        iterations: u32,
        /// Relative residual reached.
        residual: Scalar,
        /// Relative residual asked for.
        tolerance: Scalar,
    },
    /// The system matrix was not numerically positive definite.
    #[error("the implicit system matrix is not positive definite")]
    NotPositiveDefinite,
    /// Newton iterations did not reach their tolerance.
    #[error(
        "Newton iterations did not converge (relative residual {residual:.3e} after {iterations} iterations, tolerance {tolerance:.1e})"
    )]
    NewtonNotConverged {
        /// Newton iterations done.
        iterations: u32,
        /// Relative residual of the implicit equations reached.
        residual: Scalar,
        /// Relative residual asked for.
        tolerance: Scalar,
    },
    /// The quasi-Newton iterations did not reach their tolerance, or their line
    /// search found no acceptable step ([`quasi_newton`]).
    #[error(
        "quasi-Newton iterations did not converge (relative residual {residual:.3e} after {iterations} iterations, tolerance {tolerance:.1e})"
    )]
    QuasiNewtonNotConverged {
        /// Quasi-Newton iterations done.
        iterations: u32,
        /// Relative residual of the implicit equations reached.
        residual: Scalar,
        /// Relative residual asked for.
        tolerance: Scalar,
    },
    /// The sparse factorization could not be set up (memory).
    #[error("the sparse factorization could not be set up (out of memory or too large)")]
    Setup,
}

impl SolveFailure {
    /// A linear solve stopped after `iterations` at residual norm `norm`, above
    /// `tolerance` relative to `reference`.
    fn not_converged(
        iterations: u32,
        norm: Scalar,
        reference: Scalar,
        tolerance: Scalar,
    ) -> SolveFailure {
        SolveFailure::NotConverged {
            iterations,
            residual: norm / reference.max(Scalar::MIN_POSITIVE),
            tolerance,
        }
    }
}

/// Scratch memory of the implicit step, kept between steps.
#[derive(Debug, Default, Clone)]
pub struct ImplicitScratch {
    /// Every force element kind's terms of the linearised step ([`super::kinds`]).
    kinds: KindLinear,
    /// `h^2` of the step being solved (scales the shape triangles' `M`).
    h2: Scalar,
    tri_slot: Vec<Vector>,
    /// Per vertex: mass plus `h` times its drag coefficient.
    diag_mass: Vec<Scalar>,
    inv_diag: Vec<Vector>,
    /// Right-hand side of the current linear solve.
    b: Vec<Vector>,
    /// Solution of the current linear solve; on entry the first guess (the
    /// caller's warm start), with the prescribed (pinned, contact-normal) parts
    /// already set.
    dv: Vec<Vector>,
    /// Per vertex: the contact normal whose direction is filtered out of the
    /// solve, or zero (see the module docs).
    filter: Vec<Vector>,
    /// Positions and velocities at the start of the step.
    x0: Vec<Vector>,
    v0: Vec<Vector>,
    /// With the quasi-Newton solver: the linearisation gathers the block
    /// matrix too (this step factors anew).
    gather_blocks: bool,
    cg: cg::CgScratch,
    direct: direct::DirectScratch,
    quasi: quasi_newton::QuasiNewtonScratch,
}

impl ImplicitScratch {
    /// Forgets everything tied to the mesh (pattern, factorization). The warm
    /// start is simulation state, not scratch: its owner clears it.
    pub fn mesh_changed(&mut self) {
        self.direct.mesh_changed();
        self.quasi.mesh_changed();
    }

    /// After [`ImplicitScratch::mesh_changed`], with the direct solver: the new
    /// mesh's block pattern and ordering made ahead of the first solve
    /// (the direct solver's `prepare`).
    pub fn prepare_direct(&mut self, elements: &Elements, preconditioner: Preconditioner) {
        self.direct.prepare(elements, preconditioner);
    }
}

/// One backward Euler step (module docs). `warm_start`: the last step's velocity
/// change on the same mesh, the first guess of the solve (it varies slowly from
/// step to step); empty, the solve starts from zero. One of another length is
/// stale (a bug: asserted in debug builds, then a cold start). The step's own
/// velocity change is left there, whether or not it succeeded.
pub fn backward_euler(
    st: &mut Stepper,
    model: &Model,
    w: &mut World,
    warm_start: &mut Vec<Vector>,
    h: Scalar,
) -> Result<(), SolveFailure> {
    let t = w.time;
    let n = w.x.len();
    w.pins.held_at(t, &mut st.held);
    {
        let s = &mut st.implicit;
        s.x0.clear();
        s.x0.extend_from_slice(&w.x);
        s.v0.clear();
        s.v0.extend_from_slice(&w.v);
        s.gather_blocks = model.solver.solver == Solver::QuasiNewton && s.quasi.wants_factor(h);
    }
    linearise(st, model, w, h, false);
    let s = &mut st.implicit;
    s.dv.clear();
    // A warm start of another mesh should have been cleared with that mesh.
    debug_assert!(
        warm_start.is_empty() || warm_start.len() == n,
        "a warm start of {} vertices for a mesh of {n}",
        warm_start.len()
    );
    if warm_start.len() == n {
        s.dv.extend_from_slice(warm_start);
    } else {
        s.dv.resize(n, Vector::ZERO);
    }
    // Prescribed velocity change of pinned vertices; the free ones start from
    // the previous step's solution.
    for a in &w.pins.anchors {
        if st.held[a.vertex as usize] {
            let (_, vel) = w.pins.target(a, t + h);
            s.dv[a.vertex as usize] = vel - w.v[a.vertex as usize];
        }
    }
    contact_filters(s, &st.contacts, &st.held, &w.v);
    // Taken out for the solve so that the solvers can borrow the stepper.
    let held = std::mem::take(&mut st.held);
    let result = if model.solver.solver == Solver::QuasiNewton {
        let reference = filtered_norm(&st.implicit, &held);
        quasi_newton::solve(st, model, w, h, &held, reference)
    } else {
        newton(st, model, w, h, &held)
    };
    st.held = held;
    warm_start.clear();
    warm_start.extend_from_slice(&st.implicit.dv);
    result?;
    w.pins.apply(t + h, &mut w.x, &mut w.v);
    Ok(())
}

/// What a step of `h` counts as assembly, without the solve: the pins held at
/// the world's time, the linearisation at its state (element terms and `b`) and,
/// with the direct solver, the block matrix `A` and the projected system (the
/// pattern built for a new mesh). The first guess is zero; the world is left as
/// it is. Benchmarks time this through [`Stepper::assemble_implicit`].
pub(super) fn assemble(st: &mut Stepper, model: &Model, w: &World, h: Scalar) {
    let n = w.x.len();
    w.pins.held_at(w.time, &mut st.held);
    linearise(st, model, w, h, false);
    let s = &mut st.implicit;
    s.dv.clear();
    s.dv.resize(n, Vector::ZERO);
    contact_filters(s, &st.contacts, &st.held, &w.v);
    if model.solver.solver == Solver::Direct {
        let held = std::mem::take(&mut st.held);
        direct::assemble(st, &held);
        st.held = held;
    }
}

/// The Newton iterations of a step, the first one set up by the caller.
fn newton(
    st: &mut Stepper,
    model: &Model,
    w: &mut World,
    h: Scalar,
    held: &[bool],
) -> Result<(), SolveFailure> {
    let settings = model.solver;
    let reference = filtered_norm(&st.implicit, held);
    let single = settings.newton_iterations <= 1;
    linear_solve(st, model, held, reference, single)?;
    st.stats.newton_iterations += 1;
    update_state(&st.implicit, w, h);
    if single {
        return Ok(());
    }
    let mut residual = Scalar::INFINITY;
    for k in 1..=settings.newton_iterations {
        linearise(st, model, w, h, true);
        residual = filtered_norm(&st.implicit, held) / reference.max(Scalar::MIN_POSITIVE);
        if residual <= settings.newton_tolerance || k == settings.newton_iterations {
            break;
        }
        // The prescribed parts are already met: the correction is zero there.
        let s = &mut st.implicit;
        s.dv.iter_mut().for_each(|d| *d = Vector::ZERO);
        linear_solve(st, model, held, reference, false)?;
        st.stats.newton_iterations += 1;
        let s = &mut st.implicit;
        // Accumulate into v (update_state expects dv relative to v0).
        s.dv.par_iter_mut()
            .zip(w.v.par_iter().zip(s.v0.par_iter()))
            .with_min_len(PAR_MIN)
            .for_each(|(d, (v, v0))| *d += *v - *v0);
        update_state(&st.implicit, w, h);
    }
    // The normal impulse each contact needed: the normal part of minus the
    // residual `b` of the equations (no linear residual: `A dv` is zero).
    let s = &st.implicit;
    contact_push_from(
        &s.filter,
        None,
        &s.b,
        &st.elements.mass,
        &mut st.contact_push,
    );
    if residual > settings.newton_tolerance {
        return Err(SolveFailure::NewtonNotConverged {
            iterations: settings.newton_iterations,
            residual,
            tolerance: settings.newton_tolerance,
        });
    }
    Ok(())
}

/// Per vertex, the normal velocity change its contact filter imposed,
/// `n . (A dv - b) / m` (positive: the obstacle pushed; zero without a filter), into
/// `push`, from `ap = A dv` (`None`: zero, for a residual `b` of the nonlinear
/// equations). The collision pass turns it into friction's normal impulse.
fn contact_push_from(
    filter: &[Vector],
    ap: Option<&[Vector]>,
    b: &[Vector],
    mass: &[Scalar],
    push: &mut Vec<Scalar>,
) {
    push.clear();
    push.resize(filter.len(), 0.0);
    if filter.iter().all(|f| *f == Vector::ZERO) {
        return;
    }
    push.par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, push)| {
            let f = filter[i];
            if f != Vector::ZERO {
                let residual = ap.map_or(-b[i], |ap| ap[i] - b[i]);
                *push = (f.dot(residual) / mass[i]).max(0.0);
            }
        });
}

/// `v = v0 + dv`, `x = x0 + h v`.
fn update_state(s: &ImplicitScratch, w: &mut World, h: Scalar) {
    w.x.par_iter_mut()
        .zip(w.v.par_iter_mut())
        .zip(s.dv.par_iter().zip(s.x0.par_iter().zip(s.v0.par_iter())))
        .with_min_len(PAR_MIN)
        .for_each(|((x, v), (dv, (x0, v0)))| {
            *v = *v0 + *dv;
            *x = *x0 + *v * h;
        });
}

/// Solves `A dv = b` with the scene's solver; `contact_push`: also compute the
/// contacts' normal impulses from the linear residual.
fn linear_solve(
    st: &mut Stepper,
    model: &Model,
    held: &[bool],
    reference: Scalar,
    contact_push: bool,
) -> Result<(), SolveFailure> {
    match model.solver.solver {
        Solver::Cg => cg::solve(st, model, held, reference, contact_push),
        // A quasi-Newton step takes no linear solve (`backward_euler`).
        Solver::Direct | Solver::QuasiNewton => {
            direct::solve(st, model, held, reference, contact_push)
        }
    }
}

/// `|S b|` over the free rows: the scale the linear tolerance is relative to.
fn filtered_norm(s: &ImplicitScratch, held: &[bool]) -> Scalar {
    deterministic_sum(s.b.len(), |i| {
        if held[i] {
            0.0
        } else {
            without(s.filter[i], s.b[i]).length_squared()
        }
    })
    .sqrt()
}

/// `v` without its component along the unit vector `n` (`v` itself when `n` is zero).
#[inline(always)]
fn without(n: Vector, v: Vector) -> Vector {
    v - n * n.dot(v)
}

/// Chooses the contact filters (module docs) and prescribes the filtered vertices'
/// normal velocity change. `contacts` not matching the mesh (empty, or stale after a
/// remesh) filters nothing.
fn contact_filters(s: &mut ImplicitScratch, contacts: &[Contact], held: &[bool], v: &[Vector]) {
    let n = v.len();
    s.filter.clear();
    s.filter.resize(n, Vector::ZERO);
    if contacts.len() != n {
        return;
    }
    for i in 0..n {
        let c = contacts[i];
        if held[i] || c.normal == Vector::ZERO || (!c.pressed && s.b[i].dot(c.normal) >= 0.0) {
            continue;
        }
        s.filter[i] = c.normal;
        // (v0 + dv) . n = u_n, the tangential part of the warm start kept.
        s.dv[i] = without(c.normal, s.dv[i]) + c.normal * (c.normal_speed - v[i].dot(c.normal));
    }
}
