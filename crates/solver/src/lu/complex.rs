//! The complex system ((α + iβ)/h)I − J on separate real and imaginary planes: factors and
//! solves in place.

use nalgebra::Complex;
use pulp::{Arch, Simd, WithSimd};

use super::{caxpy, caxpy2, caxpy_twice, nonzero_rows, pivot, widen, Pattern, Singular};

/// A complex n×n matrix on separate real and imaginary planes and, after
/// [`ComplexLu::factor`], its factors P·A = L·U in place.
#[derive(Clone, Debug)]
pub(crate) struct ComplexLu {
    n: usize,
    /// Column-major real and imaginary parts, laid out as in [`RealLu`].
    pub(super) re: Vec<f64>,
    pub(super) im: Vec<f64>,
    pub(super) pat: Pattern,
    arch: Arch,
}

impl ComplexLu {
    pub(crate) fn new(n: usize) -> Self {
        Self::with_arch(n, Arch::new())
    }

    pub(super) fn with_arch(n: usize, arch: Arch) -> Self {
        Self {
            n,
            re: vec![0.0; n * n],
            im: vec![0.0; n * n],
            pat: Pattern::new(n),
            arch,
        }
    }

    /// Set the matrix to `diag·I − J` (J real, column-major), ready for [`Self::factor`].
    pub(crate) fn set_shifted(&mut self, diag: Complex<f64>, jac: &[f64]) {
        for (dst, &j) in self.re.iter_mut().zip(jac) {
            *dst = -j;
        }
        self.im.fill(0.0);
        for k in 0..self.n {
            self.re[k * self.n + k] += diag.re;
            self.im[k * self.n + k] += diag.im;
        }
    }

    /// Factorise in place.
    pub(crate) fn factor(&mut self) -> Result<(), Singular> {
        struct Op<'a>(&'a mut ComplexLu);
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
            let (left_re, right_re) = self.re.split_at_mut((k + 1) * n);
            let (left_im, right_im) = self.im.split_at_mut((k + 1) * n);
            let kr = &mut left_re[k * n..];
            let ki = &mut left_im[k * n..];
            // Size |re| + |im|, as LAPACK does.
            let size = |i: usize| kr[k + i].abs() + ki[k + i].abs();
            let p = k + pivot(n - k, size).ok_or(Singular)?;
            pat.piv[k] = p;
            kr.swap(k, p);
            ki.swap(k, p);
            // 1/pivot and the scaling, with the operations of `num_complex`.
            let (cr, ci) = (kr[k], ki[k]);
            let ns = cr * cr + ci * ci;
            let (ir, ii) = ((1.0 * cr + 0.0 * ci) / ns, (0.0 * cr - 1.0 * ci) / ns);
            for (r, m) in kr[k + 1..].iter_mut().zip(&mut ki[k + 1..]) {
                let (vr, vi) = (*r, *m);
                *r = vr * ir - vi * ii;
                *m = vr * ii + vi * ir;
            }
            let (lo, hi) = nonzero_rows(k + 1, n, |i| kr[i] != 0.0 || ki[i] != 0.0);
            let (lo, hi) = widen(lo, hi, k + 1, n);
            pat.lo[k] = lo;
            pat.hi[k] = hi;
            let trailing = right_re
                .chunks_exact_mut(n)
                .zip(right_im.chunks_exact_mut(n));
            if lo == hi {
                if p != k {
                    for (cr, ci) in trailing {
                        cr.swap(k, p);
                        ci.swap(k, p);
                    }
                }
                continue;
            }
            // Interchange and update in one pass, as in the real kernel.
            let l = (&kr[lo..hi], &ki[lo..hi]);
            let mut pending: Option<(&mut [f64], &mut [f64])> = None;
            for (cr, ci) in trailing {
                if p != k {
                    cr.swap(k, p);
                    ci.swap(k, p);
                }
                if cr[k].abs() + ci[k].abs() > 0.0 {
                    match pending.take() {
                        None => pending = Some((cr, ci)),
                        Some((xr, xi)) => {
                            let (a, b) = ((xr[k], xi[k]), (cr[k], ci[k]));
                            let (x, y) = (
                                (&mut xr[lo..hi], &mut xi[lo..hi]),
                                (&mut cr[lo..hi], &mut ci[lo..hi]),
                            );
                            caxpy2(simd, x.0, x.1, y.0, y.1, l.0, l.1, a, b);
                        }
                    }
                }
            }
            if let Some((xr, xi)) = pending {
                let a = (xr[k], xi[k]);
                caxpy(simd, &mut xr[lo..hi], &mut xi[lo..hi], l.0, l.1, a);
            }
        }
        for k in 0..n {
            let (ur, ui) = (&self.re[k * n..k * n + k], &self.im[k * n..k * n + k]);
            pat.top[k] = (0..k)
                .position(|i| ur[i] != 0.0 || ui[i] != 0.0)
                .unwrap_or(k);
        }
        Ok(())
    }

    /// Solve A·x = b in place with the factors, b = re + i·im.
    pub(crate) fn solve(&self, re: &mut [f64], im: &mut [f64]) {
        struct Op<'a>(&'a ComplexLu, &'a mut [f64], &'a mut [f64]);
        impl WithSimd for Op<'_> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) {
                self.0.solve_kernel(simd, self.1, self.2);
            }
        }
        self.arch.dispatch(Op(self, re, im));
    }

    #[inline(always)]
    fn solve_kernel<S: Simd>(&self, simd: S, br: &mut [f64], bi: &mut [f64]) {
        let (n, re, im, pat) = (self.n, &self.re, &self.im, &self.pat);
        for k in 0..n {
            let p = pat.piv[k];
            br.swap(k, p);
            bi.swap(k, p);
            let x = (br[k], bi[k]);
            if x.0 != 0.0 || x.1 != 0.0 {
                let (lo, hi) = (pat.lo[k], pat.hi[k]);
                let l = k * n + lo..k * n + hi;
                caxpy(
                    simd,
                    &mut br[lo..hi],
                    &mut bi[lo..hi],
                    &re[l.clone()],
                    &im[l],
                    x,
                );
            }
        }
        // U x = y, two columns per pass as in the real solve.
        // b[k] / u[k, k] as num_complex divides.
        let scale = |br: &mut [f64], bi: &mut [f64], k: usize| {
            let (cr, ci) = (re[k * n + k], im[k * n + k]);
            let ns = cr * cr + ci * ci;
            let (vr, vi) = (br[k], bi[k]);
            let x = ((vr * cr + vi * ci) / ns, (vi * cr - vr * ci) / ns);
            br[k] = x.0;
            bi[k] = x.1;
            x
        };
        let mut k = n;
        while k >= 2 {
            let (k1, k0) = (k - 1, k - 2);
            let x1 = scale(br, bi, k1);
            let (ur, ui) = (re[k1 * n + k0], im[k1 * n + k0]);
            br[k0] -= ur * x1.0 - ui * x1.1;
            bi[k0] -= ur * x1.1 + ui * x1.0;
            let x0 = scale(br, bi, k0);
            let top = widen(pat.top[k1].min(pat.top[k0]), k0, 0, k0).0;
            let (u1, u0) = (k1 * n + top..k1 * n + k0, k0 * n + top..k0 * n + k0);
            let (u1r, u1i, u0r, u0i) = (&re[u1.clone()], &im[u1], &re[u0.clone()], &im[u0]);
            caxpy_twice(
                &mut br[top..k0],
                &mut bi[top..k0],
                u1r,
                u1i,
                x1,
                u0r,
                u0i,
                x0,
            );
            k -= 2;
        }
        if k == 1 {
            scale(br, bi, 0);
        }
    }
}
