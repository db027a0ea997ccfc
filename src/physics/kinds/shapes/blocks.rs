//! The shape triangles' blocks in the direct solver's assembly, added in place
//! band by band ([`crate::physics::kinds::ForceKind::add_in_place`]) with the
//! compensation of those the factorization drops.
//!
//! The shape triangles are the bulk (21 blocks each, against 3 per spring).
//! Summed per block from the Jacobians, a triangle's products `sum_b M_ab
//! J_bl` would be formed again for every block it adds to, and once more for
//! the compensation (`perf` put two thirds of a shape-operator sheet's
//! assembly there). Formed once per triangle but written to a flat array like
//! the hinges' listed blocks, its blocks would cost 12 MB of memory traffic a
//! step at 4,096 vertices, and gathering them took as long as computing them
//! (measured). Added in place, they go straight into the band's blocks, which
//! stay in the cache; a triangle with slots in two bands forms its products in
//! both (a third of the triangles, with bands of 512 rows on a 65 x 65 grid).
//!
//! Each triangle with a slot in the band, in triangle order, forms its
//! products once and adds its blocks `h^2 sum_a J_ak (M J)_al^T` with their
//! row in the band straight into them, by its precomputed slots, and the
//! compensation of each dropped block into the diagonal compensation of both
//! its vertices that lie in the band (the lower block serves its transpose
//! too). A triangle's Jacobian is read from its edges' folds.
//!
//! A dropped block `B` (pair of used slots on distinct vertices whose block is
//! not factored: with the exact matrix, the second-ring pairs below) is the
//! rank-one `u w^T` of the first-ring matrix below, and it compensates with
//! the same lumps, `(|w| / |u|) u u^T` and `(|u| / |w|) w w^T`, on the
//! diagonals of its two vertices: with `B`'s pair left out, the factored
//! matrix is `A` plus the positive semi-definite `z z^T` of each dropped
//! block, so it stays positive definite. The lumps add stiffness only along
//! `u` and `w`, where the norm `|B| I` on both diagonals (also positive
//! semi-definite) adds it in every direction: on the uniform 128 hanging
//! sheet at 5 ms steps, the lumps' factor needs 912 CG iterations over 105
//! solves against the norms' 1,106 (`docs/model.md`, "Which factor").
//!
//! # The first-ring matrix
//! With [`crate::spec::BendingMatrix::FirstRing`] (`lump_second_ring`) the
//! matrix itself leaves out a triangle's second-ring blocks, those that join
//! the tip across edge `a` to the triangle's own vertex `a` or to another
//! tip: vertices that no mesh edge joins, which widen the stencil from a
//! vertex's edge neighbours to their neighbours too. Each such block
//! involves a tip `t = 3 + a`, which moves angle `a` alone, so it is the
//! rank-one `B = u w^T` with `u = J_at` (the tip's gradient) and `w = h^2
//! (M J)_ao` (the other slot's). It is lumped onto the two diagonal blocks
//! as `(|w| / |u|) u u^T` on the tip's and `(|u| / |w|) w w^T` on the other
//! vertex's: with `B`'s pair this is the positive semi-definite `z z^T`,
//! `z = (sqrt(s) u, -w / sqrt(s))`, `s = |w| / |u|`, so the lumped matrix is
//! the exact one plus a positive semi-definite term: positive definite, and
//! stiffer only along the folds' gradients (the cloth's normals). The
//! pattern then has no second-ring blocks, the factor needs no compensation
//! for them and a fresh factor is exact.

use crate::math::{Matrix3, Scalar, Vector};
use crate::physics::block::{BAND_ROWS, Band, BlockPattern, group_by_key, outer};
use crate::physics::elements::Elements;
use crate::physics::shape::{SHAPE_SLOTS, ShapeJacobian, ShapeTriangle};

/// One lower block `(k, l)` (slots) of a shape triangle, which the assembly
/// computes and adds to block `slot`; when the factorization drops it, its
/// rank-one lumps compensate the diagonals of both its vertices (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ShapeOp {
    /// The lower block it adds to.
    pub slot: u32,
    /// Its row slot.
    pub k: u8,
    /// Its column slot.
    pub l: u8,
    /// Whether the factorization drops it (pair of used slots on distinct
    /// vertices whose block is not factored).
    pub dropped: bool,
}

/// One second-ring block `(k, l)` (slots) of a shape triangle that the
/// first-ring matrix lumps onto the diagonal blocks `row` (of vertex `v[k]`)
/// and `column` (of `v[l]`) (module docs, "The first-ring matrix").
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ShapeLump {
    /// The diagonal block of the row slot's vertex.
    pub row: u32,
    /// The diagonal block of the column slot's vertex.
    pub column: u32,
    /// Its row slot.
    pub k: u8,
    /// Its column slot.
    pub l: u8,
}

/// The pattern of the shape triangles' blocks: per triangle the blocks it
/// adds, per band the triangles with a used slot in it.
#[derive(Debug, Clone, Default)]
pub struct ShapeBlocks {
    /// Per shape triangle, CSC-like: the blocks the assembly computes
    /// ([`ShapeOp`]), in the order of its slot pairs `(k, l)`.
    pub(crate) op_start: Vec<u32>,
    pub(crate) ops: Vec<ShapeOp>,
    /// Per shape triangle, CSC-like: the second-ring blocks lumped on the
    /// diagonal ([`ShapeLump`]; none unless `lump_second_ring`), in the order
    /// of its slot pairs.
    pub(crate) lump_start: Vec<u32>,
    pub(crate) lumps: Vec<ShapeLump>,
    /// Per band of [`BAND_ROWS`] rows, CSC-like: the shape triangles with a
    /// used slot in the band, ascending.
    pub(crate) band_start: Vec<u32>,
    pub(crate) band_shapes: Vec<u32>,
}

impl ShapeBlocks {
    /// The pattern of `el`'s shape triangles on the built pattern `p`.
    pub(super) fn build(el: &Elements, p: &BlockPattern) -> ShapeBlocks {
        let (op_start, ops, lump_start, lumps) = shape_ops(el, p);
        let (band_start, band_shapes) = bands(el, p);
        ShapeBlocks {
            op_start,
            ops,
            lump_start,
            lumps,
            band_start,
            band_shapes,
        }
    }

    /// Adds the blocks of every shape triangle with a slot in `band`
    /// (module docs), from the edges' folds `edges`.
    pub(super) fn add(
        &self,
        el: &Elements,
        edges: &[crate::physics::shape::EdgeFold],
        h2: Scalar,
        band: &mut Band<'_>,
    ) {
        let b = band.index();
        if self.band_start.len() <= b + 1 {
            return;
        }
        let shapes = self.band_start[b] as usize..self.band_start[b + 1] as usize;
        for &tri in &self.band_shapes[shapes] {
            let tri = tri as usize;
            let ops = self.op_start[tri] as usize..self.op_start[tri + 1] as usize;
            let lumps = match self.lump_start.get(tri + 1) {
                Some(&end) => &self.lumps[self.lump_start[tri] as usize..end as usize],
                None => &[],
            };
            add_shape(
                band,
                &el.kinds.shapes.triangles[tri],
                &el.kinds.shapes.fold_edges.angles(tri, edges).1,
                h2,
                (&self.ops[ops], lumps),
            );
        }
    }
}

/// The lists of [`shape_ops`]: per triangle its ops and its lumps.
type OpLists = (Vec<u32>, Vec<ShapeOp>, Vec<u32>, Vec<ShapeLump>);

/// Per shape triangle, the blocks that the assembly computes ([`ShapeOp`]):
/// each pair of used slots `(k, l)` (`k` outer, `l` inner, ascending) whose
/// block is in the lower triangle (`v[l] <= v[k]`), marked when the
/// factorization drops it; with `lump_second_ring`, the second-ring pairs on
/// distinct vertices as lumps instead ([`ShapeLump`]).
fn shape_ops(el: &Elements, p: &BlockPattern) -> OpLists {
    let shapes = &el.kinds.shapes.triangles;
    let lumped = el.kinds.shapes.lump_second_ring;
    let (mut start, mut ops) = (Vec::with_capacity(shapes.len() + 1), Vec::new());
    let (mut lump_start, mut lumps) = (Vec::new(), Vec::new());
    start.push(0);
    if lumped {
        lump_start.reserve(shapes.len() + 1);
        lump_start.push(0);
    }
    for t in shapes {
        let active = shape_active(t);
        for k in (0..SHAPE_SLOTS).filter(|&k| active >> k & 1 != 0) {
            for l in (0..SHAPE_SLOTS).filter(|&l| active >> l & 1 != 0) {
                let (i, j) = (t.v[k], t.v[l]);
                if j <= i && lumped && i != j && second_ring(k, l) {
                    let (row, column) = (p.slot(i, i), p.slot(j, j));
                    let (k, l) = (k as u8, l as u8);
                    lumps.push(ShapeLump { row, column, k, l });
                } else if j <= i {
                    let slot = p.slot(i, j);
                    let dropped = i != j && !p.is_factored(slot);
                    let (k, l) = (k as u8, l as u8);
                    ops.push(ShapeOp {
                        slot,
                        k,
                        l,
                        dropped,
                    });
                }
            }
        }
        start.push(ops.len() as u32);
        if lumped {
            lump_start.push(lumps.len() as u32);
        }
    }
    (start, ops, lump_start, lumps)
}

/// Whether slots `k` and `l` of a shape triangle are a second-ring pair
/// (module docs, "The first-ring matrix"): the tip across edge `a` with the
/// triangle's own vertex `a` or with another tip. The other pairs join the
/// ends of a mesh edge (the triangle's own edges, and a tip with the ends
/// of the edge it lies across).
#[inline(always)]
pub(crate) fn second_ring(k: usize, l: usize) -> bool {
    let (low, high) = (k.min(l), k.max(l));
    high >= 3 && (low >= 3 || low == high - 3)
}

/// Per band, the shape triangles with a used slot in it, ascending.
fn bands(el: &Elements, p: &BlockPattern) -> (Vec<u32>, Vec<u32>) {
    let mut tagged: Vec<(u32, u32)> = Vec::new();
    for (ti, t) in el.kinds.shapes.triangles.iter().enumerate() {
        let active = shape_active(t);
        let mut bands = [u32::MAX; SHAPE_SLOTS];
        for (k, band) in bands.iter_mut().enumerate() {
            if active >> k & 1 != 0 {
                *band = (t.v[k] as usize / BAND_ROWS) as u32;
            }
        }
        bands.sort_unstable();
        let mut last = u32::MAX;
        for band in bands.into_iter().filter(|&b| b != u32::MAX) {
            if band != last {
                tagged.push((band, ti as u32));
                last = band;
            }
        }
    }
    group_by_key(p.bands(), &tagged)
}

/// The used slots of a shape triangle as a bit set: its own three vertices and
/// the tips across its interior edges.
#[inline(always)]
fn shape_active(t: &ShapeTriangle) -> u32 {
    (0..3).fold(0b111, |bits, a| bits | u32::from(t.interior[a]) << (3 + a))
}

/// Computes shape triangle `t`'s blocks `ops` with a vertex in the band (with
/// the triangle's Jacobian `jac`): adds each to its block when its row is in
/// the band, and a dropped one's lumps to the compensation of each of its two
/// vertices in the band. The products `M J` are formed once for all its
/// blocks.
#[inline(always)]
fn add_shape(
    band: &mut Band<'_>,
    t: &ShapeTriangle,
    jac: &ShapeJacobian,
    h2: Scalar,
    (ops, lumps): (&[ShapeOp], &[ShapeLump]),
) {
    let mut mj = [[Vector::ZERO; SHAPE_SLOTS]; 3];
    times_m(&t.m, jac, &mut mj);
    let rows = band.rows();
    for lump in lumps {
        add_lump(band, t, jac, &mj, h2, lump);
    }
    for op in ops {
        let (row, column) = (t.v[op.k as usize] as usize, t.v[op.l as usize] as usize);
        let (in_row, in_column) = (rows.contains(&row), rows.contains(&column));
        if !(in_row || op.dropped && in_column) {
            continue;
        }
        let (k, l) = (op.k as usize, op.l as usize);
        let mut block = Matrix3::ZERO;
        for a in moved_angles(k) {
            block += outer(jac[a][k], mj[a][l]);
        }
        block *= h2;
        if in_row {
            band.lower[op.slot as usize - band.base] += block;
        }
        if op.dropped {
            // A dropped block is a second-ring pair's, rank one: lumped on
            // its two vertices' compensation as the first-ring matrix lumps it.
            let (tip, other) = if k >= 3 { (k, l) } else { (l, k) };
            let a = tip - 3;
            let (u, w) = (jac[a][tip], mj[a][other] * h2);
            let (uu, ww) = (u.length_squared(), w.length_squared());
            if uu > 0.0 && ww > 0.0 {
                let ratio = (ww / uu).sqrt();
                let (vt, vo) = (t.v[tip] as usize, t.v[other] as usize);
                if rows.contains(&vt) {
                    band.lumps[vt - band.first_row] += outer(u, u * ratio);
                }
                if rows.contains(&vo) {
                    band.lumps[vo - band.first_row] += outer(w, w / ratio);
                }
            }
        }
    }
}

/// The lumps of the second-ring block of slots `(k, l)` of shape triangle `t`
/// (module docs, "The first-ring matrix"): the block is `u w^T`, `u` the
/// tip's gradient of its fold and `w` the other vertex's row of `h^2 M J`
/// (the row slot is the tip when both are), lumped as `(|w|/|u|) u u^T` on
/// the tip and `(|u|/|w|) w w^T` on the other vertex; none when either is zero.
#[inline(always)]
fn rank_one_lumps(
    t: &ShapeTriangle,
    jac: &ShapeJacobian,
    mj: &[[Vector; SHAPE_SLOTS]; 3],
    h2: Scalar,
    (k, l): (usize, usize),
) -> impl Iterator<Item = (u32, Matrix3)> {
    let (tip, other) = if k >= 3 { (k, l) } else { (l, k) };
    let a = tip - 3;
    let (u, w) = (jac[a][tip], mj[a][other] * h2);
    let (uu, ww) = (u.length_squared(), w.length_squared());
    let lumps = (uu > 0.0 && ww > 0.0).then(|| {
        let ratio = (ww / uu).sqrt();
        [
            (t.v[tip], outer(u, u * ratio)),
            (t.v[other], outer(w, w / ratio)),
        ]
    });
    lumps.into_iter().flatten()
}

/// Lumps the second-ring block `lump` of shape triangle `t` onto the
/// diagonal blocks of its two vertices that lie in the band (module docs,
/// "The first-ring matrix"), from the Jacobian `jac` and `mj = M J`.
#[inline(always)]
fn add_lump(
    band: &mut Band<'_>,
    t: &ShapeTriangle,
    jac: &ShapeJacobian,
    mj: &[[Vector; SHAPE_SLOTS]; 3],
    h2: Scalar,
    lump: &ShapeLump,
) {
    let rows = band.rows();
    let (k, l) = (lump.k as usize, lump.l as usize);
    for (vertex, block) in rank_one_lumps(t, jac, mj, h2, (k, l)) {
        // The diagonal slot of the row slot's vertex or the column slot's.
        let diagonal = if vertex == t.v[k] {
            lump.row
        } else {
            lump.column
        };
        if rows.contains(&(vertex as usize)) {
            band.lower[diagonal as usize - band.base] += block;
        }
    }
}

/// `(M J)_al = sum_b M_ab J_bl` for every angle `a` and slot `l`. A tip slot
/// `3 + b` moves angle `b` only (`shape.rs`, `HINGE_SLOTS`), so its column has
/// one term; skipping the exact zeros leaves every value the same to the last
/// bit.
#[inline(always)]
fn times_m(m: &[[Scalar; 3]; 3], jac: &ShapeJacobian, mj: &mut [[Vector; SHAPE_SLOTS]; 3]) {
    for (row, out) in m.iter().zip(mj) {
        for (l, o) in out.iter_mut().enumerate() {
            *o = match l {
                0..3 => jac[0][l] * row[0] + jac[1][l] * row[1] + jac[2][l] * row[2],
                _ => jac[l - 3][l] * row[l - 3],
            };
        }
    }
}

/// The angles of a shape triangle that slot `k` moves: all three for one of
/// its own vertices, angle `a` alone for the tip across edge `a` (slot `3 + a`).
#[inline(always)]
pub(crate) fn moved_angles(k: usize) -> std::ops::Range<usize> {
    if k < 3 { 0..3 } else { k - 3..k - 2 }
}

/// The Frobenius norm of `b`.
#[cfg(test)]
pub(crate) fn frobenius(b: &Matrix3) -> Scalar {
    (b.x_axis.length_squared() + b.y_axis.length_squared() + b.z_axis.length_squared()).sqrt()
}
