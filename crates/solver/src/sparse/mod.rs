//! Sparse LU of Radau's iteration matrices (γ/h)I − J and ((α + iβ)/h)I − J over the fixed
//! pattern of J (compressed sparse columns, the diagonal always included).
//!
//! KLU's scheme (Davis & Palamadai Natarajan 2010): a column ordering once per pattern
//! (faer's COLAMD); a pivoted factorisation P·A·Q = L·U (faer's left-looking
//! Gilbert–Peierls with partial pivoting) fixes the row order and the patterns of L and U;
//! every later matrix of the same pattern is *refactorised* on those stored patterns, a flat
//! left-looking loop with no depth-first search and no pivot search. The pivot check of the
//! refactorisation is partial pivoting's own (|u_kk| ≥ |l_ik| before scaling, for every i
//! of column k): where the stored pivot would no longer be the column's largest, or is not
//! finite, the matrix is factorised afresh with pivoting and its new order stored. So the
//! factors are always the ones partial pivoting gives, and the refactorisation repeats
//! faer's arithmetic operation for operation: the same bits, in a fraction of the time.
//!
//! - [`pattern`]: [`SparsePattern`], the Jacobian's pattern.
//! - `scalar`: the two scalar types (f64, c64) and their pivot comparison.
//! - `factors`: L and U in pivot order, their refactorisation and triangular solves.
//! - `lu`: [`SparseLu`], one iteration matrix: ordering, pivoted factorisation, refactorisation.

mod factors;
mod lu;
mod pattern;
mod scalar;
#[cfg(test)]
mod tests;

pub(crate) use lu::SparseLu;
pub use pattern::SparsePattern;
