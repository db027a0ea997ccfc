//! Force evaluation in two parallel phases without atomics:
//! 1. **element pass**: each element of every kind (`kinds.rs`: springs, hinges,
//!    shape triangles, membrane triangles) and each (wind) triangle computes its
//!    forces into its own slots of scratch arrays;
//! 2. **gather**: each vertex sums its slots in a fixed order (kind by kind, each
//!    kind's CSR lists), adds its own forces (gravity, drag), and the integrator
//!    uses the sum at once.
//!
//! The result does not depend on the number of threads. A force the scene does not
//! declare is not computed at all: absent wind means no triangle pass, zero
//! bending means no hinges or shape triangles, no drag means no drag term.

use rayon::prelude::*;

use super::elements::Elements;
use super::kinds::{KindForces, elastic_energy};
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
    /// Every force element kind's slots ([`super::kinds`]).
    pub kinds: KindForces,
    /// A third of each triangle's wind force (the share of each of its vertices).
    pub triangle: Vec<Vector>,
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
    scratch.kinds.compute(el, x, v);
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
    scratch.kinds.gather(el, i, &mut f);
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
    Energy {
        kinetic,
        gravitational,
        elastic: elastic_energy(el, x),
    }
}
