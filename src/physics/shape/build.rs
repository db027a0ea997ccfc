//! Building the shape triangles of a mesh: each triangle's stencil (its corners,
//! the tips across its interior edges, its neighbours and its share of each
//! fold), then its constant matrix `M` (module docs of [`super`]), computed
//! afresh or kept from the elements of the mesh before a remesh
//! (`crate::physics::elements`, "Incremental rebuild").

use super::{NO_SPLIT, ShapeTriangle};
use crate::math::{Scalar, Vector2};
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
    /// Per triangle: no corner thinner than [`SPLIT_MIN_ANGLE_DEG`], so its
    /// edges may take split unknowns.
    wide: Vec<bool>,
}

/// Into `out` (cleared first): one shape triangle per mesh triangle not held by
/// a clamp, for rigidity `bending` (rest areas `area`; `clamped`: per vertex the
/// pin holding it for good or `u32::MAX`, or empty for no clamp). `kept(t,
/// stencil, across)` may offer a matrix for triangle `t` given its stencil (`m`
/// zero) and its neighbours: `Some` is used as it is, `None` computes it. Only a
/// matrix computed from the same stencil may be offered (the caller checks it).
/// Returns the number of split unknowns the triangles' `split` indices run over.
pub(crate) fn build_shape_triangles_into(
    mesh: &Mesh,
    area: &[Scalar],
    bending: Scalar,
    clamped: &[u32],
    scratch: &mut ShapeScratch,
    mut kept: impl FnMut(usize, &ShapeTriangle, &[usize; 3]) -> Option<ShapeMatrix>,
    out: &mut Vec<ShapeTriangle>,
) -> usize {
    let held = |t: usize| {
        let [a, b, c] = mesh.triangles[t].map(|v| clamped.get(v as usize).copied());
        a.is_some_and(|p| p != u32::MAX) && a == b && b == c
    };
    let n = mesh.triangles.len();
    stencils(mesh, area, &held, scratch);
    let splits = number_splits(mesh, &held, scratch);
    let ShapeScratch {
        stencil,
        across,
        share,
        ..
    } = scratch;
    out.clear();
    for t in (0..n).filter(|&t| !held(t)) {
        let mut st = stencil[t];
        st.share = [0, 1, 2].map(|a| {
            if st.interior[a] {
                0.5 * share[t][a]
            } else {
                0.0
            }
        });
        st.k = plate_k(mesh, t, area[t], bending);
        st.m = match kept(t, &st, &across[t]) {
            Some(m) => m,
            // The energy at zero splits: `M_ab = share_a share_b K_ab`.
            None => [0, 1, 2].map(|a| [0, 1, 2].map(|b| st.share[a] * st.share[b] * st.k[a][b])),
        };
        out.push(st);
    }
    splits as usize
}

/// Into `scratch`: each triangle's stencil (`m` zero), its neighbours, twice
/// its part of each edge's fold and whether it is wide enough to take split
/// unknowns; `held(t)` says whether a clamp holds triangle `t`.
fn stencils(
    mesh: &Mesh,
    area: &[Scalar],
    held: &impl Fn(usize) -> bool,
    scratch: &mut ShapeScratch,
) {
    let n = mesh.triangles.len();
    let ShapeScratch {
        stencil,
        across,
        share,
        wide,
    } = scratch;
    stencil.clear();
    stencil.extend(mesh.triangles.iter().map(|tri| ShapeTriangle {
        v: [tri[0], tri[1], tri[2], tri[0], tri[1], tri[2]],
        interior: [false; 3],
        m: [[0.0; 3]; 3],
        k: [[0.0; 3]; 3],
        share: [0.0; 3],
        split: [NO_SPLIT; 3],
        split_sign: [0.0; 3],
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
    wide.clear();
    wide.extend((0..n).map(|t| min_angle(mesh, t) >= SPLIT_MIN_ANGLE_DEG));
}

/// Numbers the split unknowns of the edges that take one into the stencils'
/// `split` and `split_sign`; returns their count.
fn number_splits(mesh: &Mesh, held: &impl Fn(usize) -> bool, scratch: &mut ShapeScratch) -> u32 {
    let ShapeScratch { stencil, wide, .. } = scratch;
    let mut splits = 0u32;
    for e in &mesh.edges {
        // The edge's triangles not held by a clamp, with the sign of their part.
        let mut free = [(0usize, 0.0); 2];
        let mut count = 0;
        for (&t, sign) in e.triangles.iter().zip([1.0, -1.0]) {
            if t != crate::mesh::NO_TRIANGLE && !held(t as usize) {
                free[count] = (t as usize, sign);
                count += 1;
            }
        }
        let free = &free[..count];
        // Both sides free, or a free edge of the cloth (its one triangle's part is
        // a free unknown: module docs, "Free edges"), and no triangle thin
        // (module docs, "Thin triangles").
        let free_edge = free.len() == 1 && e.triangles.contains(&crate::mesh::NO_TRIANGLE);
        let split = (free.len() == 2 || free_edge) && free.iter().all(|&(t, _)| wide[t]);
        if !split {
            continue;
        }
        for &(t, sign) in free {
            let tri = mesh.triangles[t];
            let a = (0..3)
                .find(|&a| !e.vertices.contains(&tri[a]))
                .expect("an edge's triangle has a vertex off the edge");
            stencil[t].split[a] = splits;
            stencil[t].split_sign[a] = sign;
        }
        splits += 1;
    }
    splits
}

/// The smallest corner angle (degrees, material space) of a triangle whose
/// edges take split unknowns (module docs of [`super`], "Thin triangles").
pub const SPLIT_MIN_ANGLE_DEG: Scalar = 15.0;

/// The smallest corner angle of triangle `t` in material space, degrees.
fn min_angle(mesh: &Mesh, t: usize) -> Scalar {
    let p = mesh.corners(t);
    (0..3)
        .map(|a| {
            let (u, w) = (p[(a + 1) % 3] - p[a], p[(a + 2) % 3] - p[a]);
            u.perp_dot(w).abs().atan2(u.dot(w)).to_degrees()
        })
        .fold(Scalar::INFINITY, Scalar::min)
}

/// The plate matrix `K_ab = (B / A) L_a L_b (n_a . n_b)^2` of triangle `t`
/// (edge `a` runs from its vertex `a + 1` to `a + 2`; `(n_a . n_b)^2 =
/// (e_a . e_b)^2 / (L_a L_b)^2`).
fn plate_k(mesh: &Mesh, t: usize, area: Scalar, bending: Scalar) -> ShapeMatrix {
    let p = mesh.corners(t);
    let e: [Vector2; 3] = [0, 1, 2].map(|a| p[(a + 2) % 3] - p[(a + 1) % 3]);
    let len = e.map(|v| v.length());
    let mut k = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            let c = e[a].dot(e[b]) / (len[a] * len[b]);
            k[a][b] = bending / area * len[a] * len[b] * c * c;
        }
    }
    k
}
