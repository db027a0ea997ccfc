//! Sparse Cholesky factorization of the implicit system, with faer.
//!
//! The symbolic analysis (AMD fill-reducing ordering, elimination tree, supernodes)
//! depends only on the sparsity pattern, so it is computed once per mesh topology;
//! a numerical factorization reuses it. Everything runs sequentially (`Par::Seq`):
//! faer's parallel supernodal factorization changes the order of floating-point
//! sums with the thread count, and on 2 cores it is also slower (a 65 x 65 grid,
//! 12,675 unknowns: 14.5 ms on 1 thread, 26 ms on 2).
//!
//! # Supernodal always
//! faer picks a simplicial (column by column) factorization when its estimate
//! of flops per stored value is low, which it was for the adaptive meshes of
//! about 1,000 to 3,000 vertices; the supernodal one (dense kernels on column
//! blocks) is faster there: on an adaptive `hanging_sheet_rest` of about 1,200
//! vertices the factorization takes 1.33 s instead of 2.17 s and the run 10 %
//! less wall time; on larger meshes faer chooses supernodal anyway. Results
//! differ from the simplicial factor's in the last digits only.
//!
//! # Ordering by vertex
//! The fill-reducing ordering (AMD) runs on the vertex graph, one node per vertex
//! (the factored blocks' pattern), and each vertex's three unknowns follow one
//! another in the result. AMD on the scalar pattern finds the same structure
//! (the three unknowns of a vertex are indistinguishable to it) but reads nine
//! times the entries, and an adaptive run orders its matrix again after every
//! remesh. `cargo bench --bench implicit -- remesh_tables/analyse` compares the
//! two: by vertex is about 1.4 times faster on a 64 x 64 grid and 1.7 times on
//! 128 x 128, with the same fill (test
//! `ordering_by_vertex_fills_no_more_than_scalar_amd`). Most of what remains is
//! faer's symbolic factorization on the scalar pattern.
//!
//! # Single precision
//! A [`Precision::Single`] factor stores `L` in `f32`: half the memory traffic in
//! the factorization and in every solve with it, which is what both are bound
//! by on meshes of thousands of vertices. It serves only as the preconditioner
//! of conjugate gradients that run in double precision, so a solve still
//! reaches its tolerance; a less exact factor can only cost iterations. Before
//! rounding, the matrix is scaled to unit diagonal, `D A D` with
//! `D = diag(A)^-1/2`, and the solve applies `D (L L^T)^-1 D`: the rows of held
//! and contact vertices (their mass alone on the diagonal) and of stretched
//! cloth (its stiffness) differ by orders of magnitude, and unscaled the
//! rounding of the large ones swamps the small. Where the matrix is stiff
//! enough (a cloth pressed against an obstacle, a stiff strip) some pivots
//! still lose most of their digits to cancellation and can come out zero or
//! negative; a pivot below `sqrt(f32::EPSILON)` (of the unit diagonal) is set
//! to that value (faer's dynamic regularization), so the factor stays positive
//! definite, a preconditioner that conjugate gradients can use, only a less
//! exact one there.
//!
//! Why faer: it is pure Rust (no system BLAS or SuiteSparse to install), maintained,
//! has a supernodal LL^T and LDL^T with AMD, and exposes the symbolic and numeric
//! phases separately. The alternatives on crates.io either wrap C libraries
//! (suitesparse, cholmod) or offer only simplicial (column-by-column) factorizations
//! (sprs-ldl, nalgebra-sparse); none of them was benchmarked against faer here.

mod dissection;
mod numeric;

pub(crate) use numeric::{Numeric, Workspace};

use std::sync::Arc;

use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};

use super::block::BlockPattern;
use crate::math::{Matrix3, Scalar, Vector};

/// Why a factorization failed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FactorError {
    /// A pivot was not positive: the matrix is not numerically positive definite.
    #[error("the implicit system matrix is not positive definite")]
    NotPositiveDefinite,
    /// The symbolic analysis could not allocate or index the factor.
    #[error("the sparse factorization could not be set up (out of memory or too large)")]
    Setup,
}

/// The fill-reducing ordering of the symbolic analysis (module docs, "Ordering by
/// vertex").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ordering {
    /// AMD on the vertex graph, a vertex's three unknowns kept together: what
    /// [`Factorization::analyse`] uses.
    ByVertex,
    /// faer's AMD on the scalar pattern (what drape used before; kept for the
    /// benchmark and the test that compare the two).
    ByUnknown,
    /// Nested dissection of the vertex graph, parts of at most 256 vertices
    /// ordered by AMD ([`dissection`]; measured against AMD by the `implicit`
    /// benchmark), a vertex's three unknowns kept together.
    NestedDissection,
}

/// The floating-point type of a factor's stored values (module docs, "Single
/// precision").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Precision {
    /// `f64`, the simulation's own precision.
    #[default]
    Double,
    /// `f32`: half the memory traffic in the factorization and the solves.
    Single,
}

/// A Cholesky factor `A = L L^T` of the (projected) implicit system matrix, and the
/// symbolic analysis of its pattern (module docs).
#[derive(Debug, Clone, Default)]
pub struct Factorization {
    /// Symbolic analysis of the current pattern (`None`: not analysed yet).
    symbolic: Option<Arc<SymbolicCholesky<u32>>>,
    /// The precision of the numerical factor.
    precision: Precision,
    /// The numerical factor in double precision.
    double: Numeric<f64>,
    /// The numerical factor in single precision.
    single: Numeric<f32>,
    /// True when the factor of `precision` holds a successful factorization.
    valid: bool,
    /// The CSC values of the matrix being factored.
    values: Vec<Scalar>,
    /// A right-hand side, flattened.
    rhs: Vec<Scalar>,
    /// Single precision: per unknown, the scale `1 / sqrt(A_ii)` of the
    /// factored matrix `D A D` (module docs, "Single precision").
    scale: Vec<Scalar>,
    /// `D A D`'s values and `D r` rounded to single precision.
    values_single: Vec<f32>,
    rhs_single: Vec<f32>,
    workspace: Option<Workspace>,
}

impl Factorization {
    /// An empty factorization whose numerical factors will be of `precision`.
    pub fn with_precision(precision: Precision) -> Factorization {
        Factorization {
            precision,
            ..Default::default()
        }
    }

    /// The precision of the numerical factor.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// Forgets the factor and the symbolic analysis (the pattern changed).
    pub fn reset(&mut self) {
        self.symbolic = None;
        self.valid = false;
    }

    /// True when a factor is ready for [`Factorization::solve`].
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    /// True when the symbolic analysis is done for the current pattern.
    pub fn is_analysed(&self) -> bool {
        self.symbolic.is_some()
    }

    /// Stored values of the factor of the analysed pattern (`None`: not analysed).
    pub fn stored_values(&self) -> Option<usize> {
        self.symbolic.as_ref().map(|s| s.len_val())
    }

    /// Ordering and symbolic analysis of `pattern` (once per topology), ordered
    /// by vertex (module docs, "Ordering by vertex").
    pub fn analyse(&mut self, pattern: &BlockPattern) -> Result<(), FactorError> {
        self.analyse_with(pattern, Ordering::ByVertex)
    }

    /// [`Factorization::analyse`] with the given fill-reducing ordering.
    pub fn analyse_with(
        &mut self,
        pattern: &BlockPattern,
        ordering: Ordering,
    ) -> Result<(), FactorError> {
        let (col_ptr, rows) = pattern.csc_structure();
        let n = 3 * pattern.vertices();
        let structure = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, rows);
        let by_vertex = match ordering {
            Ordering::ByVertex => Some(order_by_vertex(pattern)?),
            Ordering::NestedDissection => {
                let (column_start, rows) = pattern.vertex_structure();
                let order =
                    dissection::nested_dissection(pattern.vertices(), &column_start, &rows)?;
                Some(expand_to_unknowns(&order))
            }
            Ordering::ByUnknown => None,
        };
        let ordering = match &by_vertex {
            Some((forward, inverse)) => {
                SymmetricOrdering::Custom(PermRef::new_checked(forward, inverse, n))
            }
            None => SymmetricOrdering::Amd,
        };
        self.symbolic = Some(Arc::new(analyse_structure(structure, ordering)?));
        // The values are sized by the numerical factorization: an analysis that
        // is only measured (the direct solver's choice of factor) allocates none.
        self.double.clear();
        self.single.clear();
        self.valid = false;
        Ok(())
    }

    /// Numerical factorization of the matrix with blocks `blocks` on `pattern`
    /// (analysed before), with `extra[i]` added to diagonal block `i`.
    pub fn factor(
        &mut self,
        pattern: &BlockPattern,
        blocks: &[Matrix3],
        extra: &[Matrix3],
    ) -> Result<(), FactorError> {
        self.valid = false;
        let Some(symbolic) = self.symbolic.clone() else {
            return Err(FactorError::Setup);
        };
        pattern.csc_values(blocks, extra, &mut self.values);
        let (col_ptr, rows) = pattern.csc_structure();
        let structure = (3 * pattern.vertices(), col_ptr, rows);
        let result = match self.precision {
            Precision::Double => {
                self.double
                    .factor(&symbolic, structure, &self.values, &mut self.workspace)
            }
            Precision::Single => {
                equilibrate(
                    (col_ptr, rows),
                    &self.values,
                    &mut self.scale,
                    &mut self.values_single,
                )?;
                self.single.factor(
                    &symbolic,
                    structure,
                    &self.values_single,
                    &mut self.workspace,
                )
            }
        };
        self.valid = result.is_ok();
        result
    }

    /// `z = A_f^-1 r` with the current factor (which must be valid).
    pub fn solve(&mut self, r: &[Vector], z: &mut [Vector]) {
        debug_assert!(self.valid, "solve without a valid factorization");
        let Some(symbolic) = self.symbolic.clone() else {
            return;
        };
        self.rhs.clear();
        self.rhs.extend(r.iter().flat_map(|v| v.to_array()));
        match self.precision {
            Precision::Double => {
                self.double
                    .solve(&symbolic, &mut self.rhs, 1, &mut self.workspace)
            }
            Precision::Single => {
                // `D r` divided by its largest entry, so that rounding it to
                // single precision neither underflows nor overflows however
                // small or large the residual has become.
                let largest = self
                    .rhs
                    .iter()
                    .zip(&self.scale)
                    .fold(0.0, |m: Scalar, (r, d)| m.max((r * d).abs()));
                let back = if largest > 0.0 { largest } else { 1.0 };
                self.rhs_single.clear();
                self.rhs_single.extend(
                    self.rhs
                        .iter()
                        .zip(&self.scale)
                        .map(|(r, d)| (r * d / back) as f32),
                );
                self.single
                    .solve(&symbolic, &mut self.rhs_single, 1, &mut self.workspace);
                for ((out, v), d) in self.rhs.iter_mut().zip(&self.rhs_single).zip(&self.scale) {
                    *out = Scalar::from(*v) * d * back;
                }
            }
        }
        for (out, c) in z.iter_mut().zip(self.rhs.chunks_exact(3)) {
            *out = Vector::new(c[0], c[1], c[2]);
        }
    }
}

/// The lower-triangle CSC matrix (`col_ptr`, `rows`, `values`; each column's
/// diagonal first) scaled to unit diagonal, `D A D` with `D = diag(A)^-1/2`,
/// rounded to single precision into `out`, and `D` into `scale`. A diagonal
/// entry that is not positive (nor finite) makes the matrix not positive
/// definite: an error, as the double-precision factorization reports it, not a
/// pivot for the regularization to paper over.
fn equilibrate(
    (col_ptr, rows): (&[u32], &[u32]),
    values: &[Scalar],
    scale: &mut Vec<Scalar>,
    out: &mut Vec<f32>,
) -> Result<(), FactorError> {
    let n = col_ptr.len() - 1;
    scale.clear();
    for c in 0..n {
        let d = values[col_ptr[c] as usize];
        if !(d > 0.0 && d.is_finite()) {
            return Err(FactorError::NotPositiveDefinite);
        }
        scale.push(1.0 / d.sqrt());
    }
    out.clear();
    for c in 0..n {
        let (s, e) = (col_ptr[c] as usize, col_ptr[c + 1] as usize);
        for k in s..e {
            out.push((values[k] * scale[rows[k] as usize] * scale[c]) as f32);
        }
    }
    Ok(())
}

/// faer's symbolic analysis of a lower-triangle structure with `ordering`,
/// supernodal always (module docs).
pub(crate) fn analyse_structure(
    structure: SymbolicSparseColMatRef<'_, u32>,
    ordering: SymmetricOrdering<'_, u32>,
) -> Result<SymbolicCholesky<u32>, FactorError> {
    factorize_symbolic_cholesky(
        structure,
        Side::Lower,
        ordering,
        CholeskySymbolicParams {
            // Module docs, "Supernodal always".
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        },
    )
    .map_err(|_| FactorError::Setup)
}

/// The fill-reducing ordering of `pattern`'s scalar unknowns (module docs,
/// "Ordering by vertex"): AMD on the vertex graph, each vertex's three unknowns
/// kept together in x, y, z order. Returns the forward and inverse permutations.
fn order_by_vertex(pattern: &BlockPattern) -> Result<(Vec<u32>, Vec<u32>), FactorError> {
    let (column_start, rows) = pattern.vertex_structure();
    let order = amd_order(pattern.vertices(), &column_start, &rows)?;
    Ok(expand_to_unknowns(&order))
}

/// faer's AMD ordering (position to vertex) of the graph of `n` vertices given
/// as its lower triangle (`column_start`, `rows`, diagonal included).
pub(crate) fn amd_order(
    n: usize,
    column_start: &[u32],
    rows: &[u32],
) -> Result<Vec<u32>, FactorError> {
    let graph = SymbolicSparseColMatRef::new_checked(n, n, column_start, None, rows);
    let (mut forward, mut inverse) = (vec![0u32; n], vec![0u32; n]);
    let mut buffer = MemBuffer::try_new(amd::order_scratch::<u32>(n, rows.len()))
        .map_err(|_| FactorError::Setup)?;
    amd::order(
        &mut forward,
        &mut inverse,
        graph,
        amd::Control::default(),
        MemStack::new(&mut buffer),
    )
    .map_err(|_| FactorError::Setup)?;
    Ok(forward)
}

/// The forward and inverse permutations of the scalar unknowns from the
/// vertices' elimination order, each vertex's three unknowns together.
fn expand_to_unknowns(order: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let forward: Vec<u32> = order
        .iter()
        .flat_map(|&v| [3 * v, 3 * v + 1, 3 * v + 2])
        .collect();
    let mut inverse = vec![0u32; forward.len()];
    for (new, &old) in forward.iter().enumerate() {
        inverse[old as usize] = new as u32;
    }
    (forward, inverse)
}
