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
//!   with a non-zero in row k are updated. No symbolic pattern is needed, so a Jacobian
//!   whose zeros move costs nothing extra. On the knuckle-boom crane (n = 38) this does
//!   about half the multiply-adds of a dense LU.
//! - **Interchange, then update by adjacent pairs**: rows k and p are interchanged in the
//!   trailing columns in a pass of their own; then the trailing columns are visited two
//!   adjacent ones at a time (sharing the loads of the L column), each with u = a[k, j] ≠ 0
//!   updated. (Before issue 22 one pass did both, pairing each column with the next non-zero
//!   one; its bookkeeping cost more than the updates on the crane.)
//! - **Padded columns**: each column has [`PAD`] rows of padding below row n − 1, so that
//!   the row range of every update, widened to a multiple of four rows, fits and the vector
//!   loops never fall back to scalar remainders (a third of the complex kernel's update
//!   instructions before). The rows added hold exact zeros of L, or padding.
//! - **Slices, bounds asserted once**: the pivot search and the zero scans run over slices,
//!   and the bounds of the update loops are asserted once per step, so that the loops carry
//!   no bounds checks.
//! - **Explicit four-wide vectors** in the updates of factorisations and forward solves
//!   (pulp's `f64s`): LLVM's own vectorisation ran eight rows per iteration and left the
//!   last four rows of most columns to a scalar loop (40 % of the real kernel's update
//!   instructions on the crane).
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
//! **NaN and ∞.** Skipping x − l·u for l = 0 or u = 0 is exact only for finite l and u
//! (0·∞ and NaN·0 are NaN). In the textbook LU a non-finite l or u always ends in a refused
//! pivot: a non-finite u = a[k, j] makes rows k + 1.. of column j all ∞ or NaN (x − l·u, with
//! l = 0 giving NaN), so the pivot search of step j finds an infinite size or only NaN; a
//! non-finite l in row i makes row i ∞ or NaN in every trailing column, which stays so, and
//! at the step whose diagonal it reaches (NaN never wins a pivot search) the pivot is
//! refused. Until the first non-finite l or u every skip is exact, so the kernels meet it
//! exactly when the textbook does, and they refuse the matrix then (L: checked as it is
//! scaled; U: once at the end, where it is final). So a factorisation either is the
//! textbook's or is refused as it would be; before issue 22 a u = NaN was skipped, which
//! could accept a matrix the textbook refuses. The solves skip b[k] = 0 (the factors are
//! finite) but trim the zero rows of L and U only for finite b[k] and x[k].
//!
//! **Bit-identical results.** Every entry receives the same operations in the same order as
//! in the textbook dense LU with partial pivoting and its forward and back substitution
//! (the skipped ones are exact zeros, x − 0·a = x), so factors and solutions are the same to
//! the last bit, up to the sign of zero entries; the tests check this. It matters: the
//! step-size control amplifies any round-off change to the tolerance level (multiplying by
//! stored reciprocals of the pivots instead of dividing made the solves 20 % faster but
//! moved the crane's trajectory by 2.5e-5 of its scale, with 901 steps instead of 882).
//!
//! Measured and not taken (`examples/lu_bench`, the crane's Jacobians, h = 1e-4…1e-2):
//! - faer 0.24's partial-pivot LU: slower at these sizes on the crane (n = 38: real 4.0 µs,
//!   complex 6.6 µs, against 2.8 and 4.4 here; n = 66: 11.5/20.9 against 10.1/17.7); it wins
//!   only on dense matrices from n ≈ 60 (n = 100: 26/53 µs against 41/80).
//! - A fill-reducing state ordering (Markowitz on the pattern of J): 31 % of a dense LU's
//!   multiply-adds instead of 52 % at n = 38, but only 12 % less time (18 % at n = 66), as
//!   the dense mechanical block remains; and it changes the round-off (see above).
//! - A left-looking variant updating each column from four L columns at once: slower,
//!   through its bookkeeping. Issue 22, left-looking with the textbook order per entry
//!   (column j: step k's interchange, then x −= l_k·u_kj, k = 0..j increasing; bit-identical),
//!   complex kernel on the crane: 124.5 k instructions per call one column at a time,
//!   117.3 k two adjacent columns at a time, against 107.3 k right-looking, and slower in
//!   time (≈ 9.8 and 9.3 µs against 7.8): each update of column j waits on the stores of the
//!   previous one, where the right-looking step updates independent columns. Four trailing columns per pass instead of two: no gain.
//! - The complex system as a real 2n×2n one on this real kernel: 3× slower (twice the
//!   arithmetic).
//! - (Callgrind instructions per call on the crane's Jacobians, `LU_COUNT` in lu_bench.)
//!   Two elimination steps per pass over the trailing columns (a rank-2 update, still
//!   bit-identical): its update loop 7.5 k instructions instead of 11.7 k, but the extra
//!   bookkeeping ate the gain (real 54.3 k against 54.0 k). In the complex update the
//!   explicit vectors only match LLVM's own loop (114 k either way); indexed or eight-row
//!   variants: 116–121 k. The pivot search over a scratch slice of sizes (no bounds
//!   checks): real 56 k against 54 k.

mod complex;
mod real;
#[cfg(test)]
// Bit-identical results are what the tests check.
#[allow(clippy::float_cmp)]
mod tests;

pub(crate) use complex::ComplexLu;
pub(crate) use real::RealLu;

use pulp::Simd;

/// The matrix has a zero or non-finite pivot, or (which leads there in the textbook LU) a
/// non-finite entry of L or U.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Singular;

/// x −= l·a, four rows per vector (explicit vectors: LLVM's own vectorisation ran eight
/// rows per pass and left the last four rows of most columns to a scalar loop).
#[inline(always)]
fn axpy<S: Simd>(simd: S, x: &mut [f64], l: &[f64], a: f64) {
    let m = x.len();
    let (xv, xt) = S::as_mut_simd_f64s(x);
    let (lv, lt) = S::as_simd_f64s(&l[..m]);
    let va = simd.splat_f64s(a);
    for (x, l) in xv.iter_mut().zip(lv) {
        *x = simd.sub_f64s(*x, simd.mul_f64s(*l, va));
    }
    for (x, &l) in xt.iter_mut().zip(lt) {
        *x -= l * a;
    }
}

/// x −= l·a and y −= l·b.
#[inline(always)]
fn axpy2<S: Simd>(simd: S, x: &mut [f64], y: &mut [f64], l: &[f64], a: f64, b: f64) {
    let m = l.len();
    let (xv, xt) = S::as_mut_simd_f64s(&mut x[..m]);
    let (yv, yt) = S::as_mut_simd_f64s(&mut y[..m]);
    let (lv, lt) = S::as_simd_f64s(l);
    let (va, vb) = (simd.splat_f64s(a), simd.splat_f64s(b));
    for ((x, y), l) in xv.iter_mut().zip(yv.iter_mut()).zip(lv) {
        *x = simd.sub_f64s(*x, simd.mul_f64s(*l, va));
        *y = simd.sub_f64s(*y, simd.mul_f64s(*l, vb));
    }
    for ((x, y), &l) in xt.iter_mut().zip(yt.iter_mut()).zip(lt) {
        *x -= l * a;
        *y -= l * b;
    }
}

/// x −= l·a for complex numbers on planes, with the operations of `num_complex`:
/// l·a = (lr·ar − li·ai) + i(lr·ai + li·ar).
#[inline(always)]
fn caxpy<S: Simd>(simd: S, xr: &mut [f64], xi: &mut [f64], lr: &[f64], li: &[f64], a: (f64, f64)) {
    let m = lr.len();
    let (xrv, xrt) = S::as_mut_simd_f64s(&mut xr[..m]);
    let (xiv, xit) = S::as_mut_simd_f64s(&mut xi[..m]);
    let (lrv, lrt) = S::as_simd_f64s(lr);
    let (liv, lit) = S::as_simd_f64s(&li[..m]);
    let (ar, ai) = (simd.splat_f64s(a.0), simd.splat_f64s(a.1));
    let body = xrv.iter_mut().zip(xiv.iter_mut()).zip(lrv.iter().zip(liv));
    for ((xr, xi), (&lr, &li)) in body {
        let pr = simd.sub_f64s(simd.mul_f64s(lr, ar), simd.mul_f64s(li, ai));
        let pi = simd.add_f64s(simd.mul_f64s(lr, ai), simd.mul_f64s(li, ar));
        *xr = simd.sub_f64s(*xr, pr);
        *xi = simd.sub_f64s(*xi, pi);
    }
    let tail = xrt.iter_mut().zip(xit.iter_mut()).zip(lrt.iter().zip(lit));
    for ((xr, xi), (&lr, &li)) in tail {
        *xr -= lr * a.0 - li * a.1;
        *xi -= lr * a.1 + li * a.0;
    }
}

/// x −= l·a and y −= l·b for complex numbers on planes. (Separate slices, not tuples of
/// them: with tuples the loop ran 30 % slower.)
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn caxpy2<S: Simd>(
    simd: S,
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
    let (xrv, xrt) = S::as_mut_simd_f64s(&mut xr[..m]);
    let (xiv, xit) = S::as_mut_simd_f64s(&mut xi[..m]);
    let (yrv, yrt) = S::as_mut_simd_f64s(&mut yr[..m]);
    let (yiv, yit) = S::as_mut_simd_f64s(&mut yi[..m]);
    let (lrv, lrt) = S::as_simd_f64s(lr);
    let (liv, lit) = S::as_simd_f64s(&li[..m]);
    let (ar, ai) = (simd.splat_f64s(a.0), simd.splat_f64s(a.1));
    let (br, bi) = (simd.splat_f64s(b.0), simd.splat_f64s(b.1));
    let x = xrv.iter_mut().zip(xiv.iter_mut());
    let y = yrv.iter_mut().zip(yiv.iter_mut());
    for (((xr, xi), (yr, yi)), (&lr, &li)) in x.zip(y).zip(lrv.iter().zip(liv)) {
        let pr = simd.sub_f64s(simd.mul_f64s(lr, ar), simd.mul_f64s(li, ai));
        let pi = simd.add_f64s(simd.mul_f64s(lr, ai), simd.mul_f64s(li, ar));
        *xr = simd.sub_f64s(*xr, pr);
        *xi = simd.sub_f64s(*xi, pi);
        let qr = simd.sub_f64s(simd.mul_f64s(lr, br), simd.mul_f64s(li, bi));
        let qi = simd.add_f64s(simd.mul_f64s(lr, bi), simd.mul_f64s(li, br));
        *yr = simd.sub_f64s(*yr, qr);
        *yi = simd.sub_f64s(*yi, qi);
    }
    let x = xrt.iter_mut().zip(xit.iter_mut());
    let y = yrt.iter_mut().zip(yit.iter_mut());
    for (((xr, xi), (yr, yi)), (&lr, &li)) in x.zip(y).zip(lrt.iter().zip(lit)) {
        *xr -= lr * a.0 - li * a.1;
        *xi -= lr * a.1 + li * a.0;
        *yr -= lr * b.0 - li * b.1;
        *yi -= lr * b.1 + li * b.0;
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

/// The largest of four lanes of sizes and a remainder (NaN sizes never win: `s > m` is
/// false). Exact, so the lane order does not matter; four lanes so that it vectorises.
#[inline(always)]
fn lane_max(chunks: impl Iterator<Item = [f64; 4]>, rest: impl Iterator<Item = f64>) -> f64 {
    let mut m = [0.0f64; 4];
    for c in chunks {
        for (mw, s) in m.iter_mut().zip(c) {
            *mw = if s > *mw { s } else { *mw };
        }
    }
    for s in rest {
        m[0] = if s > m[0] { s } else { m[0] };
    }
    m[0].max(m[1]).max(m[2].max(m[3]))
}

/// The pivot of partial pivoting among `sizes`, whose largest is `best`: the first of the
/// largest, which is what a scan keeping the first of equal sizes finds. `None` if that size
/// is zero or not finite, or if entry 0 is NaN (such a scan starts from it and never
/// replaces it).
#[inline(always)]
fn pivot(best: f64, mut sizes: impl Iterator<Item = f64> + Clone) -> Option<usize> {
    let first = sizes.clone().next()?;
    // (best < ∞ rather than is_finite(): best is not NaN.)
    if best > 0.0 && best < f64::INFINITY && !first.is_nan() {
        // Exact: best is one of the sizes.
        #[allow(clippy::float_cmp)]
        sizes.position(|s| s == best)
    } else {
        None
    }
}

/// The pivot of a real column, sizes |a| (see [`pivot`]); slices, so no bounds checks.
#[inline(always)]
fn pivot_real(col: &[f64]) -> Option<usize> {
    let chunks = col.chunks_exact(4);
    let rest = chunks.remainder().iter().map(|v| v.abs());
    let best = lane_max(
        chunks.map(|c| [c[0].abs(), c[1].abs(), c[2].abs(), c[3].abs()]),
        rest,
    );
    pivot(best, col.iter().map(|v| v.abs()))
}

/// The pivot of a complex column on planes, sizes |re| + |im| as LAPACK's (see [`pivot`]).
#[inline(always)]
fn pivot_complex(re: &[f64], im: &[f64]) -> Option<usize> {
    let im = &im[..re.len()];
    let size = |(r, i): (&f64, &f64)| r.abs() + i.abs();
    let (cr, ci) = (re.chunks_exact(4), im.chunks_exact(4));
    let rest = cr.remainder().iter().zip(ci.remainder()).map(size);
    let chunks = cr.zip(ci).map(|(r, i)| {
        [
            r[0].abs() + i[0].abs(),
            r[1].abs() + i[1].abs(),
            r[2].abs() + i[2].abs(),
            r[3].abs() + i[3].abs(),
        ]
    });
    pivot(lane_max(chunks, rest), re.iter().zip(im).map(size))
}

/// The rows lo..hi of first.. outside which a column is zero, from the first and last
/// non-zero's positions relative to first (lo = hi = end if there is none).
#[inline(always)]
fn nonzero_rows(
    first: usize,
    end: usize,
    pos: Option<usize>,
    rpos: Option<usize>,
) -> (usize, usize) {
    match (pos, rpos) {
        (Some(lo), Some(hi)) => (first + lo, first + hi + 1),
        _ => (end, end),
    }
}

/// `bits(v − v)`: zero if v is finite, not zero if it is infinite or NaN; OR-ed over a
/// column (integer OR, so that it vectorises) it tells whether the whole column is finite.
#[inline(always)]
fn non_finite_bits(v: f64) -> u64 {
    // v − v is +0 for every finite v (also −0), NaN otherwise.
    #[allow(clippy::eq_op)]
    (v - v).to_bits()
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
}

impl Pattern {
    fn new(n: usize) -> Self {
        Self {
            piv: vec![0; n],
            lo: vec![0; n],
            hi: vec![0; n],
            top: vec![0; n],
        }
    }
}

/// Rows of padding below each column of the factors: every update then runs over a
/// multiple of four rows, [`padded_end`] reaching at most 3 rows below row n − 1. The
/// padding rows of L stay zero (they are never scaled), so that the trailing columns'
/// padding rows only ever receive x − 0·u; they are never read as results.
const PAD: usize = 3;

/// The end of rows lo..hi extended to a multiple of four rows (into zero rows of L, or the
/// padding).
#[inline(always)]
fn padded_end(lo: usize, hi: usize) -> usize {
    lo + (hi - lo).div_ceil(4) * 4
}
