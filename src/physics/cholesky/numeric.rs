//! The numerical part of a factor in one precision, and faer's scratch.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::FactorError;

/// Scratch memory for faer, recreated (empty) when cloned.
pub(crate) struct Workspace {
    req: StackReq,
    buffer: MemBuffer,
}

impl Workspace {
    fn new(req: StackReq) -> Workspace {
        Workspace {
            req,
            buffer: MemBuffer::new(req),
        }
    }

    /// The stack, grown to at least `req` first.
    fn stack(&mut self, req: StackReq) -> &mut MemStack {
        if req.size_bytes() > self.req.size_bytes() || req.align_bytes() > self.req.align_bytes() {
            *self = Workspace::new(self.req.or(req));
        }
        MemStack::new(&mut self.buffer)
    }
}

impl Clone for Workspace {
    fn clone(&self) -> Workspace {
        Workspace::new(self.req)
    }
}

impl std::fmt::Debug for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Workspace({} bytes)", self.req.size_bytes())
    }
}

/// A floating-point type faer factors in.
pub(crate) trait FactorScalar:
    faer::traits::ComplexField<Real = Self> + Copy + Default
{
    /// Neither infinite nor NaN.
    fn finite(self) -> bool;
    /// How faer treats a pivot that is not clearly positive.
    fn regularization() -> LltRegularization<Self>;
}

impl FactorScalar for f64 {
    fn finite(self) -> bool {
        self.is_finite()
    }
    /// None: a pivot that is not positive fails the factorization (the
    /// matrix is not positive definite).
    fn regularization() -> LltRegularization<f64> {
        LltRegularization::default()
    }
}

impl FactorScalar for f32 {
    fn finite(self) -> bool {
        self.is_finite()
    }
    /// A pivot below `sqrt(f32::EPSILON)` of the unit diagonal (module docs,
    /// "Single precision") is set to that value.
    fn regularization() -> LltRegularization<f32> {
        let floor = f32::EPSILON.sqrt();
        LltRegularization {
            dynamic_regularization_delta: floor,
            dynamic_regularization_epsilon: floor,
        }
    }
}

/// The numerical values of a factor `L` in one precision.
#[derive(Debug, Clone, Default)]
pub(crate) struct Numeric<T> {
    factor: Vec<T>,
}

impl<T: FactorScalar> Numeric<T> {
    /// Factors the `n x n` lower-triangle CSC matrix (`col_ptr`, `rows`) with
    /// `values` on `symbolic`. Ok only when every stored value is finite.
    pub(crate) fn factor(
        &mut self,
        symbolic: &SymbolicCholesky<u32>,
        (n, col_ptr, rows): (usize, &[u32], &[u32]),
        values: &[T],
        workspace: &mut Option<Workspace>,
    ) -> Result<(), FactorError> {
        let structure = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, rows);
        let matrix = SparseColMatRef::new(structure, values);
        let req = symbolic.factorize_numeric_llt_scratch::<T>(Par::Seq, Default::default());
        let stack = workspace
            .get_or_insert_with(|| Workspace::new(req))
            .stack(req);
        self.factor.resize(symbolic.len_val(), T::default());
        let result = symbolic
            .factorize_numeric_llt(
                &mut self.factor,
                matrix,
                Side::Lower,
                T::regularization(),
                Par::Seq,
                stack,
                Default::default(),
            )
            .map(|_| ());
        // A pivot that is not positive (faer's only numerical failure), or one
        // so small that the factor overflowed.
        if result.is_err() || !self.factor.iter().all(|v| v.finite()) {
            return Err(FactorError::NotPositiveDefinite);
        }
        Ok(())
    }

    /// Solves in place for the `columns` right-hand sides `rhs` holds, column
    /// after column, with the factor on `symbolic`.
    pub(crate) fn solve(
        &self,
        symbolic: &SymbolicCholesky<u32>,
        rhs: &mut [T],
        columns: usize,
        workspace: &mut Option<Workspace>,
    ) {
        let n = rhs.len() / columns.max(1);
        let llt = LltRef::<u32, T>::new(symbolic, &self.factor);
        let req = symbolic.solve_in_place_scratch::<T>(columns, Par::Seq);
        let stack = workspace
            .get_or_insert_with(|| Workspace::new(req))
            .stack(req);
        let matrix = MatMut::from_column_major_slice_mut(rhs, n, columns);
        llt.solve_in_place_with_conj(Conj::No, matrix, Par::Seq, stack);
    }

    /// Forgets the values (kept allocated).
    pub(crate) fn clear(&mut self) {
        self.factor.clear();
    }
}
