//! Force evaluation in two parallel phases without atomics:
//! 1. **element pass**: each spring, membrane triangle, hinge and (wind) triangle computes its forces
//!    into its own slots of scratch arrays (the capped sewing springs, `sewing.rs`, are
//!    computed as plain springs and then overwritten);
//! 2. **gather**: each vertex sums its slots in a fixed order (CSR lists), adds its
//!    own forces (gravity, drag), and the integrator uses the sum at once.
//!
//! The result does not depend on the number of threads. A force the scene does not
//! declare is not computed at all: absent wind means no triangle pass, zero
//! bending means no hinges or shape triangles, no drag means no drag term.

use rayon::prelude::*;

use super::bending::dihedral_angle_and_gradient;
use super::elements::Elements;
use super::membrane::MEMBRANE_SLOTS;
use super::sewing::{cap_energy_change, cap_forces};
use super::shape::{EdgeFold, SHAPE_SLOTS, ShapeJacobian, spread};
use crate::math::{Scalar, Vector, deterministic_sum};

/// Element count below which a pass runs on one thread (splitting costs more).
pub(crate) const PAR_MIN: usize = 1024;

/// Row count below which a per-row pass of the direct solver's block matrix
/// runs on one thread (the product by rows, the compensation). Each row sums
/// tens of 3 x 3 blocks, so far fewer rows than [`PAR_MIN`] cheap elements
/// pay for a split: on an adaptive `hanging_sheet_rest` of about 1,200
/// vertices, splitting these passes at 128 rows instead of [`PAR_MIN`] cuts
/// the wall time by 7 % on two cores with an identical summary, and uniform
/// 64 is unchanged. The assembly's per-vertex gather gains nothing from it and
/// stays at `PAR_MIN`.
pub(crate) const PAR_MIN_ROWS: usize = 128;

/// Wind as an aerodynamic pressure on each triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindForce {
    /// Wind velocity, m/s.
    pub velocity: Vector,
    /// Pressure coefficient (dimensionless).
    pub coefficient: Scalar,
    /// Air density, kg/m^3.
    pub air_density: Scalar,
}

/// The external forces a scene declares; `None` means not modelled.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ExternalForces {
    /// Gravitational acceleration, m/s^2.
    pub gravity: Option<Vector>,
    /// Linear air drag per area, kg/(m^2 s).
    pub drag: Option<Scalar>,
    /// Velocity of the air the drag acts against (the wind's, or zero), m/s.
    pub air_velocity: Vector,
    /// Wind pressure.
    pub wind: Option<WindForce>,
}

/// Scratch arrays of the element pass (one slot per element and end).
#[derive(Debug, Default, Clone)]
pub struct ForceScratch {
    /// Force on each spring's first end (the second end gets the opposite).
    pub spring: Vec<Vector>,
    /// Force on each hinge vertex, 4 per hinge.
    pub hinge: Vec<Vector>,
    /// Force on each shape triangle's slots, `SHAPE_SLOTS` per element.
    pub shape: Vec<Vector>,
    /// Force on each membrane triangle's corners, `MEMBRANE_SLOTS` per element.
    pub membrane: Vec<Vector>,
    /// A third of each triangle's wind force (the share of each of its vertices).
    pub triangle: Vec<Vector>,
    /// Each interior edge's fold ([`crate::physics::shape::FoldEdges`]).
    pub edge_folds: Vec<EdgeFold>,
    /// Each shape triangle's three folds.
    pub folds: Vec<[Scalar; 3]>,
    /// Each shape triangle's fold gradients by slot.
    pub fold_gradients: Vec<ShapeJacobian>,
    /// The fold splits at the current folds.
    pub splits: Vec<Scalar>,
}

/// The fold splits that minimise the bending energy at `x` (see
/// [`solve_splits`]); empty without shape triangles.
pub fn splits_at(el: &Elements, x: &[Vector]) -> Vec<Scalar> {
    let (mut folds, mut splits) = (Vec::new(), Vec::new());
    if !el.shape_triangles.is_empty() {
        solve_splits(el, x, &mut folds, &mut splits);
    }
    splits
}

/// Into `folds`, `gradients` and `splits`: each shape triangle's folds at
/// `x` and their gradients by slot, then the splits that minimise the
/// bending energy for them (`shape.rs`, "Splitting the folds"); `edges` is
/// scratch ([`fold_angles`]).
pub fn fold_angles_and_splits(
    el: &Elements,
    x: &[Vector],
    edges: &mut Vec<EdgeFold>,
    folds: &mut Vec<[Scalar; 3]>,
    gradients: &mut Vec<ShapeJacobian>,
    splits: &mut Vec<Scalar>,
) {
    fold_angles(el, x, edges, folds, gradients);
    el.fold_splits.solve(&el.shape_triangles, folds, splits);
}

/// Into `folds` and `gradients`: each shape triangle's folds at `x` and their
/// gradients by slot (the first half of [`fold_angles_and_splits`]), read
/// from each interior edge's fold, computed once into `edges`.
pub fn fold_angles(
    el: &Elements,
    x: &[Vector],
    edges: &mut Vec<EdgeFold>,
    folds: &mut Vec<[Scalar; 3]>,
    gradients: &mut Vec<ShapeJacobian>,
) {
    let shapes = el.shape_triangles.len();
    el.fold_edges.compute(x, edges);
    let edges = &*edges;
    folds.resize(shapes, [0.0; 3]);
    gradients.resize(shapes, [[Vector::ZERO; SHAPE_SLOTS]; 3]);
    folds
        .par_iter_mut()
        .zip(gradients.par_iter_mut())
        .enumerate()
        .with_min_len(PAR_MIN / SHAPE_SLOTS)
        .for_each(|(t, (folds, jac))| (*folds, *jac) = el.fold_edges.angles(t, edges));
}

/// Into `edges` and `folds`: each interior edge's fold at `x` and each shape
/// triangle's folds read from them ([`fold_angles`] without the gradients by
/// slot, which a pass that needs them reads from `edges` with
/// [`super::shape::FoldEdges::angles`]).
pub fn edge_folds(
    el: &Elements,
    x: &[Vector],
    edges: &mut Vec<EdgeFold>,
    folds: &mut Vec<[Scalar; 3]>,
) {
    el.fold_edges.compute(x, edges);
    let edges = &*edges;
    folds.resize(el.shape_triangles.len(), [0.0; 3]);
    folds
        .par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(t, folds)| *folds = el.fold_edges.folds(t, edges));
}

/// Into `folds` and `splits`: each shape triangle's folds at `x` and the
/// splits that minimise the bending energy for them (`shape.rs`, "Splitting
/// the folds").
pub fn solve_splits(
    el: &Elements,
    x: &[Vector],
    folds: &mut Vec<[Scalar; 3]>,
    splits: &mut Vec<Scalar>,
) {
    folds.resize(el.shape_triangles.len(), [0.0; 3]);
    folds
        .par_iter_mut()
        .with_min_len(PAR_MIN)
        .zip(el.shape_triangles.par_iter())
        .for_each(|(f, t)| *f = t.folds(x));
    el.fold_splits.solve(&el.shape_triangles, folds, splits);
}

/// Spring force on the first end `a` (the second end gets the opposite):
/// `(k (l - L) + c (v_b - v_a) . d) d` with `d` the unit vector from a to b.
#[inline(always)]
pub fn spring_force(
    xa: Vector,
    xb: Vector,
    va: Vector,
    vb: Vector,
    rest: Scalar,
    k: Scalar,
    c: Scalar,
) -> Vector {
    let d = xb - xa;
    let len = d.length();
    if len <= 0.0 {
        return Vector::ZERO;
    }
    let dir = d / len;
    dir * (k * (len - rest) + c * (vb - va).dot(dir))
}

/// Wind force share per vertex of triangle `(x0, x1, x2)` with vertex velocities:
/// `F = rho C A (w . n) |w . n| n / 2` for the relative air velocity `w` and the
/// unit normal `n`, split equally over the three vertices.
#[inline]
pub fn wind_share(x: [Vector; 3], v: [Vector; 3], wind: &WindForce) -> Vector {
    let n = (x[1] - x[0]).cross(x[2] - x[0]);
    let twice_area = n.length();
    if twice_area <= 0.0 {
        return Vector::ZERO;
    }
    let unit = n / twice_area;
    let rel = wind.velocity - (v[0] + v[1] + v[2]) / 3.0;
    let wn = rel.dot(unit);
    unit * (wind.air_density * wind.coefficient * 0.5 * twice_area * wn * wn.abs() / 6.0)
}

/// Phase 1: fills `scratch` with every element's forces for state `(x, v)`.
pub fn element_pass(
    el: &Elements,
    ext: &ExternalForces,
    triangles: &[[u32; 3]],
    x: &[Vector],
    v: &[Vector],
    scratch: &mut ForceScratch,
) {
    scratch.spring.resize(el.springs.len(), Vector::ZERO);
    scratch
        .spring
        .par_iter_mut()
        .with_min_len(PAR_MIN)
        .zip(el.springs.par_iter())
        .for_each(|(f, s)| {
            let [a, b] = [s.v[0] as usize, s.v[1] as usize];
            *f = spring_force(x[a], x[b], v[a], v[b], s.rest, s.k, s.c);
        });
    cap_forces(el, x, v, &mut scratch.spring);
    scratch.hinge.resize(4 * el.hinges.len(), Vector::ZERO);
    scratch
        .hinge
        .par_chunks_exact_mut(4)
        .with_min_len(PAR_MIN / 4)
        .zip(el.hinges.par_iter())
        .for_each(|(f, h)| {
            let (theta, g) = dihedral_angle_and_gradient(h.v.map(|i| x[i as usize]));
            for k in 0..4 {
                f[k] = g[k] * (-h.k * theta);
            }
        });
    scratch
        .shape
        .resize(SHAPE_SLOTS * el.shape_triangles.len(), Vector::ZERO);
    fold_angles_and_splits(
        el,
        x,
        &mut scratch.edge_folds,
        &mut scratch.folds,
        &mut scratch.fold_gradients,
        &mut scratch.splits,
    );
    let (folds, jacs, splits) = (&scratch.folds, &scratch.fold_gradients, &scratch.splits);
    scratch
        .shape
        .par_chunks_exact_mut(SHAPE_SLOTS)
        .with_min_len(PAR_MIN / SHAPE_SLOTS)
        .zip(
            el.shape_triangles
                .par_iter()
                .zip(folds.par_iter().zip(jacs.par_iter())),
        )
        .for_each(|(f, (t, (theta, jac)))| spread(jac, t.moments(*theta, splits).map(|c| -c), f));
    scratch
        .membrane
        .resize(MEMBRANE_SLOTS * el.membrane_triangles.len(), Vector::ZERO);
    scratch
        .membrane
        .par_chunks_exact_mut(MEMBRANE_SLOTS)
        .with_min_len(PAR_MIN / MEMBRANE_SLOTS)
        .zip(el.membrane_triangles.par_iter())
        .for_each(|(f, t)| t.forces(x, v, f));
    if let Some(wind) = &ext.wind {
        scratch.triangle.resize(triangles.len(), Vector::ZERO);
        scratch
            .triangle
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(triangles.par_iter())
            .for_each(|(f, t)| {
                *f = wind_share(t.map(|i| x[i as usize]), t.map(|i| v[i as usize]), wind)
            });
    }
}

/// Phase 2 for one vertex: the total force on vertex `i` with velocity `vi`.
#[inline(always)]
pub fn gather(
    el: &Elements,
    ext: &ExternalForces,
    scratch: &ForceScratch,
    i: usize,
    vi: Vector,
) -> Vector {
    let mut f = Vector::ZERO;
    for &s in el.spring_first.of(i) {
        f += scratch.spring[s as usize];
    }
    for &s in el.spring_second.of(i) {
        f -= scratch.spring[s as usize];
    }
    for &s in el.hinge_slots.of(i) {
        f += scratch.hinge[s as usize];
    }
    for &s in el.shape_slots.of(i) {
        f += scratch.shape[s as usize];
    }
    for &s in el.membrane_slots.of(i) {
        f += scratch.membrane[s as usize];
    }
    if ext.wind.is_some() {
        for &t in el.vertex_triangles.of(i) {
            f += scratch.triangle[t as usize];
        }
    }
    if let Some(g) = ext.gravity {
        f += g * el.mass[i];
    }
    if let Some(drag) = ext.drag {
        f -= (vi - ext.air_velocity) * (drag * el.vertex_area[i]);
    }
    f
}

/// Energies of a state, J.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Energy {
    /// Kinetic energy.
    pub kinetic: Scalar,
    /// Gravitational potential energy (zero at the world origin).
    pub gravitational: Scalar,
    /// Elastic energy of springs, membrane triangles, hinges and shape triangles.
    pub elastic: Scalar,
}

impl Energy {
    /// Kinetic + gravitational + elastic.
    pub fn total(&self) -> Scalar {
        self.kinetic + self.gravitational + self.elastic
    }
}

/// Computes the energies of state `(x, v)` with a thread-count independent sum.
pub fn energy(el: &Elements, ext: &ExternalForces, x: &[Vector], v: &[Vector]) -> Energy {
    let kinetic = deterministic_sum(x.len(), |i| 0.5 * el.mass[i] * v[i].length_squared());
    let gravitational = match ext.gravity {
        Some(g) => deterministic_sum(x.len(), |i| -el.mass[i] * g.dot(x[i])),
        None => 0.0,
    };
    let stretch = deterministic_sum(el.springs.len(), |s| {
        let sp = &el.springs[s];
        let stretch = x[sp.v[1] as usize].distance(x[sp.v[0] as usize]) - sp.rest;
        0.5 * sp.k * stretch * stretch
    });
    // The capped sewing springs' energy is Huber, not quadratic (`sewing.rs`).
    let stretch = if el.sewing_caps.is_empty() {
        stretch
    } else {
        stretch + cap_energy_change(el, x)
    };
    let bend = deterministic_sum(el.hinges.len(), |h| {
        let hg = &el.hinges[h];
        let (theta, _) = dihedral_angle_and_gradient(hg.v.map(|i| x[i as usize]));
        0.5 * hg.k * theta * theta
    });
    let splits = splits_at(el, x);
    let shape = deterministic_sum(el.shape_triangles.len(), |t| {
        el.shape_triangles[t].energy(x, &splits)
    });
    let membrane = deterministic_sum(el.membrane_triangles.len(), |t| {
        el.membrane_triangles[t].energy(x)
    });
    Energy {
        kinetic,
        gravitational,
        elastic: stretch + membrane + bend + shape,
    }
}
