//! One sparse iteration matrix A = shift·I − J over a pattern: its column ordering (faer's
//! COLAMD, once), its pivoted factorisation (faer's simplicial LU, whenever the stored pivot
//! order fails) and its refactorisation on the stored order (every other time).

use faer::c64;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::simplicial::{
    factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch, SimplicialLu,
};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams};
use faer::sparse::SparseColMatRef;

use super::factors::Factors;
use super::pattern::SparsePattern;
use super::scalar::Scalar;

/// The matrix has no usable pivot.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Singular;

/// How the factorisations of one matrix went.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct LuCounts {
    /// On the stored pivot order.
    pub(crate) refactorised: usize,
    /// With pivot search (the first, and wherever a stored pivot failed).
    pub(crate) pivoted: usize,
}

/// One sparse n×n matrix shift·I − J over a pattern, and its factors.
pub(crate) struct SparseLu<T: Scalar> {
    factors: Factors<T>,
    /// Inverse of the column ordering (for faer's permutation type).
    col_inv: Vec<usize>,
    /// A on the pattern's slots, for the pivoted factorisation.
    values: Vec<T>,
    /// faer's factors and row order of the last pivoted factorisation.
    pivoted: SimplicialLu<usize, T>,
    row_perm: Vec<usize>,
    row_inv: Vec<usize>,
    mem: MemBuffer,
    req: StackReq,
    /// Zero work column of the refactorisation.
    work: Vec<T>,
    /// The right-hand side in pivot order.
    rhs: Vec<T>,
    counts: LuCounts,
}

impl<T: Scalar> Clone for SparseLu<T> {
    fn clone(&self) -> Self {
        Self {
            factors: self.factors.clone(),
            col_inv: self.col_inv.clone(),
            values: self.values.clone(),
            pivoted: self.pivoted.clone(),
            row_perm: self.row_perm.clone(),
            row_inv: self.row_inv.clone(),
            mem: MemBuffer::new(self.req),
            req: self.req,
            work: self.work.clone(),
            rhs: self.rhs.clone(),
            counts: self.counts,
        }
    }
}

impl<T: Scalar> SparseLu<T> {
    /// The column ordering of `pattern` (COLAMD), done once.
    pub(crate) fn new(pattern: &SparsePattern) -> Result<Self, Singular> {
        let n = pattern.n();
        let symbolic = factorize_symbolic_lu(pattern.symbolic(), LuSymbolicParams::default())
            .map_err(|_| Singular)?;
        let (fwd, inv) = symbolic.col_perm().arrays();
        let (col_perm, col_inv) = (fwd.to_vec(), inv.to_vec());
        let req = factorize_simplicial_numeric_lu_scratch::<usize, T>(n, n);
        let mem = MemBuffer::try_new(req).map_err(|_| Singular)?;
        Ok(Self {
            factors: Factors::new(col_perm),
            col_inv,
            values: vec![T::real(0.0); pattern.nnz()],
            pivoted: SimplicialLu::new(),
            row_perm: vec![0; n],
            row_inv: vec![0; n],
            mem,
            req,
            work: vec![T::real(0.0); n],
            rhs: vec![T::real(0.0); n],
            counts: LuCounts::default(),
        })
    }

    /// Factorise shift·I − J (`jac` on the pattern's slots): on the stored pivot order if
    /// partial pivoting keeps it, else with pivot search.
    pub(crate) fn factor(
        &mut self,
        pattern: &SparsePattern,
        shift: T,
        jac: &[f64],
    ) -> Result<(), Singular> {
        if self.factors.ordered()
            && self
                .factors
                .refactor(pattern, shift, jac, &mut self.work)
                .is_ok()
        {
            self.counts.refactorised += 1;
            return Ok(());
        }
        self.factor_pivoted(pattern, shift, jac)
    }

    /// Factorise shift·I − J with pivot search (faer's), and store its order.
    pub(crate) fn factor_pivoted(
        &mut self,
        pattern: &SparsePattern,
        shift: T,
        jac: &[f64],
    ) -> Result<(), Singular> {
        for (v, &j) in self.values.iter_mut().zip(jac) {
            *v = T::real(-j);
        }
        for &d in pattern.diag() {
            self.values[d] += shift;
        }
        let a = SparseColMatRef::new(pattern.symbolic(), &self.values);
        let n = pattern.n();
        let col_perm = PermRef::new_checked(self.factors.col_perm(), &self.col_inv, n);
        factorize_simplicial_numeric_lu(
            &mut self.row_perm,
            &mut self.row_inv,
            &mut self.pivoted,
            a,
            col_perm,
            MemStack::new(&mut self.mem),
        )
        .map_err(|_| Singular)?;
        self.factors
            .store(&self.pivoted, &self.row_perm, &self.row_inv, pattern);
        self.counts.pivoted += 1;
        Ok(())
    }

    /// How the factorisations went so far.
    pub(crate) fn counts(&self) -> LuCounts {
        self.counts
    }

    /// Stored entries of L and U (both diagonals included).
    pub(crate) fn factor_nnz(&self) -> usize {
        self.factors.nnz()
    }
}

impl SparseLu<f64> {
    /// Solve A·x = b in place (b unchanged if the last factorisation failed).
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        if !self.factors.valid() {
            return;
        }
        self.factors.gather(&mut self.rhs, |i| b[i]);
        self.factors.solve_permuted(&mut self.rhs);
        self.factors.scatter(&self.rhs, |i, v| b[i] = v);
    }
}

impl SparseLu<c64> {
    /// Solve A·x = b in place, b = re + i·im (unchanged if the last factorisation failed).
    pub(crate) fn solve(&mut self, re: &mut [f64], im: &mut [f64]) {
        if !self.factors.valid() {
            return;
        }
        self.factors
            .gather(&mut self.rhs, |i| c64::new(re[i], im[i]));
        self.factors.solve_permuted(&mut self.rhs);
        self.factors.scatter(&self.rhs, |i, v| {
            re[i] = v.re;
            im[i] = v.im;
        });
    }
}
