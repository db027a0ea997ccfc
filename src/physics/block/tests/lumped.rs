//! The first-ring bending matrix (`lump_second_ring`, `kinds/shapes/blocks.rs`,
//! "The first-ring matrix") against the exact one.

use super::{Terms, bent, meshes, noise_vector};
use crate::math::{Matrix3, Scalar, Vector};
use crate::physics::block::BlockPattern;
use crate::physics::elements::Elements;
use crate::physics::kinds::frobenius;

/// The block `(i, j)` of the symmetric matrix with pattern `p` and lower
/// blocks `lower`, or `None` when the pattern has none there.
fn block(p: &BlockPattern, lower: &[Matrix3], i: u32, j: u32) -> Option<Matrix3> {
    let row = p.row_start[i as usize] as usize..p.row_start[i as usize + 1] as usize;
    let found = p.columns[row.clone()].binary_search(&j).ok()?;
    Some(p.full_block(lower, row.start + found))
}

/// On the grid and the refined mesh with the shape operator: the first-ring
/// pattern holds only the diagonal and the springs' pairs (the mesh edges),
/// drops nothing from the factor, keeps every off-diagonal block of the
/// exact matrix to the last bit, and the first-ring matrix minus the exact
/// one is positive semi-definite and not zero.
#[test]
fn the_first_ring_matrix_keeps_the_edges_and_bounds_the_exact_one() {
    let (meshes, fabric) = meshes();
    for m in &meshes {
        let x = bent(m);
        let n = m.vertex_count();
        let exact = Elements::build(m, &fabric);
        assert!(!exact.kinds.shapes.triangles.is_empty());
        let mut lumped = exact.clone();
        lumped.kinds.shapes.lump_second_ring = true;
        let (pe, pl) = (
            BlockPattern::build(n, &exact, false),
            BlockPattern::build(n, &lumped, false),
        );
        let springs = &exact.kinds.springs.springs;
        let mut edges: Vec<(u32, u32)> = springs
            .iter()
            .map(|s| (s.v[0].min(s.v[1]), s.v[0].max(s.v[1])))
            .collect();
        edges.sort_unstable();
        for s in 0..pl.blocks() {
            let (i, j) = (pl.rows[s], pl.columns[s]);
            assert!(i == j || edges.binary_search(&(i.min(j), i.max(j))).is_ok());
        }
        println!(
            "{n} vertices: {} blocks exact, {} first ring",
            pe.blocks(),
            pl.blocks()
        );
        assert!(pl.blocks() < pe.blocks());
        assert!(pl.in_place.shapes.ops.iter().all(|op| !op.dropped));
        let (te, tl) = (Terms::new(&exact, &x), Terms::new(&lumped, &x));
        let (mut lumps_e, mut lower_e, mut lumps_l, mut lower_l) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        pe.gather(&te.view(&exact), &mut lumps_e, &mut lower_e);
        pl.gather(&tl.view(&lumped), &mut lumps_l, &mut lower_l);
        assert!(lumps_l.iter().all(|&s| s == Matrix3::ZERO));
        let bits = |m: Matrix3| m.to_cols_array().map(Scalar::to_bits);
        let mut largest: Scalar = 0.0;
        for salt in 0..6 {
            let v: Vec<Vector> = (0..n).map(|i| noise_vector(i, 20 + salt)).collect();
            // x^T (first ring - exact) x, block by block, and its rounding scale.
            let (mut q, mut scale) = (0.0, 0.0);
            for s in 0..pe.blocks() {
                let (i, j) = (pe.rows[s], pe.columns[s]);
                let a = pe.full_block(&lower_e, s);
                let d = match block(&pl, &lower_l, i, j) {
                    Some(b) if i != j => {
                        assert_eq!(bits(b), bits(a), "block ({i}, {j})");
                        continue;
                    }
                    Some(b) => b - a,
                    None => -a,
                };
                let (xi, xj) = (v[i as usize], v[j as usize]);
                q += xi.dot(d * xj);
                scale += xi.length() * frobenius(&d) * xj.length();
            }
            assert!(q >= -1e-9 * scale, "salt {salt}: {q:e} of {scale:e}");
            largest = largest.max(q / scale);
        }
        println!("largest x^T (first ring - exact) x over its scale: {largest:.3}");
        assert!(largest > 1e-3);
    }
}
