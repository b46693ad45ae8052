//! The sparse path of the Jacobian: its pattern, read off the compiled plan, and the
//! assembly straight into the pattern's value slots.

use bg_solver::SparsePattern;

use super::Out;
use crate::equations::StateEquations;

impl StateEquations {
    /// The sparsity pattern of [`jacobian`](Self::jacobian), from the compiled plan: the
    /// states each stage's written scalars depend on, propagated in plan order. For a block
    /// of up to [`DENSE_MAX_COLS`](crate::local_jacobian::DENSE_MAX_COLS) local columns
    /// every written scalar depends on every column the block reads (robust against partials
    /// an element sets only in some regimes); for a wider one (a line of many segments) on
    /// the columns of the entries the element's partials set, found by one evaluation at the
    /// initial state. The diagonal is always included.
    ///
    /// `None` if the pattern cannot be formed (it always can for a valid plan).
    #[must_use]
    pub fn jacobian_pattern(&self) -> Option<SparsePattern> {
        let n = self.states.len();
        let compiled = self.compiled();
        let code = &compiled.0;
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for &(i, span) in &code.rows {
            for q in span.range() {
                cols[code.cols[q] as usize].push(i);
            }
        }
        SparsePattern::from_columns(n, &cols).ok()
    }

    /// [`jacobian`](Self::jacobian) straight into the value slots of `pattern` (from
    /// [`jacobian_pattern`](Self::jacobian_pattern)), column by column as
    /// [`SparsePattern::row_idx`]: no n×n matrix. Allocates only on the first call.
    pub fn jacobian_sparse(&self, t: f64, x: &[f64], pattern: &SparsePattern, values: &mut [f64]) {
        values.fill(0.0);
        self.jacobian_into(t, x, &mut Out::Sparse(pattern, values));
    }
}
