//! The complex system ((α + iβ)/h)I − J on separate real and imaginary planes: factors and
//! solves in place.

use nalgebra::Complex;
use pulp::{Arch, Simd, WithSimd};

use super::{
    caxpy, caxpy2, caxpy_twice, non_finite_bits, nonzero_rows, padded_end, pivot_complex, widen,
    Pattern, Singular, PAD,
};

/// A complex n×n matrix on separate real and imaginary planes and, after
/// [`ComplexLu::factor`], its factors P·A = L·U in place.
#[derive(Clone, Debug)]
pub(crate) struct ComplexLu {
    n: usize,
    /// Column stride: n rows and [`PAD`] rows of padding.
    pub(super) ld: usize,
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
        let ld = n + PAD;
        Self {
            n,
            ld,
            re: vec![0.0; ld * n],
            im: vec![0.0; ld * n],
            pat: Pattern::new(n),
            arch,
        }
    }

    /// Set the matrix to `diag·I − J` (J real, column-major), ready for [`Self::factor`].
    pub(crate) fn set_shifted(&mut self, diag: Complex<f64>, jac: &[f64]) {
        let (n, ld) = (self.n, self.ld);
        for k in 0..n {
            let (dst, src) = (&mut self.re[k * ld..k * ld + n], &jac[k * n..k * n + n]);
            for (d, &j) in dst.iter_mut().zip(src) {
                *d = -j;
            }
            dst[k] += diag.re;
            let dst = &mut self.im[k * ld..k * ld + n];
            dst.fill(0.0);
            dst[k] += diag.im;
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

    /// As [`RealLu::factor`]'s kernel, complex.
    #[inline(always)]
    fn factor_kernel<S: Simd>(&mut self, simd: S) -> Result<(), Singular> {
        let (n, ld) = (self.n, self.ld);
        let Self { re, im, pat, .. } = self;
        for k in 0..n {
            let (left_re, right_re) = re.split_at_mut((k + 1) * ld);
            let (left_im, right_im) = im.split_at_mut((k + 1) * ld);
            let kr = &mut left_re[k * ld..];
            let ki = &mut left_im[k * ld..];
            let p = k + pivot_complex(&kr[k..n], &ki[k..n]).ok_or(Singular)?;
            pat.piv[k] = p;
            kr.swap(k, p);
            ki.swap(k, p);
            // 1/pivot and the scaling, with the operations of `num_complex`.
            let (cr, ci) = (kr[k], ki[k]);
            let ns = cr * cr + ci * ci;
            let (ir, ii) = ((1.0 * cr + 0.0 * ci) / ns, (0.0 * cr - 1.0 * ci) / ns);
            // `bad` ≠ 0 if an l is not finite.
            let mut bad = 0;
            for (r, m) in kr[k + 1..n].iter_mut().zip(&mut ki[k + 1..n]) {
                let (vr, vi) = (*r, *m);
                *r = vr * ir - vi * ii;
                *m = vr * ii + vi * ir;
                bad |= non_finite_bits(*r) | non_finite_bits(*m);
            }
            // A non-finite l: refused, as by the textbook LU (see `mod.rs`).
            if bad != 0 {
                return Err(Singular);
            }
            let (lr, li) = (&kr[k + 1..n], &ki[k + 1..n]);
            let nonzero = |(r, i): (&f64, &f64)| *r != 0.0 || *i != 0.0;
            let pos = lr.iter().zip(li).position(nonzero);
            let rpos = lr.iter().zip(li).rposition(nonzero);
            let (lo, hi) = nonzero_rows(k + 1, n, pos, rpos);
            let (lo, hi) = widen(lo, hi, k + 1, n);
            pat.lo[k] = lo;
            pat.hi[k] = hi;
            let end = padded_end(lo, hi);
            // Known to the compiler, these bounds leave the loops below without bounds
            // checks.
            assert!(k < ld && p < ld && lo <= end && end <= ld);
            // Rows k and p interchanged in the trailing columns, then the update by adjacent
            // pairs of columns, as in the real kernel.
            if p != k {
                for (cr, ci) in right_re
                    .chunks_exact_mut(ld)
                    .zip(right_im.chunks_exact_mut(ld))
                {
                    cr.swap(k, p);
                    ci.swap(k, p);
                }
            }
            if lo == hi {
                continue;
            }
            let (lr, li) = (&kr[lo..end], &ki[lo..end]);
            let mut pairs = right_re
                .chunks_exact_mut(2 * ld)
                .zip(right_im.chunks_exact_mut(2 * ld));
            for (pr, pi) in &mut pairs {
                let ((xr, yr), (xi, yi)) = (pr.split_at_mut(ld), pi.split_at_mut(ld));
                let (a, b) = ((xr[k], xi[k]), (yr[k], yi[k]));
                let (xr, xi) = (&mut xr[lo..end], &mut xi[lo..end]);
                let (yr, yi) = (&mut yr[lo..end], &mut yi[lo..end]);
                match (a.0 != 0.0 || a.1 != 0.0, b.0 != 0.0 || b.1 != 0.0) {
                    (true, true) => caxpy2(simd, xr, xi, yr, yi, lr, li, a, b),
                    (false, false) => {}
                    (true, false) => caxpy(simd, xr, xi, lr, li, a),
                    (false, true) => caxpy(simd, yr, yi, lr, li, b),
                }
            }
            // The odd column left over (the zip's remainders are not exposed).
            let m = right_re.len() / ld;
            if m % 2 == 1 {
                let xr = &mut right_re[(m - 1) * ld..m * ld];
                let xi = &mut right_im[(m - 1) * ld..m * ld];
                let a = (xr[k], xi[k]);
                if a.0 != 0.0 || a.1 != 0.0 {
                    caxpy(simd, &mut xr[lo..end], &mut xi[lo..end], lr, li, a);
                }
            }
        }
        // U: where its columns start, and whether it is finite (if not: refused, as by the
        // textbook LU).
        let mut bad = 0;
        for k in 0..n {
            let (ur, ui) = (&re[k * ld..k * ld + k], &im[k * ld..k * ld + k]);
            pat.top[k] = (0..k)
                .position(|i| ur[i] != 0.0 || ui[i] != 0.0)
                .unwrap_or(k);
            bad |= ur.iter().chain(ui).fold(0, |b, &v| b | non_finite_bits(v));
        }
        if bad != 0 {
            return Err(Singular);
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
        let (n, ld, re, im, pat) = (self.n, self.ld, &self.re, &self.im, &self.pat);
        // As the real solve: b[k] = 0 skipped, the zeros of L for a finite b[k] only.
        for k in 0..n {
            let p = pat.piv[k];
            br.swap(k, p);
            bi.swap(k, p);
            let x = (br[k], bi[k]);
            if x.0 == 0.0 && x.1 == 0.0 {
                continue;
            }
            let (lo, hi) = if x.0.is_finite() && x.1.is_finite() {
                (pat.lo[k], pat.hi[k])
            } else {
                (k + 1, n)
            };
            let l = k * ld + lo..k * ld + hi;
            caxpy(
                simd,
                &mut br[lo..hi],
                &mut bi[lo..hi],
                &re[l.clone()],
                &im[l],
                x,
            );
        }
        // U x = y, two columns per pass as in the real solve.
        // b[k] / u[k, k] as num_complex divides.
        let scale = |br: &mut [f64], bi: &mut [f64], k: usize| {
            let (cr, ci) = (re[k * ld + k], im[k * ld + k]);
            let ns = cr * cr + ci * ci;
            let (vr, vi) = (br[k], bi[k]);
            let x = ((vr * cr + vi * ci) / ns, (vi * cr - vr * ci) / ns);
            br[k] = x.0;
            bi[k] = x.1;
            x
        };
        let finite = |x: (f64, f64)| x.0.is_finite() && x.1.is_finite();
        let mut k = n;
        while k >= 2 {
            let (k1, k0) = (k - 1, k - 2);
            let x1 = scale(br, bi, k1);
            let (ur, ui) = (re[k1 * ld + k0], im[k1 * ld + k0]);
            br[k0] -= ur * x1.0 - ui * x1.1;
            bi[k0] -= ur * x1.1 + ui * x1.0;
            let x0 = scale(br, bi, k0);
            let top = if finite(x1) && finite(x0) {
                widen(pat.top[k1].min(pat.top[k0]), k0, 0, k0).0
            } else {
                0
            };
            let (u1, u0) = (k1 * ld + top..k1 * ld + k0, k0 * ld + top..k0 * ld + k0);
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
