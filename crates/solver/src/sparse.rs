//! Sparse LU of Radau's iteration matrices (γ/h)I − J and ((α + iβ)/h)I − J over the fixed
//! pattern of J (compressed sparse columns, the diagonal always included): faer 0.24's sparse
//! LU, whose symbolic analysis (COLAMD column ordering, elimination tree, supernodes) is done
//! once per pattern and whose numeric factorisation (partial pivoting within the symbolic
//! structure) is repeated whenever h or J changes.
//!
//! Why faer: it is already in the tree (diffsol builds it; only its `sparse-linalg` feature
//! is added), it has the symbolic/numeric split KLU has, and it factors real and complex
//! matrices alike, which Radau needs both of. Solves take their scratch from a buffer sized
//! once, so a Newton iteration allocates nothing; a numeric factorisation reuses the vectors
//! of the previous one (it may grow them the first few times).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::traits::ComplexField;
use faer::{c64, Conj, MatMut, Par, Spec};
use nalgebra::Complex;

/// The sparsity pattern of an n×n Jacobian in compressed sparse columns: the rows of column
/// j are `row_idx[col_ptr[j]..col_ptr[j + 1]]`, sorted, without duplicates.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SparsePattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Position of the diagonal entry of each column in `row_idx`.
    diag: Vec<usize>,
}

/// Why a pattern was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("invalid sparsity pattern: {0}")]
pub struct PatternError(String);

impl SparsePattern {
    /// The pattern of an n×n matrix from the rows of each column (any order, duplicates
    /// allowed); the diagonal is added where missing.
    ///
    /// # Errors
    /// If `columns` does not have n entries or names a row ≥ n.
    pub fn from_columns(n: usize, columns: &[Vec<usize>]) -> Result<Self, PatternError> {
        if columns.len() != n {
            return Err(PatternError(format!(
                "{} columns for an {n}×{n} matrix",
                columns.len()
            )));
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut diag = Vec::with_capacity(n);
        col_ptr.push(0);
        for (j, rows) in columns.iter().enumerate() {
            if let Some(&i) = rows.iter().find(|&&i| i >= n) {
                return Err(PatternError(format!("row {i} in column {j}, n = {n}")));
            }
            let mut rows = rows.clone();
            rows.push(j);
            rows.sort_unstable();
            rows.dedup();
            let start = row_idx.len();
            diag.push(start + rows.iter().position(|&i| i == j).unwrap_or(0));
            row_idx.extend(rows);
            col_ptr.push(row_idx.len());
        }
        Ok(Self {
            n,
            col_ptr,
            row_idx,
            diag,
        })
    }

    /// The full (dense) pattern of an n×n matrix.
    #[must_use]
    pub fn dense(n: usize) -> Self {
        let all: Vec<usize> = (0..n).collect();
        let cols = vec![all; n];
        // Cannot fail: n columns, rows < n.
        Self::from_columns(n, &cols).unwrap_or_else(|_| Self::from_parts_empty())
    }

    fn from_parts_empty() -> Self {
        Self {
            n: 0,
            col_ptr: vec![0],
            row_idx: Vec::new(),
            diag: Vec::new(),
        }
    }

    /// Number of rows and columns.
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }
    /// Number of stored entries (the diagonal included).
    #[must_use]
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
    /// Stored entries over n² (1 for a dense pattern).
    #[must_use]
    pub fn density(&self) -> f64 {
        self.nnz() as f64 / (self.n.max(1) * self.n.max(1)) as f64
    }
    /// Column start offsets (n + 1 of them).
    #[must_use]
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }
    /// Row of each stored entry.
    #[must_use]
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }
    /// The slot of entry (i, j) in the value array, if it is stored.
    #[must_use]
    pub fn slot(&self, i: usize, j: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        self.row_idx[a..b].binary_search(&i).ok().map(|k| a + k)
    }

    fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }
}

/// The matrix has no usable pivot.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Singular;

/// One sparse n×n matrix diag·I − J over a pattern, and its factors.
pub(crate) struct SparseLu<T: ComplexField> {
    values: Vec<T>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, T>,
    factored: bool,
    mem: MemBuffer,
    req: StackReq,
    /// The right-hand side as one column.
    rhs: Vec<T>,
}

impl<T: Scalar> Clone for SparseLu<T> {
    fn clone(&self) -> Self {
        Self {
            values: self.values.clone(),
            symbolic: self.symbolic.clone(),
            numeric: self.numeric.clone(),
            factored: self.factored,
            mem: MemBuffer::new(self.req),
            req: self.req,
            rhs: self.rhs.clone(),
        }
    }
}

/// The two scalar types of the iteration matrices.
pub(crate) trait Scalar: ComplexField + Copy {
    fn real(v: f64) -> Self;
    fn plus(self, other: Self) -> Self;
}
impl Scalar for f64 {
    fn real(v: f64) -> Self {
        v
    }
    fn plus(self, other: Self) -> Self {
        self + other
    }
}
impl Scalar for c64 {
    fn real(v: f64) -> Self {
        Complex::new(v, 0.0)
    }
    fn plus(self, other: Self) -> Self {
        self + other
    }
}

impl<T: Scalar> SparseLu<T> {
    /// Symbolic analysis of `pattern`, done once.
    pub(crate) fn new(pattern: &SparsePattern) -> Result<Self, Singular> {
        let symbolic = factorize_symbolic_lu(pattern.symbolic(), LuSymbolicParams::default())
            .map_err(|_| Singular)?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<T>(
                Par::Seq,
                Spec::<PartialPivLuParams, T>::default(),
            ),
            symbolic.solve_in_place_scratch::<T>(1, Par::Seq),
        ]);
        let mem = MemBuffer::try_new(req).map_err(|_| Singular)?;
        Ok(Self {
            values: vec![T::real(0.0); pattern.nnz()],
            symbolic,
            numeric: NumericLu::new(),
            factored: false,
            mem,
            req,
            rhs: vec![T::real(0.0); pattern.n()],
        })
    }

    /// Set the values to diag·I − J (`jac` on the pattern's slots) and factorise.
    pub(crate) fn factor(
        &mut self,
        pattern: &SparsePattern,
        diag: T,
        jac: &[f64],
    ) -> Result<(), Singular> {
        for (v, &j) in self.values.iter_mut().zip(jac) {
            *v = T::real(-j);
        }
        for &d in &pattern.diag {
            self.values[d] = self.values[d].plus(diag);
        }
        self.factored = false;
        let a = SparseColMatRef::new(pattern.symbolic(), &self.values);
        let stack = MemStack::new(&mut self.mem);
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                a,
                Par::Seq,
                stack,
                Spec::<PartialPivLuParams, T>::default(),
            )
            .map_err(|_| Singular)?;
        self.factored = true;
        Ok(())
    }

    /// Solve in place the column held in `self.rhs`.
    fn solve_rhs(&mut self) {
        if !self.factored {
            return;
        }
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let n = self.rhs.len();
        let col = MatMut::from_column_major_slice_mut(&mut self.rhs, n, 1);
        let stack = MemStack::new(&mut self.mem);
        lu.solve_in_place_with_conj(Conj::No, col, Par::Seq, stack);
    }
}

impl SparseLu<f64> {
    /// Solve A·x = b in place.
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        self.rhs.copy_from_slice(b);
        self.solve_rhs();
        b.copy_from_slice(&self.rhs);
    }
}

impl SparseLu<c64> {
    /// Solve A·x = b in place, b = re + i·im.
    pub(crate) fn solve(&mut self, re: &mut [f64], im: &mut [f64]) {
        for ((v, r), i) in self.rhs.iter_mut().zip(re.iter()).zip(im.iter()) {
            *v = Complex::new(*r, *i);
        }
        self.solve_rhs();
        for ((v, r), i) in self.rhs.iter().zip(re.iter_mut()).zip(im.iter_mut()) {
            *r = v.re;
            *i = v.im;
        }
    }
}
