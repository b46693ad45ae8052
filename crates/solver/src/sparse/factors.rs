//! L and U of one iteration matrix in pivot order, stored flat: P·A·Q = L·U with L unit
//! lower and U upper triangular, P the row order of the last pivoted factorisation and Q the
//! column ordering. Refactorisation (new values, same P, Q and patterns) and the triangular
//! solves run on these arrays alone, allocating nothing.
//!
//! The refactorisation is Gilbert–Peierls's left-looking column step with the reach already
//! known: column k of P·A·Q is scattered into a dense work vector x, then for each row j of
//! U's column k, in the stored (topological) order, u_jk = x_j and x ← x − l_·j·u_jk; the
//! pivot is u_kk = x_k and l_ik = x_i / u_kk. The order of every operation is faer's, so the
//! factors are faer's to the bit whenever its pivot search would choose the same rows.

use faer::sparse::linalg::lu::simplicial::SimplicialLu;

use super::pattern::SparsePattern;
use super::scalar::Scalar;

/// A stored pivot is no longer the largest of its column, or is not finite: the matrix
/// needs a pivoted factorisation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PivotLost;

#[derive(Clone, Debug)]
pub(crate) struct Factors<T> {
    /// Whether L and U hold the factors of the last matrix.
    valid: bool,
    /// Whether a pivot order and the patterns are stored (after a pivoted factorisation).
    ordered: bool,
    /// The row of A at step p: row_perm[p].
    row_perm: Vec<usize>,
    /// The column of A eliminated at step k: col_perm[k] (the fill-reducing ordering).
    col_perm: Vec<usize>,
    /// The pivot step of the row of each stored entry of A (indexed like the pattern's slots).
    a_row: Vec<usize>,
    /// L below its unit diagonal, by columns: rows in l_row[l_ptr[k]..l_ptr[k + 1]].
    l_ptr: Vec<usize>,
    l_row: Vec<usize>,
    l_val: Vec<T>,
    /// U above its diagonal, by columns, in elimination order.
    u_ptr: Vec<usize>,
    u_row: Vec<usize>,
    u_val: Vec<T>,
    /// 1/u_kk.
    u_inv: Vec<T>,
}

impl<T: Scalar> Factors<T> {
    /// No factors yet, the column ordering `col_perm`.
    pub(crate) fn new(col_perm: Vec<usize>) -> Self {
        let n = col_perm.len();
        Self {
            valid: false,
            ordered: false,
            row_perm: Vec::with_capacity(n),
            col_perm,
            a_row: Vec::new(),
            l_ptr: Vec::with_capacity(n + 1),
            l_row: Vec::new(),
            l_val: Vec::new(),
            u_ptr: Vec::with_capacity(n + 1),
            u_row: Vec::new(),
            u_val: Vec::new(),
            u_inv: vec![T::real(0.0); n],
        }
    }

    /// The column ordering Q.
    pub(crate) fn col_perm(&self) -> &[usize] {
        &self.col_perm
    }
    /// Whether a pivot order is stored to refactorise on.
    pub(crate) fn ordered(&self) -> bool {
        self.ordered
    }
    /// Whether the factors are those of the last matrix.
    pub(crate) fn valid(&self) -> bool {
        self.valid
    }
    /// Stored entries of L and U (both diagonals included).
    pub(crate) fn nnz(&self) -> usize {
        self.l_row.len() + self.u_row.len() + 2 * self.u_inv.len()
    }

    /// Take the factors, row order and patterns of faer's pivoted factorisation (L's rows
    /// already in pivot order, its unit diagonal first in each column; U's diagonal last).
    pub(crate) fn store(
        &mut self,
        lu: &SimplicialLu<usize, T>,
        row_perm: &[usize],
        row_inv: &[usize],
        pattern: &SparsePattern,
    ) {
        let n = self.col_perm.len();
        self.row_perm.clear();
        self.row_perm.extend_from_slice(row_perm);
        self.a_row.clear();
        self.a_row
            .extend(pattern.row_idx().iter().map(|&r| row_inv[r]));
        let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
        self.l_ptr.clear();
        self.l_row.clear();
        self.l_val.clear();
        self.u_ptr.clear();
        self.u_row.clear();
        self.u_val.clear();
        self.l_ptr.push(0);
        self.u_ptr.push(0);
        for k in 0..n {
            let (rows, vals) = (l.row_idx_of_col_raw(k), l.val_of_col(k));
            debug_assert_eq!(rows.first(), Some(&k));
            self.l_row
                .extend_from_slice(rows.get(1..).unwrap_or_default());
            self.l_val
                .extend_from_slice(vals.get(1..).unwrap_or_default());
            self.l_ptr.push(self.l_row.len());
            let (rows, vals) = (u.row_idx_of_col_raw(k), u.val_of_col(k));
            debug_assert_eq!(rows.last(), Some(&k));
            let m = rows.len().saturating_sub(1);
            self.u_row.extend_from_slice(&rows[..m]);
            self.u_val.extend_from_slice(&vals[..m]);
            self.u_ptr.push(self.u_row.len());
            self.u_inv[k] = vals.get(m).map_or(T::real(0.0), |&d| d).inv();
        }
        self.ordered = true;
        self.valid = true;
    }

    /// Refactorise shift·I − J (`jac` on the pattern's slots) on the stored order and
    /// patterns. `x` is a zero work vector of length n, left zero.
    ///
    /// # Errors
    /// [`PivotLost`] (the factors then invalid) where partial pivoting would choose another
    /// row than the stored one, or a pivot is not finite.
    pub(crate) fn refactor(
        &mut self,
        pattern: &SparsePattern,
        shift: T,
        jac: &[f64],
        x: &mut [T],
    ) -> Result<(), PivotLost> {
        let zero = T::real(0.0);
        let (ptr, diag) = (pattern.col_ptr(), pattern.diag());
        self.valid = false;
        for (k, &q) in self.col_perm.iter().enumerate() {
            // Column q of A = shift·I − J, in pivot order.
            for s in ptr[q]..ptr[q + 1] {
                let mut v = T::real(-jac[s]);
                if s == diag[q] {
                    v += shift;
                }
                x[self.a_row[s]] += v;
            }
            // x ← x − l_·j·u_jk over U's column k.
            let (ua, ub) = (self.u_ptr[k], self.u_ptr[k + 1]);
            for (&j, u) in self.u_row[ua..ub].iter().zip(&mut self.u_val[ua..ub]) {
                let xj = x[j];
                x[j] = zero;
                *u = xj;
                let (la, lb) = (self.l_ptr[j], self.l_ptr[j + 1]);
                for (&i, &l) in self.l_row[la..lb].iter().zip(&self.l_val[la..lb]) {
                    x[i] -= l * xj;
                }
            }
            let pivot = x[k];
            x[k] = zero;
            let (la, lb) = (self.l_ptr[k], self.l_ptr[k + 1]);
            let rows = &self.l_row[la..lb];
            if !pivot.finite() || rows.iter().any(|&i| x[i].exceeds(pivot)) {
                for &i in rows {
                    x[i] = zero;
                }
                return Err(PivotLost);
            }
            // l_ik = x_i / u_kk (as faer: times the reciprocal).
            let inv = pivot.inv();
            self.u_inv[k] = inv;
            for (&i, l) in rows.iter().zip(&mut self.l_val[la..lb]) {
                *l = x[i] * inv;
                x[i] = zero;
            }
        }
        self.valid = true;
        Ok(())
    }

    /// c ← P·b: `load(i)` gives b_i.
    pub(crate) fn gather(&self, c: &mut [T], load: impl Fn(usize) -> T) {
        for (c, &r) in c.iter_mut().zip(&self.row_perm) {
            *c = load(r);
        }
    }

    /// x = Q·c: `store(i, x_i)`.
    pub(crate) fn scatter(&self, c: &[T], mut store: impl FnMut(usize, T)) {
        for (&c, &q) in c.iter().zip(&self.col_perm) {
            store(q, c);
        }
    }

    /// c ← U⁻¹·L⁻¹·c, in place (faer's order of operations).
    pub(crate) fn solve_permuted(&self, c: &mut [T]) {
        let n = self.u_inv.len();
        for j in 0..n {
            let cj = c[j];
            let (a, b) = (self.l_ptr[j], self.l_ptr[j + 1]);
            for (&i, &l) in self.l_row[a..b].iter().zip(&self.l_val[a..b]) {
                c[i] -= l * cj;
            }
        }
        for k in (0..n).rev() {
            let ck = c[k] * self.u_inv[k];
            c[k] = ck;
            let (a, b) = (self.u_ptr[k], self.u_ptr[k + 1]);
            for (&j, &u) in self.u_row[a..b].iter().zip(&self.u_val[a..b]).rev() {
                c[j] -= u * ck;
            }
        }
    }
}
