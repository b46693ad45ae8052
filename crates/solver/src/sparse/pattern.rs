//! The fixed sparsity pattern of a Jacobian, in compressed sparse columns with the diagonal
//! always stored (the iteration matrices add to it).

use faer::sparse::SymbolicSparseColMatRef;

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

    /// The slot of each column's diagonal entry.
    pub(crate) fn diag(&self) -> &[usize] {
        &self.diag
    }

    pub(crate) fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }
}
