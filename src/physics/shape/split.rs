//! The split of each fold between its two triangles (module docs of
//! [`super`], "Splitting the folds"): one unknown per interior edge, chosen to
//! minimise the bending energy for the current folds. The energy is quadratic
//! in the splits with a constant matrix, so they solve one sparse symmetric
//! positive definite system, factored once per mesh (faer's sparse Cholesky,
//! sequential: the result does not depend on the thread count).

use std::sync::{Arc, Mutex};

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Par, Side};

use super::{NO_SPLIT, ShapeTriangle};
use crate::math::Scalar;
use crate::physics::block::group_by_key;

/// The factored system of the split unknowns of one mesh's shape triangles.
#[derive(Clone)]
pub struct FoldSplits {
    /// Number of split unknowns.
    count: usize,
    /// The system's lower triangle `(row, column, value)`, row-major (what two
    /// systems are compared by).
    matrix: Vec<(u32, u32, Scalar)>,
    /// Its Cholesky factor (none when there are no unknowns).
    factor: Option<Arc<Factor>>,
    /// The solve's scratch memory, allocated once.
    workspace: Arc<Mutex<MemBuffer>>,
}

/// A simplicial Cholesky factor: the system is small and local (each unknown
/// couples to the other edges of its two triangles).
struct Factor {
    symbolic: Arc<SymbolicCholesky<usize>>,
    values: Vec<Scalar>,
}

impl Default for FoldSplits {
    fn default() -> FoldSplits {
        FoldSplits {
            count: 0,
            matrix: Vec::new(),
            factor: None,
            workspace: Arc::new(Mutex::new(MemBuffer::new(StackReq::EMPTY))),
        }
    }
}

impl std::fmt::Debug for FoldSplits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FoldSplits")
            .field("count", &self.count)
            .field("stored", &self.matrix.len())
            .finish()
    }
}

/// Two systems are equal when their matrices are (the factor follows from it).
impl PartialEq for FoldSplits {
    fn eq(&self, other: &FoldSplits) -> bool {
        self.count == other.count && self.matrix == other.matrix
    }
}

/// The split system could not be factored: a triangle's plate matrix is not
/// positive definite, which a valid mesh (no zero-area triangle) rules out.
#[derive(Debug, Clone, thiserror::Error)]
#[error("the bending elements' fold-split system cannot be factored: {0}")]
pub struct SplitError(&'static str);

impl FoldSplits {
    /// Assembles and factors the system of `shapes`, whose split indices run
    /// over `0..count`.
    pub fn new(shapes: &[ShapeTriangle], count: usize) -> Result<FoldSplits, SplitError> {
        FoldSplits::default().renew(shapes, count)
    }

    /// The system of `shapes` (as [`FoldSplits::new`]), reusing what it shares
    /// with this one: all of it when the matrices are equal (a mesh rebuilt
    /// unchanged), the ordering and symbolic analysis when only the values
    /// differ. Either way the factor is the one [`FoldSplits::new`] makes.
    pub fn renew(&self, shapes: &[ShapeTriangle], count: usize) -> Result<FoldSplits, SplitError> {
        if count == 0 {
            return Ok(FoldSplits::default());
        }
        let matrix = assemble(shapes, count);
        if count == self.count && matrix == self.matrix {
            return Ok(self.clone());
        }
        let (col_ptr, row_idx, values) = lower_columns(&matrix, count);
        let structure =
            SymbolicSparseColMatRef::new_checked(count, count, &col_ptr, None, &row_idx);
        let a = SparseColMatRef::new(structure, &values);
        let same_structure = count == self.count
            && matrix.len() == self.matrix.len()
            && matrix
                .iter()
                .zip(&self.matrix)
                .all(|(m, o)| (m.0, m.1) == (o.0, o.1));
        let symbolic = match &self.factor {
            Some(f) if same_structure => f.symbolic.clone(),
            _ => Arc::new(
                factorize_symbolic_cholesky(
                    structure,
                    Side::Lower,
                    SymmetricOrdering::Amd,
                    CholeskySymbolicParams {
                        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                        ..Default::default()
                    },
                )
                .map_err(|_| SplitError("the symbolic analysis failed"))?,
            ),
        };
        let req = symbolic
            .factorize_numeric_llt_scratch::<Scalar>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<Scalar>(1, Par::Seq));
        let mut buffer = MemBuffer::new(req);
        let mut values = vec![0.0; symbolic.len_val()];
        symbolic
            .factorize_numeric_llt(
                &mut values,
                a,
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|_| SplitError("a pivot is not positive"))?;
        Ok(FoldSplits {
            count,
            matrix,
            factor: Some(Arc::new(Factor { symbolic, values })),
            workspace: Arc::new(Mutex::new(buffer)),
        })
    }

    /// Number of split unknowns.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Into `out`: the splits that minimise the energy of `shapes` (the
    /// triangles this system was built from) at their folds `theta`.
    pub fn solve(&self, shapes: &[ShapeTriangle], theta: &[[Scalar; 3]], out: &mut Vec<Scalar>) {
        out.clear();
        out.resize(self.count, 0.0);
        let Some(factor) = &self.factor else {
            return;
        };
        // The energy's gradient at zero splits, negated.
        for (t, th) in shapes.iter().zip(theta) {
            let fixed = [0, 1, 2].map(|a| t.share[a] * th[a]);
            let k_fixed = t.times_k(fixed);
            for a in (0..3).filter(|&a| t.split[a] != NO_SPLIT) {
                out[t.split[a] as usize] -= t.split_sign[a] * k_fixed[a];
            }
        }
        let rhs = faer::MatMut::from_column_major_slice_mut(out.as_mut_slice(), self.count, 1);
        let llt = LltRef::<usize, Scalar>::new(&factor.symbolic, &factor.values);
        // A poisoned lock only means another solve panicked; the buffer is scratch.
        let mut buffer = self
            .workspace
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        llt.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, MemStack::new(&mut buffer));
    }
}

/// The lower triangle of the splits' system, `(row, column, value)` in
/// row-major order: `sum_t s_a s_b K_ab` over the triangles' split edges,
/// each entry summed from zero in triangle order. The terms are grouped by row
/// by a counting sort and each row's few terms by column by a stable sort, so
/// the order of every sum is the triangles'.
fn assemble(shapes: &[ShapeTriangle], count: usize) -> Vec<(u32, u32, Scalar)> {
    let mut terms: Vec<(u32, (u32, Scalar))> = Vec::with_capacity(6 * shapes.len());
    for t in shapes {
        for a in (0..3).filter(|&a| t.split[a] != NO_SPLIT) {
            for b in (0..3).filter(|&b| t.split[b] != NO_SPLIT) {
                let (i, j) = (t.split[a], t.split[b]);
                if j <= i {
                    let v = t.split_sign[a] * t.split_sign[b] * t.k[a][b];
                    terms.push((i, (j, v)));
                }
            }
        }
    }
    let (start, mut items) = group_by_key(count, &terms);
    let mut matrix: Vec<(u32, u32, Scalar)> = Vec::with_capacity(terms.len());
    for (i, range) in start.windows(2).enumerate() {
        let row = &mut items[range[0] as usize..range[1] as usize];
        row.sort_by_key(|&(j, _)| j);
        for &(j, v) in row.iter() {
            match matrix.last_mut() {
                Some((r, c, sum)) if *r == i as u32 && *c == j => *sum += v,
                _ => matrix.push((i as u32, j, 0.0 + v)),
            }
        }
    }
    matrix
}

/// The compressed columns of the lower triangle `matrix` (row-major, as
/// [`assemble`] makes it): column pointers, row indices ascending within each
/// column, and values.
fn lower_columns(
    matrix: &[(u32, u32, Scalar)],
    count: usize,
) -> (Vec<usize>, Vec<usize>, Vec<Scalar>) {
    let by_column: Vec<(u32, (u32, Scalar))> =
        matrix.iter().map(|&(i, j, v)| (j, (i, v))).collect();
    let (start, entries) = group_by_key(count, &by_column);
    let col_ptr = start.iter().map(|&s| s as usize).collect();
    let row_idx = entries.iter().map(|&(i, _)| i as usize).collect();
    let values = entries.iter().map(|&(_, v)| v).collect();
    (col_ptr, row_idx, values)
}

#[cfg(test)]
mod tests {
    use super::FoldSplits;
    use crate::math::Scalar;
    use crate::mesh::{Mesh, rectangle};
    use crate::physics::Model;
    use crate::physics::elements::{Elements, MaterialParams};
    use crate::scene::{DiagonalPattern, default_scene};

    /// The splits of `s` for `el`'s shape triangles at made-up folds, as bits.
    fn solved(s: &FoldSplits, el: &Elements) -> Vec<u64> {
        let folds: Vec<[Scalar; 3]> = (0..el.kinds.shapes.triangles.len())
            .map(|t| [0, 1, 2].map(|a| ((7 * t + 3 * a) % 11) as Scalar * 0.01 - 0.05))
            .collect();
        let mut out = Vec::new();
        s.solve(&el.kinds.shapes.triangles, &folds, &mut out);
        out.iter().map(|v| v.to_bits()).collect()
    }

    fn grid(resolution: u32) -> Mesh {
        rectangle(1.0, 1.0, resolution, DiagonalPattern::Alternating).expect("a grid")
    }

    /// A system renewed from another, whether the matrices are equal, share
    /// their structure only (another rigidity) or differ in size (another
    /// mesh), is the one made new and solves bit for bit as it does.
    #[test]
    fn a_renewed_system_solves_as_a_new_one() {
        let scene = default_scene(&[]).expect("the default scene");
        let fabric = Model::from_scene(&scene).material;
        let stiffer = MaterialParams {
            bending: 3.0 * fabric.bending,
            ..fabric
        };
        let (coarse, fine) = (grid(6), grid(9));
        let base = Elements::build(&coarse, &fabric);
        for (mesh, mat) in [(&coarse, &fabric), (&coarse, &stiffer), (&fine, &fabric)] {
            let el = Elements::build(mesh, mat);
            let count = el.kinds.shapes.fold_splits.count();
            assert!(count > 0, "the grid has split unknowns");
            let new = FoldSplits::new(&el.kinds.shapes.triangles, count).expect("factored");
            let renewed = (base.kinds.shapes.fold_splits)
                .renew(&el.kinds.shapes.triangles, count)
                .expect("factored");
            assert!(renewed == new, "the renewed system's matrix differs");
            assert_eq!(solved(&renewed, &el), solved(&new, &el));
        }
    }
}
