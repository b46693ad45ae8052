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
    /// The trailing columns to update at the current elimination step.
    cols: Vec<usize>,
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
            cols: vec![0; n],
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
        let Self {
            re, im, pat, cols, ..
        } = self;
        pat.finite = true;
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
            let mut bad = 0;
            for (r, m) in kr[k + 1..n].iter_mut().zip(&mut ki[k + 1..n]) {
                let (vr, vi) = (*r, *m);
                *r = vr * ir - vi * ii;
                *m = vr * ii + vi * ir;
                bad |= non_finite_bits(*r) | non_finite_bits(*m);
            }
            let (lr, li) = (&kr[k + 1..n], &ki[k + 1..n]);
            let nonzero = |(r, i): (&f64, &f64)| *r != 0.0 || *i != 0.0;
            let pos = lr.iter().zip(li).position(nonzero);
            let rpos = lr.iter().zip(li).rposition(nonzero);
            let (lo, hi) = nonzero_rows(k + 1, n, pos, rpos);
            let (lo, hi) = widen(lo, hi, k + 1, n);
            pat.lo[k] = lo;
            pat.hi[k] = hi;
            // Pass 1: interchange, list the columns with u ≠ 0, test u's finiteness.
            let trailing = right_re
                .chunks_exact_mut(ld)
                .zip(right_im.chunks_exact_mut(ld));
            let mut count = 0;
            for (j, (cr, ci)) in trailing.enumerate() {
                if p != k {
                    cr.swap(k, p);
                    ci.swap(k, p);
                }
                let (ur, ui) = (cr[k], ci[k]);
                bad |= non_finite_bits(ur) | non_finite_bits(ui);
                cols[count] = j;
                count += usize::from(ur != 0.0 || ui != 0.0);
            }
            if bad != 0 {
                // Not finite: every row and column, as the textbook.
                pat.finite = false;
                let (lr, li) = (&kr[k + 1..n], &ki[k + 1..n]);
                let trailing = right_re
                    .chunks_exact_mut(ld)
                    .zip(right_im.chunks_exact_mut(ld));
                for (cr, ci) in trailing {
                    let (ur, ui) = (cr[k], ci[k]);
                    let x = cr[k + 1..n].iter_mut().zip(&mut ci[k + 1..n]);
                    for ((xr, xi), (&lr, &li)) in x.zip(lr.iter().zip(li)) {
                        *xr -= lr * ur - li * ui;
                        *xi -= lr * ui + li * ur;
                    }
                }
                continue;
            }
            if lo == hi {
                continue;
            }
            // Pass 2: the listed columns, two at a time, rows widened (see the real kernel).
            let end = padded_end(lo, hi);
            let (lr, li) = (&kr[lo..end], &ki[lo..end]);
            let mut pairs = cols[..count].chunks_exact(2);
            for pair in &mut pairs {
                let (j0, j1) = (pair[0], pair[1]);
                let (xr, yr) = right_re.split_at_mut(j1 * ld);
                let (xi, yi) = right_im.split_at_mut(j1 * ld);
                let (xr, yr) = (&mut xr[j0 * ld..j0 * ld + ld], &mut yr[..ld]);
                let (xi, yi) = (&mut xi[j0 * ld..j0 * ld + ld], &mut yi[..ld]);
                let (a, b) = ((xr[k], xi[k]), (yr[k], yi[k]));
                let (xr, xi) = (&mut xr[lo..end], &mut xi[lo..end]);
                let (yr, yi) = (&mut yr[lo..end], &mut yi[lo..end]);
                caxpy2(simd, xr, xi, yr, yi, lr, li, a, b);
            }
            if let [j] = *pairs.remainder() {
                let xr = &mut right_re[j * ld..j * ld + ld];
                let xi = &mut right_im[j * ld..j * ld + ld];
                let a = (xr[k], xi[k]);
                caxpy(simd, &mut xr[lo..end], &mut xi[lo..end], lr, li, a);
            }
        }
        for k in 0..n {
            let (ur, ui) = (&re[k * ld..k * ld + k], &im[k * ld..k * ld + k]);
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
        let (n, ld, re, im, pat) = (self.n, self.ld, &self.re, &self.im, &self.pat);
        // As the real solve: zeros skipped for finite factors and a finite b[k] only.
        for k in 0..n {
            let p = pat.piv[k];
            br.swap(k, p);
            bi.swap(k, p);
            let x = (br[k], bi[k]);
            let (lo, hi) = if pat.finite && x.0.is_finite() && x.1.is_finite() {
                if x.0 == 0.0 && x.1 == 0.0 {
                    continue;
                }
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
