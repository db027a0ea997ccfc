//! The projected system against each block projected alone, to the last bit.

use super::{Terms, assemble, bent, meshes, noise, noise_vector};
use crate::math::{Matrix3, Scalar, Vector};
use crate::mesh::rectangle;
use crate::physics::block::{BlockPattern, outer};
use crate::physics::elements::Elements;
use crate::scene::DiagonalPattern;

/// Block `slot` of `S A S + (I - S) m` formed alone from the full block (the
/// reference of [`BlockPattern::project`]).
fn projected_block(
    p: &BlockPattern,
    lower: &[Matrix3],
    projection: &[Option<Vector>],
    scale: &[Scalar],
    slot: usize,
) -> Matrix3 {
    let s = |n: Vector| {
        if n == Vector::ZERO {
            Matrix3::ZERO
        } else {
            Matrix3::IDENTITY - outer(n, n)
        }
    };
    let (i, j) = (p.rows[slot] as usize, p.columns[slot] as usize);
    let mut m = p.full_block(lower, slot);
    if let Some(n) = projection[i] {
        m = s(n) * m;
    }
    if let Some(n) = projection[j] {
        m *= s(n);
    }
    if let (true, Some(n)) = (i == j, projection[i]) {
        m += (Matrix3::IDENTITY - s(n)) * scale[i];
    }
    m
}

#[test]
fn projection_matches_the_per_block_formula() {
    let m = rectangle(1.0, 1.0, 48, DiagonalPattern::Alternating).expect("a grid");
    let x = bent(&m);
    let (_, fabric) = meshes();
    let el = Elements::build(&m, &fabric);
    let terms = Terms::new(&el, &x);
    let t = terms.view(&el);
    let p = BlockPattern::build(m.vertex_count(), &el, false);
    let [lower, _, _] = assemble(&p, &t);
    let n = p.vertices();
    let scale: Vec<Scalar> = (0..n).map(|i| 1.0 + noise(i, 11)).collect();
    // Dense projections (most rows touch one) and sparse ones (most rows free).
    for period in [7, 97] {
        let projection: Vec<Option<Vector>> = (0..n)
            .map(|i| match i % period {
                0 => Some(Vector::ZERO),
                3 => Some(noise_vector(i, 10).normalize()),
                _ => None,
            })
            .collect();
        let mut system = Vec::new();
        let mut touched = Vec::new();
        p.touched_rows(&projection, &mut touched);
        p.project(&lower, &projection, &touched, &scale, &mut system);
        let bits = |m: Matrix3| m.to_cols_array().map(Scalar::to_bits);
        for (slot, &got) in system.iter().enumerate() {
            let expected = projected_block(&p, &lower, &projection, &scale, slot);
            assert_eq!(bits(got), bits(expected), "block {slot}, period {period}");
        }
    }
}
