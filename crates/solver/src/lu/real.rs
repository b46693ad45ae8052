//! The real system (γ/h)I − J: factors and solves in place.

use pulp::{Arch, Simd, WithSimd};

use super::{
    axpy, axpy2, axpy_twice, non_finite_bits, nonzero_rows, padded_end, pivot_real, widen, Pattern,
    Singular, PAD,
};

/// A real n×n matrix and, after [`RealLu::factor`], its factors P·A = L·U in place.
#[derive(Clone, Debug)]
pub(crate) struct RealLu {
    pub(super) n: usize,
    /// Column stride: n rows and [`PAD`] rows of padding.
    pub(super) ld: usize,
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
        let ld = n + PAD;
        Self {
            n,
            ld,
            a: vec![0.0; ld * n],
            pat: Pattern::new(n),
            arch,
        }
    }

    /// Set the matrix to `diag·I − J` (J column-major), ready for [`Self::factor`].
    pub(crate) fn set_shifted(&mut self, diag: f64, jac: &[f64]) {
        let (n, ld) = (self.n, self.ld);
        for k in 0..n {
            let (dst, src) = (&mut self.a[k * ld..k * ld + n], &jac[k * n..k * n + n]);
            for (d, &j) in dst.iter_mut().zip(src) {
                *d = -j;
            }
            dst[k] += diag;
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
        let (n, ld) = (self.n, self.ld);
        let Self { a, pat, .. } = self;
        for k in 0..n {
            let (left, right) = a.split_at_mut((k + 1) * ld);
            let colk = &mut left[k * ld..];
            let p = k + pivot_real(&colk[k..n]).ok_or(Singular)?;
            pat.piv[k] = p;
            colk.swap(k, p);
            let inv = 1.0 / colk[k];
            // l = a·(1/pivot). A non-finite l: the textbook LU refuses the matrix (see
            // `mod.rs`), so does this one, before skipping anything.
            let mut bad = 0;
            for v in &mut colk[k + 1..n] {
                *v *= inv;
                bad |= non_finite_bits(*v);
            }
            if bad != 0 {
                return Err(Singular);
            }
            let l = &colk[k + 1..n];
            let (pos, rpos) = (
                l.iter().position(|v| *v != 0.0),
                l.iter().rposition(|v| *v != 0.0),
            );
            let (lo, hi) = nonzero_rows(k + 1, n, pos, rpos);
            let (lo, hi) = widen(lo, hi, k + 1, n);
            pat.lo[k] = lo;
            pat.hi[k] = hi;
            let end = padded_end(lo, hi);
            // Known to the compiler, these bounds leave the loops below without bounds
            // checks.
            assert!(k < ld && p < ld && lo <= end && end <= ld);
            // Rows k and p interchanged in the trailing columns (LINPACK's layout).
            if p != k {
                for x in right.chunks_exact_mut(ld) {
                    x.swap(k, p);
                }
            }
            if lo == hi {
                continue;
            }
            // The trailing columns, two adjacent ones at a time (sharing the loads of l),
            // those with u = a[k, j] ≠ 0 updated over the non-zero rows of l widened to a
            // multiple of four (zero rows of l or padding).
            let l = &colk[lo..end];
            let mut pairs = right.chunks_exact_mut(2 * ld);
            for pair in &mut pairs {
                let (x, y) = pair.split_at_mut(ld);
                let (u0, u1) = (x[k], y[k]);
                let (x, y) = (&mut x[lo..end], &mut y[lo..end]);
                match (u0 != 0.0, u1 != 0.0) {
                    (true, true) => axpy2(simd, x, y, l, u0, u1),
                    (false, false) => {}
                    (true, false) => axpy(simd, x, l, u0),
                    (false, true) => axpy(simd, y, l, u1),
                }
            }
            let x = pairs.into_remainder();
            if x.len() == ld && x[k] != 0.0 {
                let u = x[k];
                axpy(simd, &mut x[lo..end], l, u);
            }
        }
        // U: where its columns start, and whether it is finite (if not, the textbook LU
        // refuses the matrix: see `mod.rs`).
        let mut bad = 0;
        for k in 0..n {
            let u = &a[k * ld..k * ld + k];
            pat.top[k] = u.iter().position(|v| *v != 0.0).unwrap_or(k);
            bad |= u.iter().fold(0, |b, &v| b | non_finite_bits(v));
        }
        if bad != 0 {
            return Err(Singular);
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
        let (n, ld, a, pat) = (self.n, self.ld, &self.a, &self.pat);
        // L y = P b, interchanging as the factorisation did. The factors are finite (or
        // refused), so b[k] = 0 is skipped exactly; the zeros of L only for finite b[k]
        // (0·∞ is NaN).
        for k in 0..n {
            b.swap(k, pat.piv[k]);
            let bk = b[k];
            if bk != 0.0 {
                let (lo, hi) = if bk.is_finite() {
                    (pat.lo[k], pat.hi[k])
                } else {
                    (k + 1, n)
                };
                axpy(simd, &mut b[lo..hi], &a[k * ld + lo..k * ld + hi], bk);
            }
        }
        // U x = y, column-oriented, columns k1 = k0 + 1 and k0 in one pass over the rows
        // above k0 (each row still receives k1's term first); the zeros of U above top are
        // skipped for finite x only.
        let mut k = n;
        while k >= 2 {
            let (k1, k0) = (k - 1, k - 2);
            b[k1] /= a[k1 * ld + k1];
            let x1 = b[k1];
            b[k0] -= a[k1 * ld + k0] * x1;
            b[k0] /= a[k0 * ld + k0];
            let x0 = b[k0];
            let top = if x1.is_finite() && x0.is_finite() {
                widen(pat.top[k1].min(pat.top[k0]), k0, 0, k0).0
            } else {
                0
            };
            let (u1, u0) = (
                &a[k1 * ld + top..k1 * ld + k0],
                &a[k0 * ld + top..k0 * ld + k0],
            );
            axpy_twice(&mut b[top..k0], u1, x1, u0, x0);
            k -= 2;
        }
        if k == 1 {
            b[0] /= a[0];
        }
    }
}
