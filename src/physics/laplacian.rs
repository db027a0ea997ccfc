//! A scalar preconditioner for the implicit system: one `n x n` sparse Cholesky
//! factor of a weighted graph Laplacian plus the mass, applied to x, y and z
//! alike (`simulation.preconditioner = "laplacian"`).
//!
//! The implicit matrix `A = M + h D + h^2 K` has a 3x3 block per coupled vertex
//! pair. A spring's blocks are `k (n n^T + ...)`: stiff along the spring, soft
//! across it. The scalar matrix keeps one number per pair instead, the weight
//! `w_ij = max(0, -tr(A_ij) / 3)` (the block's mean stiffness, a coupling that
//! pulls the two vertices together), and per vertex the diagonal
//! `max(tr(A_ii) / 3, m_i + sum_j w_ij)`: a symmetric, strictly diagonally
//! dominant matrix with positive diagonal, so positive definite whatever the
//! blocks hold. Its pattern is the vertex graph of the factored blocks (springs
//! and membrane edges, not the bending's second ring), so its factor has
//! about a ninth of the block factor's stored values (the benchmark's time
//! split: 12 ms a factorization at 16,384 vertices against 63 ms).
//!
//! It is the matrix of projective dynamics and of Liu et al. (2013), taken from
//! the current `A` rather than the rest state so that it follows the step size
//! and the contacts. What it cannot hold is direction: along a spring it is a
//! third as stiff as `A`, across it (where a taut spring is soft) far stiffer.
//! Conjugate gradients on the exact `A` correct both; how many iterations that
//! takes is measured in `docs/model.md`, "The linear solver".

use std::sync::Arc;

use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymmetricOrdering};

use super::block::BlockPattern;
use super::cholesky::{FactorError, Numeric, Workspace, analyse_structure};
use crate::math::{Matrix3, Scalar, Vector};

/// The scalar Laplacian factor of a pattern's matrix (module docs).
#[derive(Debug, Clone, Default)]
pub struct LaplacianFactor {
    /// Symbolic analysis of the vertex graph (`None`: not analysed yet).
    symbolic: Option<Arc<SymbolicCholesky<u32>>>,
    /// The lower triangle's CSC structure, one row and column per vertex.
    column_start: Vec<u32>,
    rows: Vec<u32>,
    /// Per CSC entry: the block of `A` it is taken from.
    blocks: Vec<u32>,
    numeric: Numeric<Scalar>,
    /// The CSC values of the scalar matrix.
    values: Vec<Scalar>,
    /// Per vertex: the sum of its couplings' weights.
    weights: Vec<Scalar>,
    /// Right-hand sides: x, y and z, one column each.
    rhs: Vec<Scalar>,
    valid: bool,
    workspace: Option<Workspace>,
}

impl LaplacianFactor {
    /// Forgets the factor and the analysis (the pattern changed).
    pub fn reset(&mut self) {
        self.symbolic = None;
        self.valid = false;
    }

    /// True when a factor is ready for [`LaplacianFactor::solve`].
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    /// True when the vertex graph of the current pattern is analysed.
    pub fn is_analysed(&self) -> bool {
        self.symbolic.is_some()
    }

    /// Stored values of the factor (`None`: not analysed).
    pub fn stored_values(&self) -> Option<usize> {
        self.symbolic.as_ref().map(|s| s.len_val())
    }

    /// Ordering (faer's AMD on the vertex graph) and symbolic analysis of
    /// `pattern`'s factored blocks, once per topology.
    pub fn analyse(&mut self, pattern: &BlockPattern) -> Result<(), FactorError> {
        (self.column_start, self.rows) = pattern.vertex_structure();
        self.blocks = pattern.vertex_structure_blocks();
        let n = pattern.vertices();
        let structure =
            SymbolicSparseColMatRef::new_checked(n, n, &self.column_start, None, &self.rows);
        self.symbolic = Some(Arc::new(analyse_structure(
            structure,
            SymmetricOrdering::Amd,
        )?));
        self.valid = false;
        Ok(())
    }

    /// Factors the scalar matrix of the blocks `blocks` on `pattern` (module
    /// docs); `mass`: per vertex, the least diagonal.
    pub fn factor(
        &mut self,
        pattern: &BlockPattern,
        blocks: &[Matrix3],
        mass: &[Scalar],
    ) -> Result<(), FactorError> {
        self.valid = false;
        let Some(symbolic) = self.symbolic.clone() else {
            return Err(FactorError::Setup);
        };
        let n = pattern.vertices();
        self.scalar_values(blocks, mass, n);
        let structure = (n, self.column_start.as_slice(), self.rows.as_slice());
        let result = self
            .numeric
            .factor(&symbolic, structure, &self.values, &mut self.workspace);
        self.valid = result.is_ok();
        result
    }

    /// The scalar matrix's CSC values from the blocks (module docs).
    fn scalar_values(&mut self, blocks: &[Matrix3], mass: &[Scalar], n: usize) {
        let trace = |b: &Matrix3| (b.x_axis.x + b.y_axis.y + b.z_axis.z) / 3.0;
        self.values.clear();
        self.weights.clear();
        self.weights.resize(n, 0.0);
        for j in 0..n {
            let (s, e) = (
                self.column_start[j] as usize,
                self.column_start[j + 1] as usize,
            );
            for k in s..e {
                let i = self.rows[k] as usize;
                let block = &blocks[self.blocks[k] as usize];
                if i == j {
                    self.values.push(trace(block));
                } else {
                    let w = (-trace(block)).max(0.0);
                    self.weights[i] += w;
                    self.weights[j] += w;
                    self.values.push(-w);
                }
            }
        }
        for (j, (m, w)) in mass.iter().zip(&self.weights).enumerate().take(n) {
            // The diagonal comes first in its column (rows ascending, i >= j).
            let d = self.column_start[j] as usize;
            self.values[d] = self.values[d].max(m + w);
        }
    }

    /// `z = P^-1 r`, the scalar factor applied to each coordinate.
    pub fn solve(&mut self, r: &[Vector], z: &mut [Vector]) {
        debug_assert!(self.valid, "solve without a valid factorization");
        let Some(symbolic) = self.symbolic.clone() else {
            return;
        };
        let n = r.len();
        self.rhs.clear();
        self.rhs.extend(r.iter().map(|v| v.x));
        self.rhs.extend(r.iter().map(|v| v.y));
        self.rhs.extend(r.iter().map(|v| v.z));
        self.numeric
            .solve(&symbolic, &mut self.rhs, 3, &mut self.workspace);
        for (i, out) in z.iter_mut().enumerate() {
            *out = Vector::new(self.rhs[i], self.rhs[n + i], self.rhs[2 * n + i]);
        }
    }
}
