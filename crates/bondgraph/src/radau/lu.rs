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
//! - **Two trailing columns per pass**, sharing the loads of the L column.
//! - **Complex numbers on separate real and imaginary planes**, so that the inner loops
//!   vectorise (2.5× faster than `Complex<f64>` elements at n = 38).
//! - **LINPACK-style interchanges**: row k is swapped with the pivot row in the trailing
//!   columns only; the L columns keep the row order of their step and [`RealLu::solve`]
//!   interchanges the right-hand side step by step.
//! - **AVX2 when the CPU has it**, chosen at run time through `pulp` (the SIMD layer faer is
//!   built on, already compiled for diffsol): the same loops compiled with wider vectors.
//!   Rust never fuses a multiply and an add, so the results are bit-identical either way.
//!
//! Every entry receives the same operations in the same order as in the textbook
//! algorithm (the skipped ones are exact zeros: x − 0·a = x), so the factors and solutions
//! are bit-identical to those of a plain dense LU with partial pivoting; the tests check this.
//!
//! Measured alternatives (`examples/lu_bench`): faer 0.24's partial-pivot LU is slower at
//! these sizes on the crane (n = 38: real 3.9 µs, complex 6.4 µs, against 2.8 and 4.4 here)
//! and only wins for dense n ≳ 80; a left-looking variant with four fused columns lost to
//! this one through its bookkeeping; the real 2n×2n form of the complex system does twice
//! the arithmetic of the complex n×n one on planes.

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
        // U x = y, column-oriented.
        for k in (0..n).rev() {
            b[k] /= a[k * n + k];
            let bk = b[k];
            if bk != 0.0 {
                let top = pat.top[k];
                axpy(&mut b[top..k], &a[k * n + top..k * n + k], bk);
            }
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
        for k in (0..n).rev() {
            // b[k] / u[k, k] as num_complex divides.
            let (cr, ci) = (re[k * n + k], im[k * n + k]);
            let ns = cr * cr + ci * ci;
            let (vr, vi) = (br[k], bi[k]);
            let x = ((vr * cr + vi * ci) / ns, (vi * cr - vr * ci) / ns);
            br[k] = x.0;
            bi[k] = x.1;
            if x.0 != 0.0 || x.1 != 0.0 {
                let top = pat.top[k];
                let u = k * n + top..k * n + k;
                caxpy(&mut br[top..k], &mut bi[top..k], &re[u.clone()], &im[u], x);
            }
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
        + std::ops::Sub<Output = Self>
        + std::ops::Mul<Output = Self>
        + std::ops::Div<Output = Self>
    {
        const ONE: Self;
        /// |re| + |im|.
        fn size(self) -> f64;
    }
    impl Num for f64 {
        const ONE: Self = 1.0;
        fn size(self) -> f64 {
            self.abs()
        }
    }
    impl Num for Complex<f64> {
        const ONE: Self = Complex::new(1.0, 0.0);
        fn size(self) -> f64 {
            self.re.abs() + self.im.abs()
        }
    }

    /// The textbook algorithm the kernels must reproduce bit for bit: dense right-looking
    /// elimination, full row interchanges, the first entry of largest size as pivot, then
    /// forward and back substitution. Returns false for a zero or non-finite pivot.
    fn reference_solve<T: Num>(n: usize, mat: &[T], b: &mut [T]) -> bool {
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
                return false;
            }
            piv[k] = p;
            for j in 0..n {
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
        for (k, &p) in piv.iter().enumerate() {
            b.swap(k, p);
        }
        for k in 0..n {
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
        true
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

    /// Factorise diag·I − J with both kernels (with the instruction set `arch`) and solve
    /// for b; compare with the reference bit for bit (== also equates ±0).
    fn check_against_reference(n: usize, jac: &[f64], diag: Complex<f64>, arch: Arch) {
        let mut rnd = stream(n as u64 + 7);
        let b: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let bc: Vec<Complex<f64>> = b.iter().map(|&v| Complex::new(v, rnd())).collect();

        let real: Vec<f64> = (0..n * n)
            .map(|k| -jac[k] + if k % (n + 1) == 0 { diag.re } else { 0.0 })
            .collect();
        let mut want = b.clone();
        let ok = reference_solve(n, &real, &mut want);
        let mut lu = RealLu::with_arch(n, arch);
        lu.set_shifted(diag.re, jac);
        assert_eq!(lu.factor().is_ok(), ok, "real singularity");
        if ok {
            let mut x = b.clone();
            lu.solve(&mut x);
            for (got, want) in x.iter().zip(&want) {
                assert!(got == want, "real n = {n}: {got:e} vs {want:e}");
            }
        }

        let cmat: Vec<Complex<f64>> = (0..n * n)
            .map(|k| {
                let d = if k % (n + 1) == 0 {
                    diag
                } else {
                    Complex::new(0.0, 0.0)
                };
                Complex::new(-jac[k], 0.0) + d
            })
            .collect();
        let mut want = bc.clone();
        let ok = reference_solve(n, &cmat, &mut want);
        let mut clu = ComplexLu::with_arch(n, arch);
        clu.set_shifted(diag, jac);
        assert_eq!(clu.factor().is_ok(), ok, "complex singularity");
        if ok {
            let mut re: Vec<f64> = bc.iter().map(|v| v.re).collect();
            let mut im: Vec<f64> = bc.iter().map(|v| v.im).collect();
            clu.solve(&mut re, &mut im);
            for ((r, i), want) in re.iter().zip(&im).zip(&want) {
                assert!(
                    *r == want.re && *i == want.im,
                    "complex n = {n}: {r:e}{i:+e}i vs {want:e}"
                );
            }
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
    /// instruction sets: bit-identical to the reference.
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
    /// 1e-3 to 1e9 (so that pivoting happens), for shifts across step sizes: bit-identical
    /// to the dense reference, with the sparsity actually skipping work.
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
