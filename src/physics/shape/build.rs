//! Building the shape triangles of a mesh: each triangle's stencil (its corners,
//! the tips across its interior edges, its neighbours and its share of each
//! fold), then its constant matrix `M` (module docs of [`super`]), computed
//! afresh or kept from the elements of the mesh before a remesh
//! (`crate::physics::elements`, "Incremental rebuild").

use super::ShapeTriangle;
use crate::math::{Matrix3, Scalar, Vector, Vector2};
use crate::mesh::Mesh;

/// A shape triangle's `M`.
pub(crate) type ShapeMatrix = [[Scalar; 3]; 3];

/// Scratch memory of [`build_shape_triangles_into`], kept between builds.
#[derive(Debug, Default, Clone)]
pub(crate) struct ShapeScratch {
    /// Per triangle: its stencil (`m` still zero).
    stencil: Vec<ShapeTriangle>,
    /// Per triangle: the neighbour across each edge (`usize::MAX`: boundary).
    across: Vec<[usize; 3]>,
    /// Per triangle: twice its part of each edge's fold.
    share: Vec<[Scalar; 3]>,
}

/// Into `out` (cleared first): one shape triangle per mesh triangle not held by
/// a clamp, for rigidity `bending` (rest areas `area`; `clamped`: per vertex the
/// pin holding it for good or `u32::MAX`, or empty for no clamp). `kept(t,
/// stencil, across)` may offer a matrix for triangle `t` given its stencil (`m`
/// zero) and its neighbours: `Some` is used as it is, `None` computes it. Only a
/// matrix computed from the same stencil may be offered (the caller checks it).
pub(crate) fn build_shape_triangles_into(
    mesh: &Mesh,
    area: &[Scalar],
    bending: Scalar,
    clamped: &[u32],
    scratch: &mut ShapeScratch,
    mut kept: impl FnMut(usize, &ShapeTriangle, &[usize; 3]) -> Option<ShapeMatrix>,
    out: &mut Vec<ShapeTriangle>,
) {
    let held = |t: usize| {
        let [a, b, c] = mesh.triangles[t].map(|v| clamped.get(v as usize).copied());
        a.is_some_and(|p| p != u32::MAX) && a == b && b == c
    };
    let n = mesh.triangles.len();
    let ShapeScratch {
        stencil,
        across,
        share,
    } = scratch;
    stencil.clear();
    stencil.extend(mesh.triangles.iter().map(|tri| ShapeTriangle {
        v: [tri[0], tri[1], tri[2], tri[0], tri[1], tri[2]],
        interior: [false; 3],
        m: [[0.0; 3]; 3],
    }));
    across.clear();
    across.resize(n, [usize::MAX; 3]);
    share.clear();
    share.resize(n, [1.0; 3]);
    for e in mesh.edges.iter().filter(|e| e.is_interior()) {
        for (side, other) in [(0, 1), (1, 0)] {
            let (t, o) = (e.triangles[side] as usize, e.triangles[other]);
            let tri = mesh.triangles[t];
            let a = (0..3)
                .find(|&a| !e.vertices.contains(&tri[a]))
                .expect("an edge's triangle has a vertex off the edge");
            stencil[t].v[3 + a] = mesh.opposite_vertex(o, e);
            stencil[t].interior[a] = true;
            across[t][a] = o as usize;
            // Twice the triangle's part of the fold (shape module docs, "Sharing"):
            // all of it next to a clamp, else in proportion to area.
            share[t][a] = if held(o as usize) {
                2.0
            } else {
                2.0 * area[t] / (area[t] + area[o as usize])
            };
        }
    }
    out.clear();
    for t in (0..n).filter(|&t| !held(t)) {
        let mut st = stencil[t];
        st.m = match kept(t, &st, &across[t]) {
            Some(m) => m,
            None => {
                // Refinement transitions (shape module docs, "Transitions"): a triangle
                // with all three edges interior next to a free triangle of
                // another level.
                let o = across[t];
                let transition = o.iter().all(|&o| o != usize::MAX)
                    && o.iter()
                        .any(|&o| !held(o) && mesh.levels[o] != mesh.levels[t]);
                if transition {
                    transition_m(mesh, t, o, o.map(held), share[t], area[t], bending)
                } else {
                    shared_m(mesh, t, share[t], area[t], bending)
                }
            }
        };
        out.push(st);
    }
}

/// `M` of triangle `t` away from transitions: `(B / (4 A)) L_a L_b (t_a . t_b)^2`
/// times the triangle's shares of the two folds.
fn shared_m(
    mesh: &Mesh,
    t: usize,
    share: [Scalar; 3],
    area: Scalar,
    bending: Scalar,
) -> ShapeMatrix {
    let p = mesh.triangles[t].map(|v| mesh.material[v as usize]);
    // Edge a runs from vertex a+1 to a+2.
    let e: [Vector2; 3] = [0, 1, 2].map(|a| p[(a + 2) % 3] - p[(a + 1) % 3]);
    let len = e.map(|v| v.length());
    let mut m = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            // (t_a . t_b)^2 = (e_a . e_b)^2 / (L_a L_b)^2.
            let c = e[a].dot(e[b]) / (len[a] * len[b]);
            m[a][b] = bending / (4.0 * area) * len[a] * len[b] * c * c;
            m[a][b] *= share[a] * share[b];
        }
    }
    m
}

/// A symmetric 2 x 2 tensor as `[xx, yy, xy]`.
type Sym = [Scalar; 3];

/// The 3 x 3 matrix with these rows (glam's matrices are built from columns).
fn from_rows(rows: [[Scalar; 3]; 3]) -> Matrix3 {
    Matrix3::from_cols_array_2d(&rows).transpose()
}

/// Pseudo-inverse of `a` (regularised: `(a^T a + eps I)^-1 a^T` with `eps`
/// 1e-9 of the trace), so that directions `a` does not see (or barely sees) are
/// left alone rather than amplified.
fn pseudo_inverse(a: Matrix3) -> Matrix3 {
    let g = a.transpose() * a;
    let eps = 1e-9 * (g.x_axis.x + g.y_axis.y + g.z_axis.z);
    (g + Matrix3::from_diagonal(Vector::splat(eps))).inverse() * a.transpose()
}

/// `M` of a transition triangle (shape module docs, "Transitions"): the shape operator
/// `S = P theta` with `P = C + (I - C Theta) Theta^+`, where `C` is the shared-fold
/// operator of the other triangles and `Theta` maps a constant curvature tensor
/// to the three folds the triangle and its neighbours `across` give it; then
/// `M = B A P^T W P` with `W = diag(1, 1, 2)` (the Frobenius norm of `[xx, yy, xy]`).
fn transition_m(
    mesh: &Mesh,
    t: usize,
    across: [usize; 3],
    held: [bool; 3],
    share: [Scalar; 3],
    area: Scalar,
    bending: Scalar,
) -> [[Scalar; 3]; 3] {
    let corners = |t: usize| mesh.triangles[t].map(|v| mesh.material[v as usize]);
    let p = corners(t);
    let origin = (p[0] + p[1] + p[2]) / 3.0;
    let local = |q: [Vector2; 3]| q.map(|v| v - origin);
    let p = local(p);
    let e: [Vector2; 3] = [0, 1, 2].map(|a| p[(a + 2) % 3] - p[(a + 1) % 3]);
    // Outward in-plane unit normals (the triangle is counter-clockwise).
    let n = e.map(|v| Vector2::new(v.y, -v.x) / v.length());
    // C: S = C theta.
    let mut c = [[0.0; 3]; 3];
    for a in 0..3 {
        let q: Sym = [n[a].x * n[a].x, n[a].y * n[a].y, n[a].x * n[a].y];
        for k in 0..3 {
            c[k][a] = share[a] * e[a].length() * q[k] / (2.0 * area);
        }
    }
    // Theta: the folds of the linear interpolant of f = x^T H x / 2 for the
    // three unit tensors H; a held neighbour keeps the tangent plane of f at the
    // edge's midpoint (the clamp is flat where the free sheet leaves it).
    let hx = |h: Sym, x: Vector2| Vector2::new(h[0] * x.x + h[2] * x.y, h[2] * x.x + h[1] * x.y);
    let grad = |q: [Vector2; 3], h: Sym| {
        let f = q.map(|x| 0.5 * x.dot(hx(h, x)));
        let (d1, d2) = (q[1] - q[0], q[2] - q[0]);
        let (f1, f2) = (f[1] - f[0], f[2] - f[0]);
        let det = d1.perp_dot(d2);
        Vector2::new(f1 * d2.y - f2 * d1.y, d1.x * f2 - d2.x * f1) / det
    };
    let mut theta = [[0.0; 3]; 3];
    for j in 0..3 {
        let mut h = [0.0; 3];
        h[j] = 1.0;
        let own = grad(p, h);
        for a in 0..3 {
            let other = if held[a] {
                hx(h, 0.5 * (p[(a + 1) % 3] + p[(a + 2) % 3]))
            } else {
                grad(local(corners(across[a])), h)
            };
            theta[a][j] = n[a].dot(other - own);
        }
    }
    let (c, theta) = (from_rows(c), from_rows(theta));
    let p = c + (Matrix3::IDENTITY - c * theta) * pseudo_inverse(theta);
    let w = Matrix3::from_diagonal(Vector::new(1.0, 1.0, 2.0));
    ((bending * area) * p.transpose() * w * p)
        .transpose()
        .to_cols_array_2d()
}
