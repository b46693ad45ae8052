//! The problem the integrators solve, dy/dt = f(t, y): a small trait, knowing nothing of
//! where the equations come from (the way diffsol separates its `OdeEquations` from its
//! methods). `bondgraph` implements it for its state equations.

/// The dense Jacobian's matrix type, re-exported so that implementing [`OdeSystem`] needs no
/// direct dependency on nalgebra.
pub use nalgebra::DMatrix;

pub use crate::sparse::SparsePattern;

/// What the integrator needs from the equations dy/dt = f(t, y).
pub trait OdeSystem {
    /// Number of states.
    fn n(&self) -> usize;
    /// dy = f(t, y).
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]);
    /// The dense Jacobian ∂f/∂y at (t, y) into the n×n `jac`. `fy` = f(t, y), already
    /// evaluated, for finite differences (which then cost n right-hand sides, not n + 1).
    fn jacobian(&mut self, t: f64, y: &[f64], fy: &[f64], jac: &mut DMatrix<f64>);

    /// The sparsity pattern of ∂f/∂y, if the system knows it: what the sparse linear algebra
    /// needs. `None` (the default) keeps the integrator dense.
    fn jacobian_pattern(&self) -> Option<SparsePattern> {
        None
    }

    /// ∂f/∂y at (t, y) into `values`, one per stored entry of `pattern` (column by column,
    /// as [`SparsePattern::row_idx`]). The default evaluates the dense Jacobian into
    /// `dense` (resized to n×n on the first call) and gathers the pattern's entries from it;
    /// a system that can assemble straight into the pattern should.
    fn jacobian_sparse(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        pattern: &SparsePattern,
        values: &mut [f64],
        dense: &mut DMatrix<f64>,
    ) {
        let n = pattern.n();
        if dense.shape() != (n, n) {
            *dense = DMatrix::zeros(n, n);
        }
        self.jacobian(t, y, fy, dense);
        let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
        for j in 0..n {
            for k in ptr[j]..ptr[j + 1] {
                values[k] = dense[(rows[k], j)];
            }
        }
    }
}
