//! The real system (γ/h)I − J: factors and solves in place.

use pulp::{Arch, Simd, WithSimd};

use super::{axpy, axpy2, axpy_twice, nonzero_rows, pivot, widen, Pattern, Singular};

/// A real n×n matrix and, after [`RealLu::factor`], its factors P·A = L·U in place.
#[derive(Clone, Debug)]
pub(crate) struct RealLu {
    pub(super) n: usize,
    /// Column-major; L below the diagonal (unit diagonal implied), U on and above it.
    pub(super) a: Vec<f64>,
    pub(super) pat: Pattern,
    arch: Arch,
}

impl RealLu {
    pub(crate) fn new(n: usize) -> Self {
        Self::with_arch(n, Arch::new())
    }

    /// With a given instruction set (the tests compare them).
    pub(super) fn with_arch(n: usize, arch: Arch) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            pat: Pattern::new(n),
            arch,
        }
    }

    /// Set the matrix to `diag·I − J` (J column-major), ready for [`Self::factor`].
    pub(crate) fn set_shifted(&mut self, diag: f64, jac: &[f64]) {
        for (dst, &j) in self.a.iter_mut().zip(jac) {
            *dst = -j;
        }
        for k in 0..self.n {
            self.a[k * self.n + k] += diag;
        }
    }

    /// Factorise in place.
    pub(crate) fn factor(&mut self) -> Result<(), Singular> {
        struct Op<'a>(&'a mut RealLu);
        impl WithSimd for Op<'_> {
            type Output = Result<(), Singular>;
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) -> Self::Output {
                self.0.factor_kernel(simd)
            }
        }
        self.arch.dispatch(Op(self))
    }

    #[inline(always)]
    fn factor_kernel<S: Simd>(&mut self, simd: S) -> Result<(), Singular> {
        let n = self.n;
        let pat = &mut self.pat;
        for k in 0..n {
            let (left, right) = self.a.split_at_mut((k + 1) * n);
            let colk = &mut left[k * n..];
            let p = k + pivot(n - k, |i| colk[k + i].abs()).ok_or(Singular)?;
            pat.piv[k] = p;
            colk.swap(k, p);
            let inv = 1.0 / colk[k];
            for v in &mut colk[k + 1..] {
                *v *= inv;
            }
            let (lo, hi) = nonzero_rows(k + 1, n, |i| colk[i] != 0.0);
            let (lo, hi) = widen(lo, hi, k + 1, n);
            pat.lo[k] = lo;
            pat.hi[k] = hi;
            if lo == hi {
                if p != k {
                    for colj in right.chunks_exact_mut(n) {
                        colj.swap(k, p);
                    }
                }
                continue;
            }
            // One pass over the trailing columns: rows k and p interchanged, and those with
            // a non-zero (not NaN) in row k updated, two at a time (the first of a pair
            // waits in `pending`).
            let l = &colk[lo..hi];
            let mut pending: Option<&mut [f64]> = None;
            for colj in right.chunks_exact_mut(n) {
                if p != k {
                    colj.swap(k, p);
                }
                if colj[k].abs() > 0.0 {
                    match pending.take() {
                        None => pending = Some(colj),
                        Some(x) => {
                            let (a, b) = (x[k], colj[k]);
                            axpy2(simd, &mut x[lo..hi], &mut colj[lo..hi], l, a, b);
                        }
                    }
                }
            }
            if let Some(x) = pending {
                let a = x[k];
                axpy(simd, &mut x[lo..hi], l, a);
            }
        }
        for k in 0..n {
            let u = &self.a[k * n..k * n + k];
            pat.top[k] = u.iter().position(|v| *v != 0.0).unwrap_or(k);
        }
        Ok(())
    }

    /// Solve A·x = b in place with the factors.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        struct Op<'a>(&'a RealLu, &'a mut [f64]);
        impl WithSimd for Op<'_> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) {
                self.0.solve_kernel(simd, self.1);
            }
        }
        self.arch.dispatch(Op(self, b));
    }

    #[inline(always)]
    fn solve_kernel<S: Simd>(&self, simd: S, b: &mut [f64]) {
        let (n, a, pat) = (self.n, &self.a, &self.pat);
        // L y = P b, interchanging as the factorisation did.
        for k in 0..n {
            b.swap(k, pat.piv[k]);
            let bk = b[k];
            if bk != 0.0 {
                let (lo, hi) = (pat.lo[k], pat.hi[k]);
                axpy(simd, &mut b[lo..hi], &a[k * n + lo..k * n + hi], bk);
            }
        }
        // U x = y, column-oriented, columns k1 = k0 + 1 and k0 in one pass over the rows
        // above k0 (each row still receives k1's term first).
        let mut k = n;
        while k >= 2 {
            let (k1, k0) = (k - 1, k - 2);
            b[k1] /= a[k1 * n + k1];
            let x1 = b[k1];
            b[k0] -= a[k1 * n + k0] * x1;
            b[k0] /= a[k0 * n + k0];
            let x0 = b[k0];
            let top = widen(pat.top[k1].min(pat.top[k0]), k0, 0, k0).0;
            let (u1, u0) = (&a[k1 * n + top..k1 * n + k0], &a[k0 * n + top..k0 * n + k0]);
            axpy_twice(&mut b[top..k0], u1, x1, u0, x0);
            k -= 2;
        }
        if k == 1 {
            b[0] /= a[0];
        }
    }
}
