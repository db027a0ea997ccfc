//! The springs kind: stretch springs, hinge springs and sewing springs, one
//! force slot per spring (the force on its first end; the second end gets the
//! opposite). The capped sewing springs (`sewing.rs`) are computed as plain
//! springs and then overwritten with their capped force, energy and blocks.

use rayon::prelude::*;

use super::ForceKind;
use crate::math::{Matrix3, Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;
use crate::physics::block::outer;
use crate::physics::elements::{BuildContext, Elements, Incidence, MaterialParams, level_factor};
use crate::physics::forces::{PAR_MIN, spring_force};
use crate::physics::membrane::Membrane;
use crate::physics::sewing::{
    SpringCap, cap_energy_change, cap_force, cap_forces, capped_spring_force,
    capped_spring_stiffness, sewing_springs,
};
use crate::spec::{BendingModel, StiffnessRule};

/// The springs kind: the springs of [`SpringSet`] (with their caps).
#[derive(Debug, Clone, Copy, Default)]
pub struct Springs;
/// A linear spring with damping along its axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// End vertices `[a, b]`.
    pub v: [u32; 2],
    /// Rest length, m.
    pub rest: Scalar,
    /// Stiffness, N/m.
    pub k: Scalar,
    /// Damping coefficient, N s/m.
    pub c: Scalar,
}

/// The springs of one mesh and their incidence lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpringSet {
    /// Stretch springs (one per edge, with [`Membrane::Springs`]), then hinge
    /// springs when that bending model is on, then the sewing springs of a
    /// garment's open seams.
    pub springs: Vec<Spring>,
    /// The sewing springs with a maximum force, in spring order (empty unless a
    /// seam has `max_force`; `sewing.rs`).
    pub caps: Vec<SpringCap>,
    /// Springs where the vertex is the first end (`v[0]`).
    pub first: Incidence,
    /// Springs where the vertex is the second end (`v[1]`).
    pub second: Incidence,
}

/// One stretch spring per edge (`elements.rs`, "Stiffness derivations") with
/// the springs membrane, none with the triangles; `area` is each triangle's
/// rest area.
fn stretch_springs(mesh: &Mesh, mat: &MaterialParams, area: &[Scalar], springs: &mut Vec<Spring>) {
    springs.clear();
    if mat.membrane != Membrane::Springs {
        return;
    }
    for (e, edge) in mesh.edges.iter().enumerate() {
        let rest = mesh.rest_length(e);
        let tris = edge
            .triangles
            .iter()
            .filter(|&&t| t != crate::mesh::NO_TRIANGLE);
        let level = tris
            .clone()
            .map(|&t| mesh.levels[t as usize])
            .max()
            .unwrap_or(0);
        let k = match mat.stiffness_rule {
            StiffnessRule::Consistent => {
                mat.stretch * tris.map(|&t| area[t as usize]).sum::<Scalar>() / (rest * rest)
            }
            StiffnessRule::PaperA => mat.stretch * level_factor(mat.stiffness_rule, level),
        };
        springs.push(Spring {
            v: edge.vertices,
            rest,
            k,
            c: mat.damping * k,
        });
    }
}

/// A spring between the two wing tips of each interior edge with the
/// hinge-spring bending model and non-zero rigidity, appended to `springs`
/// (`elements.rs`, "Stiffness derivations").
fn hinge_springs(mesh: &Mesh, mat: &MaterialParams, springs: &mut Vec<Spring>) {
    if mat.bending <= 0.0 || mat.bending_model != BendingModel::HingeSpring {
        return;
    }
    for (e, edge) in mesh
        .edges
        .iter()
        .enumerate()
        .filter(|(_, e)| e.is_interior())
    {
        let [t0, t1] = edge.triangles;
        let (p, q) = (
            mesh.opposite_vertex(t0, edge),
            mesh.opposite_vertex(t1, edge),
        );
        let level = mesh.levels[t0 as usize].max(mesh.levels[t1 as usize]);
        let rest = tip_distance(mesh, e);
        let k = mat.bending / (rest * rest) * level_factor(mat.stiffness_rule, level);
        springs.push(Spring {
            v: [p, q],
            rest,
            k,
            c: mat.damping * k,
        });
    }
}

/// The rest distance between the wing tips of interior edge `e`. On a garment the
/// second wing may lie in another panel's pattern: it is unfolded into the first
/// wing's pattern about their shared edge ([`Mesh::unfold`]).
fn tip_distance(mesh: &Mesh, e: usize) -> Scalar {
    let edge = &mesh.edges[e];
    let [t0, t1] = edge.triangles;
    let (p, q) = (
        mesh.opposite_vertex(t0, edge),
        mesh.opposite_vertex(t1, edge),
    );
    if mesh.panels().is_none() {
        return mesh.material[p as usize].distance(mesh.material[q as usize]);
    }
    let (t0, t1) = (t0 as usize, t1 as usize);
    let unfolded = mesh.unfold(t0, t1, edge.vertices, q);
    mesh.corner_at(t0, p).distance(unfolded)
}

/// The springs' terms of the linearised step.
#[derive(Debug, Default, Clone)]
pub struct SpringLinear {
    /// Per spring: `h^2 K_e + h D_e`.
    pub block: Vec<Matrix3>,
    /// Per spring: its right-hand side slot, then its slot of a product.
    pub slot: Vec<Vector>,
}

impl ForceKind for Springs {
    type Set = SpringSet;
    type Deferred = ();
    type Forces = Vec<Vector>;
    type Linear = SpringLinear;
    type Kick = Vec<Vector>;
    type InPlace = ();
    const ENERGY_RANK: usize = 0;

    /// Stretch springs, then hinge springs, then sewing springs, and their
    /// ends' incidence lists.
    fn build(cx: &BuildContext<'_>, set: &mut SpringSet) {
        let (mesh, mat) = (cx.mesh, cx.mat);
        stretch_springs(mesh, mat, cx.area, &mut set.springs);
        hinge_springs(mesh, mat, &mut set.springs);
        sewing_springs(mesh, mat, &mut set.springs, &mut set.caps);
        let n = mesh.vertex_count();
        let springs = &set.springs;
        let ends = |end: usize| {
            let pairs = springs.iter().enumerate();
            pairs.map(move |(s, sp)| (sp.v[end], s as u32))
        };
        set.first.fill(n, ends(0));
        set.second.fill(n, ends(1));
    }

    fn count(el: &Elements) -> usize {
        el.kinds.springs.springs.len()
    }

    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend(el.kinds.springs.springs[e].v);
    }

    /// The capped sewing springs among `ids` get their capped force
    /// ([`SpringSet::caps`] is in spring order).
    fn kick(
        el: &Elements,
        ids: &[u32],
        x: &[Vector],
        v: &[Vector],
        out: &mut Vec<Vector>,
        kick: &mut Vec<Vector>,
    ) {
        let caps = &el.kinds.springs.caps;
        ids.par_iter()
            .with_min_len(512)
            .map(|&s| match caps.binary_search_by_key(&s, |c| c.spring) {
                Ok(c) => cap_force(el, &caps[c], x, v),
                Err(_) => {
                    let sp = &el.kinds.springs.springs[s as usize];
                    let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
                    spring_force(x[a], x[b], v[a], v[b], sp.rest, sp.k, sp.c)
                }
            })
            .collect_into_vec(kick);
        for (&s, &f) in ids.iter().zip(kick.iter()) {
            out[s as usize] = f;
        }
    }

    fn size_forces(el: &Elements, out: &mut Vec<Vector>) {
        out.resize(el.kinds.springs.springs.len(), Vector::ZERO);
    }

    fn forces(el: &Elements, x: &[Vector], v: &[Vector], out: &mut Vec<Vector>) {
        Self::size_forces(el, out);
        out.par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(el.kinds.springs.springs.par_iter())
            .for_each(|(f, s)| {
                let [a, b] = [s.v[0] as usize, s.v[1] as usize];
                *f = spring_force(x[a], x[b], v[a], v[b], s.rest, s.k, s.c);
            });
        cap_forces(el, x, v, out);
    }

    #[inline(always)]
    fn gather_force(el: &Elements, out: &Vec<Vector>, i: usize, f: &mut Vector) {
        for &s in el.kinds.springs.first.of(i) {
            *f += out[s as usize];
        }
        for &s in el.kinds.springs.second.of(i) {
            *f -= out[s as usize];
        }
    }

    fn energy(el: &Elements, x: &[Vector]) -> Scalar {
        let stretch = deterministic_sum(el.kinds.springs.springs.len(), |s| {
            let sp = &el.kinds.springs.springs[s];
            let stretch = x[sp.v[1] as usize].distance(x[sp.v[0] as usize]) - sp.rest;
            0.5 * sp.k * stretch * stretch
        });
        // The capped sewing springs' energy is Huber, not quadratic (`sewing.rs`).
        if el.kinds.springs.caps.is_empty() {
            stretch
        } else {
            stretch + cap_energy_change(el, x)
        }
    }

    /// Per spring: the block `h^2 K_e + h D_e` and the slot `h f_e - h^2 K_e (v_a - v_b)`.
    fn linearise(
        el: &Elements,
        x: &[Vector],
        v: &[Vector],
        h: Scalar,
        k_term: Scalar,
        lin: &mut SpringLinear,
    ) {
        lin.block
            .resize(el.kinds.springs.springs.len(), Matrix3::ZERO);
        lin.slot
            .resize(el.kinds.springs.springs.len(), Vector::ZERO);
        lin.block
            .par_iter_mut()
            .zip(lin.slot.par_iter_mut())
            .zip(el.kinds.springs.springs.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|((block, slot), sp)| {
                let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
                let f = spring_force(x[a], x[b], v[a], v[b], sp.rest, sp.k, sp.c);
                let d = x[b] - x[a];
                let (len, nn) = axis(d);
                let transverse = if len > 0.0 {
                    (1.0 - sp.rest / len).max(0.0)
                } else {
                    0.0
                };
                let stiff = (nn + (Matrix3::IDENTITY - nn) * transverse) * sp.k;
                (*block, *slot) = spring_terms(f, stiff, nn, sp.c, v[a] - v[b], h, k_term);
            });
        capped_springs(lin, el, x, v, h, k_term);
    }

    #[inline(always)]
    fn gather_linear(
        el: &Elements,
        lin: &SpringLinear,
        i: usize,
        _h: Scalar,
        jacobi: bool,
        rhs: &mut Vector,
        diag: &mut Vector,
    ) {
        for &e in el.kinds.springs.first.of(i) {
            *rhs += lin.slot[e as usize];
            if jacobi {
                *diag += matrix_diagonal(&lin.block[e as usize]);
            }
        }
        for &e in el.kinds.springs.second.of(i) {
            *rhs -= lin.slot[e as usize];
            if jacobi {
                *diag += matrix_diagonal(&lin.block[e as usize]);
            }
        }
    }

    fn product(el: &Elements, lin: &mut SpringLinear, p: &[Vector], _h2: Scalar) {
        lin.slot
            .par_iter_mut()
            .zip(lin.block.par_iter())
            .zip(el.kinds.springs.springs.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|((q, block), sp)| {
                *q = *block * (p[sp.v[0] as usize] - p[sp.v[1] as usize]);
            });
    }

    #[inline(always)]
    fn gather_product(el: &Elements, lin: &SpringLinear, i: usize, acc: &mut Vector) {
        for &e in el.kinds.springs.first.of(i) {
            *acc += lin.slot[e as usize];
        }
        for &e in el.kinds.springs.second.of(i) {
            *acc -= lin.slot[e as usize];
        }
    }

    fn coupling_count(el: &Elements) -> usize {
        2 * el.kinds.springs.springs.len()
    }

    fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>) {
        for sp in &el.kinds.springs.springs {
            let [a, b] = sp.v;
            pairs.extend([(a, b), (b, a)]);
        }
    }

    /// One value per spring, its block: added on both ends' diagonal blocks
    /// and subtracted off it.
    fn listed_blocks(el: &Elements, mut f: impl FnMut(u32, u32, u32, bool)) {
        for (e, sp) in el.kinds.springs.springs.iter().enumerate() {
            let ([a, b], e) = (sp.v, e as u32);
            f(a, a, e, false);
            f(b, b, e, false);
            f(a, b, e, a != b);
        }
    }

    fn block_values(lin: &SpringLinear) -> &[Matrix3] {
        &lin.block
    }

    /// A spring's ends: the factorization keeps its coupling.
    fn factored_pairs(el: &Elements, mut f: impl FnMut(u32, u32)) {
        for sp in &el.kinds.springs.springs {
            let [a, b] = sp.v;
            f(a, b);
            f(b, a);
        }
    }

    fn gershgorin(
        el: &Elements,
        _mesh: &Mesh,
        _flat: &mut [Vector],
        stiff: &mut [Scalar],
        damp: &mut [Scalar],
    ) {
        for s in &el.kinds.springs.springs {
            for &v in &s.v {
                stiff[v as usize] += 2.0 * s.k;
                damp[v as usize] += 2.0 * s.c;
            }
        }
    }
}

/// The length of a spring's separation `d` and the projector `n n^T` on its
/// axis (zero for coincident ends).
#[inline(always)]
fn axis(d: Vector) -> (Scalar, Matrix3) {
    let len = d.length();
    let dir = if len > 0.0 { d / len } else { Vector::ZERO };
    (len, outer(dir, dir))
}

/// The block `h^2 K + h c n n^T` and the slot `h f - h^2 K (v_a - v_b)` of a
/// spring with force `f` on its first end, stiffness `K`, axis projector
/// `nn = n n^T`, damping coefficient `c` and relative velocity `dv = v_a - v_b`.
#[inline(always)]
fn spring_terms(
    f: Vector,
    stiff: Matrix3,
    nn: Matrix3,
    c: Scalar,
    dv: Vector,
    h: Scalar,
    k_term: Scalar,
) -> (Matrix3, Vector) {
    let block = stiff * (h * h) + nn * (h * c);
    (block, f * h - stiff * dv * (h * h * k_term))
}

/// The capped sewing springs' blocks and slots over the plain ones the pass
/// above wrote (their force and stiffness of the Huber energy, `sewing.rs`).
fn capped_springs(
    lin: &mut SpringLinear,
    el: &Elements,
    x: &[Vector],
    v: &[Vector],
    h: Scalar,
    k_term: Scalar,
) {
    for cap in &el.kinds.springs.caps {
        let e = cap.spring as usize;
        let sp = &el.kinds.springs.springs[e];
        let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
        let d = x[b] - x[a];
        let (_, nn) = axis(d);
        let f = capped_spring_force(x[a], x[b], v[a], v[b], sp.k, sp.c, cap.max_force);
        let stiff = capped_spring_stiffness(d, sp.k, cap.max_force);
        (lin.block[e], lin.slot[e]) = spring_terms(f, stiff, nn, sp.c, v[a] - v[b], h, k_term);
    }
}

/// The diagonal of a 3 x 3 matrix.
#[inline(always)]
pub(crate) fn matrix_diagonal(m: &Matrix3) -> Vector {
    Vector::new(m.x_axis.x, m.y_axis.y, m.z_axis.z)
}
