//! Dense LU with partial pivoting, in place on preallocated column-major buffers: one real
//! (γ/h)I − J and one complex ((α + iβ)/h)I − J per factorisation.
//!
//! nalgebra's `LU::new` takes the matrix by value and allocates its permutation on every
//! call; the integrator factorises two matrices per step-size change, so it keeps its own
//! buffers and factorises here without touching the heap.
//!
//! # The kernel
//! Right-looking elimination (column k: pivot, scale, then subtract multiples of it from the
//! trailing columns), with what makes it fast at n = 5…100 on the sparse Jacobians of
//! mechanical–hydraulic models:
//! - **Sparsity, found numerically.** Column k of L is scanned for its first and last
//!   non-zero row and the trailing update only touches those rows; only the trailing columns
//!   with a non-zero in row k are updated (gathered without branches). No symbolic pattern
//!   is needed, so a Jacobian whose zeros move costs nothing extra. On the knuckle-boom crane
//!   (n = 38) this does about half the multiply-adds of a dense LU.
//! - **Two trailing columns per pass**, sharing the loads of the L column; row ranges
//!   widened to a multiple of four rows (over exact zeros) so the vector loops have no
//!   scalar remainder.
//! - **Complex numbers on separate real and imaginary planes**, so that the inner loops
//!   vectorise (2.5× faster than `Complex<f64>` elements at n = 38).
//! - **LINPACK-style interchanges**: row k is swapped with the pivot row in the trailing
//!   columns only; the L columns keep the row order of their step and [`RealLu::solve`]
//!   interchanges the right-hand side step by step.
//! - **AVX2 when the CPU has it**, chosen at run time through `pulp` (the SIMD layer faer is
//!   built on, already compiled for diffsol): the same loops compiled with wider vectors.
//!   Rust never fuses a multiply and an add, so the results are bit-identical either way.
//! - **Solves** skip the zeros of L and U likewise and back-substitute two U columns per
//!   pass.
//!
//! **Bit-identical results.** Every entry receives the same operations in the same order as
//! in the textbook dense LU with partial pivoting and its forward and back substitution
//! (the skipped ones are exact zeros, x − 0·a = x), so factors and solutions are the same to
//! the last bit, up to the sign of zero entries; the tests check this. It matters: the step-size control amplifies any
//! round-off change to the tolerance level (multiplying by stored reciprocals of the pivots
//! instead of dividing made the solves 20 % faster but moved the crane's trajectory by
//! 2.5e-5 of its scale, with 901 steps instead of 882).
//!
//! Measured and not taken (`examples/lu_bench`, the crane's Jacobians, h = 1e-4…1e-2):
//! - faer 0.24's partial-pivot LU: slower at these sizes on the crane (n = 38: real 4.0 µs,
//!   complex 6.6 µs, against 2.8 and 4.4 here; n = 66: 11.5/20.9 against 10.1/17.7); it wins
//!   only on dense matrices from n ≈ 60 (n = 100: 26/53 µs against 41/80).
//! - A fill-reducing state ordering (Markowitz on the pattern of J): 31 % of a dense LU's
//!   multiply-adds instead of 52 % at n = 38, but only 12 % less time (18 % at n = 66), as
//!   the dense mechanical block remains; and it changes the round-off (see above).
//! - A left-looking variant updating each column from four L columns at once: slower,
//!   through its bookkeeping. Four trailing columns per pass instead of two: no gain.
//! - The complex system as a real 2n×2n one on this real kernel: 3× slower (twice the
//!   arithmetic).

use nalgebra::Complex;
use pulp::{Arch, Simd, WithSimd};

/// The matrix has a zero or non-finite pivot.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Singular;

/// x −= l·a.
#[inline(always)]
fn axpy(x: &mut [f64], l: &[f64], a: f64) {
    let l = &l[..x.len()];
    for (x, &l) in x.iter_mut().zip(l) {
        *x -= l * a;
    }
}

/// x −= l·a and y −= l·b.
#[inline(always)]
fn axpy2(x: &mut [f64], y: &mut [f64], l: &[f64], a: f64, b: f64) {
    let m = l.len();
    let (x, y) = (&mut x[..m], &mut y[..m]);
    for i in 0..m {
        x[i] -= l[i] * a;
        y[i] -= l[i] * b;
    }
}

/// x −= l·a for complex numbers on planes, with the operations of `num_complex`:
/// l·a = (lr·ar − li·ai) + i(lr·ai + li·ar).
#[inline(always)]
fn caxpy(xr: &mut [f64], xi: &mut [f64], lr: &[f64], li: &[f64], a: (f64, f64)) {
    let m = lr.len();
    let (xr, xi, li) = (&mut xr[..m], &mut xi[..m], &li[..m]);
    for i in 0..m {
        xr[i] -= lr[i] * a.0 - li[i] * a.1;
        xi[i] -= lr[i] * a.1 + li[i] * a.0;
    }
}

/// x −= l·a and y −= l·b for complex numbers on planes. (Separate slices, not tuples of
/// them: with tuples the loop ran 30 % slower.)
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn caxpy2(
    xr: &mut [f64],
    xi: &mut [f64],
    yr: &mut [f64],
    yi: &mut [f64],
    lr: &[f64],
    li: &[f64],
    a: (f64, f64),
    b: (f64, f64),
) {
    let m = lr.len();
    let (xr, xi, li) = (&mut xr[..m], &mut xi[..m], &li[..m]);
    let (yr, yi) = (&mut yr[..m], &mut yi[..m]);
    for i in 0..m {
        xr[i] -= lr[i] * a.0 - li[i] * a.1;
        xi[i] -= lr[i] * a.1 + li[i] * a.0;
        yr[i] -= lr[i] * b.0 - li[i] * b.1;
        yi[i] -= lr[i] * b.1 + li[i] * b.0;
    }
}

/// x −= l·a, then x −= m·b. From the last row up: the back substitution needs the rows just
/// above the pair next, so computing them first shortens its chain of dependent operations
/// (8 % on the complex solve).
#[inline(always)]
fn axpy_twice(x: &mut [f64], l: &[f64], a: f64, m: &[f64], b: f64) {
    let len = x.len();
    let (l, m) = (&l[..len], &m[..len]);
    for i in (0..len).rev() {
        x[i] = x[i] - l[i] * a - m[i] * b;
    }
}

/// x −= l·a, then x −= m·b, complex on planes, from the last row up (see [`axpy_twice`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn caxpy_twice(
    xr: &mut [f64],
    xi: &mut [f64],
    lr: &[f64],
    li: &[f64],
    a: (f64, f64),
    mr: &[f64],
    mi: &[f64],
    b: (f64, f64),
) {
    let len = xr.len();
    let (xi, lr, li, mr, mi) = (
        &mut xi[..len],
        &lr[..len],
        &li[..len],
        &mr[..len],
        &mi[..len],
    );
    for i in (0..len).rev() {
        let r = xr[i] - (lr[i] * a.0 - li[i] * a.1);
        let m = xi[i] - (lr[i] * a.1 + li[i] * a.0);
        xr[i] = r - (mr[i] * b.0 - mi[i] * b.1);
        xi[i] = m - (mr[i] * b.1 + mi[i] * b.0);
    }
}

/// The pivot of partial pivoting among `size(0..len)`: the first of the largest, which is
/// what a scan keeping the first of equal sizes finds. `None` if that size is zero or not
/// finite, or if entry 0 is NaN (such a scan starts from it and never replaces it).
///
/// The maximum is taken in four independent lanes so that it vectorises; it is exact, so
/// the lane order does not matter.
#[inline(always)]
fn pivot(len: usize, size: impl Fn(usize) -> f64) -> Option<usize> {
    let mut m = [0.0f64; 4];
    let full = len / 4 * 4;
    for c in (0..full).step_by(4) {
        for (w, mw) in m.iter_mut().enumerate() {
            let s = size(c + w);
            *mw = if s > *mw { s } else { *mw };
        }
    }
    for i in full..len {
        let s = size(i);
        m[0] = if s > m[0] { s } else { m[0] };
    }
    let best = m[0].max(m[1]).max(m[2].max(m[3]));
    if best > 0.0 && best.is_finite() && !size(0).is_nan() {
        // Exact: best is one of the sizes.
        #[allow(clippy::float_cmp)]
        (0..len).position(|i| size(i) == best)
    } else {
        None
    }
}

/// The rows lo..hi of first..n outside which `nonzero` is false (lo = hi = n if it is false
/// everywhere).
#[inline(always)]
fn nonzero_rows(first: usize, n: usize, nonzero: impl Fn(usize) -> bool) -> (usize, usize) {
    match (first..n).position(&nonzero) {
        None => (n, n),
        Some(lo) => {
            let hi = (first..n).rposition(&nonzero).map_or(n, |i| first + i + 1);
            (first + lo, hi)
        }
    }
}

/// Rows lo..hi widened, within first..end, to a multiple of 4 rows where there is room, so
/// that the vector loops need no scalar remainder; the rows added hold exact zeros of the
/// factor, which change nothing (x − 0·a = x).
#[inline(always)]
fn widen(lo: usize, hi: usize, first: usize, end: usize) -> (usize, usize) {
    let len = (hi - lo).div_ceil(4) * 4;
    let hi = (lo + len).min(end);
    (hi.saturating_sub(len).max(first), hi)
}

/// Columns j1 < j2 of the column-major `cols` with n rows.
#[inline(always)]
fn two_columns(cols: &mut [f64], n: usize, j1: usize, j2: usize) -> (&mut [f64], &mut [f64]) {
    let (a, b) = cols.split_at_mut(j2 * n);
    (&mut a[j1 * n..(j1 + 1) * n], &mut b[..n])
}

/// Where the zeros of the factors are, for the solves.
#[derive(Clone, Debug)]
struct Pattern {
    /// Row interchanged with row k at step k.
    piv: Vec<usize>,
    /// Column k of L is zero outside rows lo[k]..hi[k].
    lo: Vec<usize>,
    hi: Vec<usize>,
    /// Column k of U is zero above row top[k].
    top: Vec<usize>,
    /// Scratch: the trailing columns updated at the current step.
    cols: Vec<usize>,
}

impl Pattern {
    fn new(n: usize) -> Self {
        Self {
            piv: vec![0; n],
            lo: vec![0; n],
            hi: vec![0; n],
            top: vec![0; n],
            cols: vec![0; n],
        }
    }
}

/// A real n×n matrix and, after [`RealLu::factor`], its factors P·A = L·U in place.
#[derive(Clone, Debug)]
pub(crate) struct RealLu {
    n: usize,
    /// Column-major; L below the diagonal (unit diagonal implied), U on and above it.
    a: Vec<f64>,
    pat: Pattern,
    arch: Arch,
}

impl RealLu {
    pub(crate) fn new(n: usize) -> Self {
        Self::with_arch(n, Arch::new())
    }

    /// With a given instruction set (the tests compare them).
    fn with_arch(n: usize, arch: Arch) -> Self {
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
            fn with_simd<S: Simd>(self, _: S) -> Self::Output {
                self.0.factor_kernel()
            }
        }
        self.arch.dispatch(Op(self))
    }

    #[inline(always)]
    fn factor_kernel(&mut self) -> Result<(), Singular> {
        let n = self.n;
        let pat = &mut self.pat;
        for k in 0..n {
            let (left, right) = self.a.split_at_mut((k + 1) * n);
            let colk = &mut left[k * n..];
            let p = k + pivot(n - k, |i| colk[k + i].abs()).ok_or(Singular)?;
            pat.piv[k] = p;
            if p != k {
                colk.swap(k, p);
                for colj in right.chunks_exact_mut(n) {
                    colj.swap(k, p);
                }
            }
            let inv = 1.0 / colk[k];
            for v in &mut colk[k + 1..] {
                *v *= inv;
            }
            let (lo, hi) = nonzero_rows(k + 1, n, |i| colk[i] != 0.0);
            let (lo, hi) = widen(lo, hi, k + 1, n);
            pat.lo[k] = lo;
            pat.hi[k] = hi;
            if lo == hi {
                continue;
            }
            // The trailing columns with a non-zero (not NaN) in row k, gathered without
            // branches; updated two at a time.
            let mut count = 0;
            for (j, colj) in right.chunks_exact(n).enumerate() {
                pat.cols[count] = j;
                count += usize::from(colj[k].abs() > 0.0);
            }
            let l = &colk[lo..hi];
            let mut pairs = pat.cols[..count].chunks_exact(2);
            for pair in &mut pairs {
                let (x, y) = two_columns(right, n, pair[0], pair[1]);
                let (a, b) = (x[k], y[k]);
                axpy2(&mut x[lo..hi], &mut y[lo..hi], l, a, b);
            }
            if let [j] = *pairs.remainder() {
                let x = &mut right[j * n..(j + 1) * n];
                let a = x[k];
                axpy(&mut x[lo..hi], l, a);
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
            fn with_simd<S: Simd>(self, _: S) {
                self.0.solve_kernel(self.1);
            }
        }
        self.arch.dispatch(Op(self, b));
    }

    #[inline(always)]
    fn solve_kernel(&self, b: &mut [f64]) {
        let (n, a, pat) = (self.n, &self.a, &self.pat);
        // L y = P b, interchanging as the factorisation did.
        for k in 0..n {
            b.swap(k, pat.piv[k]);
            let bk = b[k];
            if bk != 0.0 {
                let (lo, hi) = (pat.lo[k], pat.hi[k]);
                axpy(&mut b[lo..hi], &a[k * n + lo..k * n + hi], bk);
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

/// A complex n×n matrix on separate real and imaginary planes and, after
/// [`ComplexLu::factor`], its factors P·A = L·U in place.
#[derive(Clone, Debug)]
pub(crate) struct ComplexLu {
    n: usize,
    /// Column-major real and imaginary parts, laid out as in [`RealLu`].
    re: Vec<f64>,
    im: Vec<f64>,
    pat: Pattern,
    arch: Arch,
}

impl ComplexLu {
    pub(crate) fn new(n: usize) -> Self {
        Self::with_arch(n, Arch::new())
    }

    fn with_arch(n: usize, arch: Arch) -> Self {
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
            fn with_simd<S: Simd>(self, _: S) -> Self::Output {
                self.0.factor_kernel()
            }
        }
        self.arch.dispatch(Op(self))
    }

    #[inline(always)]
    fn factor_kernel(&mut self) -> Result<(), Singular> {
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
            if p != k {
                kr.swap(k, p);
                ki.swap(k, p);
                for colj in right_re.chunks_exact_mut(n) {
                    colj.swap(k, p);
                }
                for colj in right_im.chunks_exact_mut(n) {
                    colj.swap(k, p);
                }
            }
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
            if lo == hi {
                continue;
            }
            let mut count = 0;
            let trailing = right_re.chunks_exact(n).zip(right_im.chunks_exact(n));
            for (j, (cr, ci)) in trailing.enumerate() {
                pat.cols[count] = j;
                count += usize::from(cr[k].abs() + ci[k].abs() > 0.0);
            }
            let l = (&kr[lo..hi], &ki[lo..hi]);
            let mut pairs = pat.cols[..count].chunks_exact(2);
            for pair in &mut pairs {
                let (xr, yr) = two_columns(right_re, n, pair[0], pair[1]);
                let (xi, yi) = two_columns(right_im, n, pair[0], pair[1]);
                let (a, b) = ((xr[k], xi[k]), (yr[k], yi[k]));
                let (x, y) = (
                    (&mut xr[lo..hi], &mut xi[lo..hi]),
                    (&mut yr[lo..hi], &mut yi[lo..hi]),
                );
                caxpy2(x.0, x.1, y.0, y.1, l.0, l.1, a, b);
            }
            if let [j] = *pairs.remainder() {
                let xr = &mut right_re[j * n..(j + 1) * n];
                let xi = &mut right_im[j * n..(j + 1) * n];
                let a = (xr[k], xi[k]);
                caxpy(&mut xr[lo..hi], &mut xi[lo..hi], l.0, l.1, a);
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
            fn with_simd<S: Simd>(self, _: S) {
                self.0.solve_kernel(self.1, self.2);
            }
        }
        self.arch.dispatch(Op(self, re, im));
    }

    #[inline(always)]
    fn solve_kernel(&self, br: &mut [f64], bi: &mut [f64]) {
        let (n, re, im, pat) = (self.n, &self.re, &self.im, &self.pat);
        for k in 0..n {
            let p = pat.piv[k];
            br.swap(k, p);
            bi.swap(k, p);
            let x = (br[k], bi[k]);
            if x.0 != 0.0 || x.1 != 0.0 {
                let (lo, hi) = (pat.lo[k], pat.hi[k]);
                let l = k * n + lo..k * n + hi;
                caxpy(&mut br[lo..hi], &mut bi[lo..hi], &re[l.clone()], &im[l], x);
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

#[cfg(test)]
// Bit-identical results are what the tests check.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    /// The arithmetic of the reference.
    trait Num:
        Copy
        + std::ops::Add<Output = Self>
        + std::ops::Sub<Output = Self>
        + std::ops::Mul<Output = Self>
        + std::ops::Div<Output = Self>
    {
        const ZERO: Self;
        const ONE: Self;
        /// |re| + |im|.
        fn size(self) -> f64;
    }
    impl Num for f64 {
        const ZERO: Self = 0.0;
        const ONE: Self = 1.0;
        fn size(self) -> f64 {
            self.abs()
        }
    }
    impl Num for Complex<f64> {
        const ZERO: Self = Complex::new(0.0, 0.0);
        const ONE: Self = Complex::new(1.0, 0.0);
        fn size(self) -> f64 {
            self.re.abs() + self.im.abs()
        }
    }

    /// The textbook algorithm whose factors the kernels must reproduce bit for bit: dense
    /// right-looking elimination, the first entry of largest size as pivot, rows
    /// interchanged in the trailing columns only (LINPACK's layout). `None` for a zero or
    /// non-finite pivot.
    fn reference_factor<T: Num>(n: usize, mat: &[T]) -> Option<(Vec<T>, Vec<usize>)> {
        let mut a = mat.to_vec();
        let mut piv = vec![0; n];
        for k in 0..n {
            let mut p = k;
            let mut best = a[k * n + k].size();
            for i in k + 1..n {
                if a[k * n + i].size() > best {
                    best = a[k * n + i].size();
                    p = i;
                }
            }
            if best <= 0.0 || !best.is_finite() {
                return None;
            }
            piv[k] = p;
            for j in k..n {
                a.swap(j * n + k, j * n + p);
            }
            let inv = T::ONE / a[k * n + k];
            for i in k + 1..n {
                a[k * n + i] = a[k * n + i] * inv;
            }
            for j in k + 1..n {
                let akj = a[j * n + k];
                for i in k + 1..n {
                    a[j * n + i] = a[j * n + i] - a[k * n + i] * akj;
                }
            }
        }
        Some((a, piv))
    }

    /// Forward and back substitution with the reference's factors, interchanging b step by
    /// step (equivalent, operation for operation, to interchanging all rows first).
    fn reference_solve<T: Num>(n: usize, a: &[T], piv: &[usize], b: &mut [T]) {
        for k in 0..n {
            b.swap(k, piv[k]);
            for i in k + 1..n {
                b[i] = b[i] - a[k * n + i] * b[k];
            }
        }
        for k in (0..n).rev() {
            b[k] = b[k] / a[k * n + k];
            for i in 0..k {
                b[i] = b[i] - a[k * n + i] * b[k];
            }
        }
    }

    /// max |A·x − b| / (max|A|·max|x|·n + max|b|): of the order of the unit round-off for
    /// a backward-stable solve.
    fn residual<T: Num>(n: usize, mat: &[T], x: &[T], b: &[T]) -> f64 {
        let big = |v: &[T]| v.iter().fold(0.0f64, |m, v| m.max(v.size()));
        let mut worst = 0.0f64;
        for i in 0..n {
            let mut ax = T::ZERO;
            for j in 0..n {
                ax = ax + mat[j * n + i] * x[j];
            }
            worst = worst.max((ax - b[i]).size());
        }
        worst / (big(mat) * big(x) * n as f64 + big(b))
    }

    /// A deterministic pseudo-random stream in [−1, 1).
    fn stream(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// Factorise diag·I − J with both kernels (with the instruction set `arch`) and solve:
    /// factors, interchanges and solution are those of the reference bit for bit (== also
    /// equates ±0), singularity is detected alike, and the residual is at round-off level.
    fn check_against_reference(n: usize, jac: &[f64], diag: Complex<f64>, arch: Arch) {
        let mut rnd = stream(n as u64 + 7);
        let on_diagonal = |k: usize| k % (n + 1) == 0;

        let mat: Vec<f64> = (0..n * n)
            .map(|k| -jac[k] + if on_diagonal(k) { diag.re } else { 0.0 })
            .collect();
        let reference = reference_factor(n, &mat);
        let mut lu = RealLu::with_arch(n, arch);
        lu.set_shifted(diag.re, jac);
        assert_eq!(lu.factor().is_ok(), reference.is_some(), "real singularity");
        if let Some((a, piv)) = reference {
            assert_eq!(lu.pat.piv, piv, "real interchanges, n = {n}");
            for (k, (got, want)) in lu.a.iter().zip(&a).enumerate() {
                assert!(got == want, "real n = {n}, entry {k}: {got:e} vs {want:e}");
            }
            let b: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let mut x = b.clone();
            lu.solve(&mut x);
            let mut want = b.clone();
            reference_solve(n, &a, &piv, &mut want);
            for (got, want) in x.iter().zip(&want) {
                assert!(got == want, "real n = {n}: solution {got:e} vs {want:e}");
            }
            let r = residual(n, &mat, &x, &b);
            assert!(r < 1e-15, "real n = {n}: residual {r:e}");
        }

        let zero = Complex::new(0.0, 0.0);
        let cmat: Vec<Complex<f64>> = (0..n * n)
            .map(|k| Complex::new(-jac[k], 0.0) + if on_diagonal(k) { diag } else { zero })
            .collect();
        let reference = reference_factor(n, &cmat);
        let mut clu = ComplexLu::with_arch(n, arch);
        clu.set_shifted(diag, jac);
        assert_eq!(
            clu.factor().is_ok(),
            reference.is_some(),
            "complex singularity"
        );
        if let Some((a, piv)) = reference {
            assert_eq!(clu.pat.piv, piv, "complex interchanges, n = {n}");
            for (k, want) in a.iter().enumerate() {
                let (r, i) = (clu.re[k], clu.im[k]);
                assert!(r == want.re && i == want.im, "complex n = {n}, entry {k}");
            }
            let b: Vec<Complex<f64>> = (0..n).map(|_| Complex::new(rnd(), rnd())).collect();
            let mut re: Vec<f64> = b.iter().map(|v| v.re).collect();
            let mut im: Vec<f64> = b.iter().map(|v| v.im).collect();
            clu.solve(&mut re, &mut im);
            let x: Vec<Complex<f64>> = re
                .iter()
                .zip(&im)
                .map(|(&r, &i)| Complex::new(r, i))
                .collect();
            let mut want = b.clone();
            reference_solve(n, &a, &piv, &mut want);
            assert!(x == want, "complex n = {n}: solution {x:?} vs {want:?}");
            let r = residual(n, &cmat, &x, &b);
            assert!(r < 1e-15, "complex n = {n}: residual {r:e}");
        }
    }

    /// Solving with the factors of a matrix that needs pivoting reproduces a known solution.
    #[test]
    fn real_and_complex_solves_reproduce_a_known_solution() {
        let n = 5;
        // J with a zero in the (0, 0) corner of diag − J so that pivoting is needed.
        let mut jac = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                jac[j * n + i] =
                    ((i * 7 + j * 3) % 5) as f64 - 2.0 + if i == j { 1.0 } else { 0.0 };
            }
        }
        jac[0] = 2.0;
        let mat = |i: usize, j: usize| -jac[j * n + i] + if i == j { 2.0 } else { 0.0 };
        let x: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let mut lu = RealLu::new(n);
        lu.set_shifted(2.0, &jac);
        lu.factor().unwrap_or_else(|_| panic!("singular"));
        assert_ne!(lu.pat.piv[0], 0, "the zero corner must be pivoted away");
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| mat(i, j) * x[j]).sum())
            .collect();
        lu.solve(&mut b);
        for (got, want) in b.iter().zip(&x) {
            assert!((got - want).abs() < 1e-12, "{b:?}");
        }

        let shift = Complex::new(0.5, 3.0);
        let cmat = |i: usize, j: usize| {
            Complex::new(-jac[j * n + i], 0.0)
                + if i == j {
                    shift
                } else {
                    Complex::new(0.0, 0.0)
                }
        };
        let mut clu = ComplexLu::new(n);
        clu.set_shifted(shift, &jac);
        clu.factor().unwrap_or_else(|_| panic!("singular"));
        let xc: Vec<Complex<f64>> = (0..n).map(|i| Complex::new(1.0, -(i as f64))).collect();
        let bc: Vec<Complex<f64>> = (0..n)
            .map(|i| (0..n).fold(Complex::new(0.0, 0.0), |s, j| s + cmat(i, j) * xc[j]))
            .collect();
        let mut re: Vec<f64> = bc.iter().map(|v| v.re).collect();
        let mut im: Vec<f64> = bc.iter().map(|v| v.im).collect();
        clu.solve(&mut re, &mut im);
        for ((r, i), want) in re.iter().zip(&im).zip(&xc) {
            assert!(
                (Complex::new(*r, *i) - want).norm() < 1e-12,
                "{re:?} {im:?}"
            );
        }
    }

    /// Zero, rank-deficient and non-finite matrices are reported singular, not divided by.
    #[test]
    fn singular_matrix_is_refused() {
        let mut lu = RealLu::new(3);
        lu.set_shifted(0.0, &[0.0; 9]);
        assert!(lu.factor().is_err());
        let mut clu = ComplexLu::new(3);
        clu.set_shifted(Complex::new(0.0, 0.0), &[0.0; 9]);
        assert!(clu.factor().is_err());
        // Rank 2, the second column twice the first; in powers of two, so that the
        // elimination is exact and leaves a zero pivot.
        let jac = [1.0, 2.0, 4.0, 2.0, 4.0, 8.0, 1.0, 1.0, 1.0];
        lu.set_shifted(0.0, &jac);
        assert!(lu.factor().is_err());
        clu.set_shifted(Complex::new(0.0, 0.0), &jac);
        assert!(clu.factor().is_err());
        // A NaN on the diagonal is never a pivot.
        let mut jac = [0.5; 9];
        jac[0] = f64::NAN;
        lu.set_shifted(1.0, &jac);
        assert!(lu.factor().is_err());
        clu.set_shifted(Complex::new(1.0, 1.0), &jac);
        assert!(clu.factor().is_err());
    }

    /// Dense random matrices, sizes across the vector widths and the pairs of columns, both
    /// instruction sets: the reference's factors and solutions, bit for bit.
    #[test]
    fn dense_matrices_match_the_reference_bit_for_bit() {
        for n in [1, 2, 3, 4, 5, 7, 8, 9, 16, 17, 38] {
            let mut rnd = stream(n as u64);
            let jac: Vec<f64> = (0..n * n).map(|_| 10.0 * rnd()).collect();
            for arch in [Arch::new(), Arch::Scalar] {
                check_against_reference(n, &jac, Complex::new(3.0, 2.0), arch);
                check_against_reference(n, &jac, Complex::new(0.0, 0.0), arch);
            }
        }
    }

    /// A crane-like sparse Jacobian: a few hydraulic states coupled to a dense mechanical
    /// block, spring and mass chains hanging off it, many structural zeros, entries from
    /// 1e-3 to 1e9 (so that pivoting happens), for shifts across step sizes: the dense
    /// reference's factors and solutions bit for bit, with the sparsity actually skipping
    /// work.
    #[test]
    fn sparse_crane_like_pattern_matches_the_dense_reference() {
        let n = 30;
        let mut rnd = stream(3);
        let mut jac = vec![0.0; n * n];
        let mut set = |i: usize, j: usize, v: f64| jac[j * n + i] = v;
        let (hyd, mech) = (0..6, 6..18);
        for i in hyd.clone() {
            // Pressures: stiff, driven by the mechanics' velocities.
            set(i, i, -1e3 * (1.0 + rnd().abs()));
            for j in mech.clone().step_by(3) {
                set(i, j, 1e9 * rnd());
            }
        }
        for i in mech.clone() {
            for j in mech.clone() {
                set(i, j, 1e2 * rnd());
            }
            set(i, i % 6, 1e-3 * rnd());
        }
        for c in 18..n {
            // Chains: springs and masses, each coupled to its neighbour and one mech state.
            let m = 6 + (c - 18) % 12;
            set(c, m, 1e4 * rnd());
            set(m, c, rnd());
            if c + 6 < n {
                set(c, c + 6, 1e6 * rnd());
                set(c + 6, c, -1e-2 * rnd().abs());
            }
        }
        let mut lu = RealLu::new(n);
        lu.set_shifted(10.0, &jac);
        lu.factor().unwrap_or_else(|_| panic!("singular"));
        let skipped = (0..n)
            .filter(|&k| lu.pat.lo[k] > k + 1 || lu.pat.hi[k] < n)
            .count();
        assert!(skipped > n / 3, "only {skipped} L columns trimmed");
        assert!(
            lu.pat.piv.iter().enumerate().any(|(k, &p)| p != k),
            "no pivoting"
        );
        for h in [1e-5, 1e-4, 1e-3, 1e-2, 1e-1] {
            let diag = Complex::new(2.68 / h, 3.05 / h);
            for arch in [Arch::new(), Arch::Scalar] {
                check_against_reference(n, &jac, diag, arch);
            }
        }
    }
}
