//! The kernels against the textbook dense LU, bit for bit.

use nalgebra::Complex;
use pulp::Arch;

use super::*;

mod structured;

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
pub(super) fn stream(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// The same value: equal (±0 equated: skipping x − 0·u may keep a zero's sign where the
/// textbook flips it), or both NaN (NaN payloads are not compared).
fn same(got: f64, want: f64) -> bool {
    got == want || (got.is_nan() && want.is_nan())
}

/// Right-hand sides for the checks: random, with exact zeros (which the forward solve
/// skips) every third entry.
fn rhs(n: usize, rnd: &mut impl FnMut() -> f64) -> Vec<f64> {
    (0..n)
        .map(|i| if i % 3 == 1 { 0.0 } else { rnd() })
        .collect()
}

/// Factorise diag·I − J with both kernels (with the instruction set `arch`) and solve:
/// factors, interchanges and solution are those of the reference bit for bit (see
/// [`same`]), singularity is detected alike, and for finite matrices the residual is at
/// round-off level. `b`: the real right-hand side (the complex one is b + i·b reversed).
pub(super) fn check_with_rhs(n: usize, jac: &[f64], diag: Complex<f64>, arch: Arch, b: &[f64]) {
    let on_diagonal = |k: usize| k % (n + 1) == 0;
    let finite = jac.iter().chain(b).all(|v| v.is_finite());

    let mat: Vec<f64> = (0..n * n)
        .map(|k| -jac[k] + if on_diagonal(k) { diag.re } else { 0.0 })
        .collect();
    let reference = reference_factor(n, &mat);
    let mut lu = RealLu::with_arch(n, arch);
    lu.set_shifted(diag.re, jac);
    assert_eq!(lu.factor().is_ok(), reference.is_some(), "real singularity");
    if let Some((a, piv)) = reference {
        assert_eq!(lu.pat.piv, piv, "real interchanges, n = {n}");
        for j in 0..n {
            for i in 0..n {
                let (got, want) = (lu.a[j * lu.ld + i], a[j * n + i]);
                assert!(
                    same(got, want),
                    "real n = {n}, ({i}, {j}): {got:e} vs {want:e}"
                );
            }
        }
        let mut x = b.to_vec();
        lu.solve(&mut x);
        let mut want = b.to_vec();
        reference_solve(n, &a, &piv, &mut want);
        for (got, want) in x.iter().zip(&want) {
            assert!(
                same(*got, *want),
                "real n = {n}: solution {got:e} vs {want:e}"
            );
        }
        if finite {
            let r = residual(n, &mat, &x, b);
            assert!(r < 1e-15, "real n = {n}: residual {r:e}");
        }
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
        for j in 0..n {
            for i in 0..n {
                let (r, m) = (clu.re[j * clu.ld + i], clu.im[j * clu.ld + i]);
                let want = a[j * n + i];
                assert!(
                    same(r, want.re) && same(m, want.im),
                    "complex n = {n}, ({i}, {j}): {r:e} {m:e} vs {want}"
                );
            }
        }
        let bc: Vec<Complex<f64>> = b
            .iter()
            .zip(b.iter().rev())
            .map(|(&r, &i)| Complex::new(r, i))
            .collect();
        let mut re: Vec<f64> = bc.iter().map(|v| v.re).collect();
        let mut im: Vec<f64> = bc.iter().map(|v| v.im).collect();
        clu.solve(&mut re, &mut im);
        let mut want = bc.clone();
        reference_solve(n, &a, &piv, &mut want);
        for ((r, m), want) in re.iter().zip(&im).zip(&want) {
            assert!(
                same(*r, want.re) && same(*m, want.im),
                "complex n = {n}: solution {r:e} {m:e} vs {want}"
            );
        }
        if finite {
            let x: Vec<Complex<f64>> = re
                .iter()
                .zip(&im)
                .map(|(&r, &i)| Complex::new(r, i))
                .collect();
            let r = residual(n, &cmat, &x, &bc);
            assert!(r < 1e-15, "complex n = {n}: residual {r:e}");
        }
    }
}

/// [`check_with_rhs`] with a random right-hand side (zeros every third entry).
pub(super) fn check_against_reference(n: usize, jac: &[f64], diag: Complex<f64>, arch: Arch) {
    let mut rnd = stream(n as u64 + 7);
    let b = rhs(n, &mut rnd);
    check_with_rhs(n, jac, diag, arch, &b);
}

/// Solving with the factors of a matrix that needs pivoting reproduces a known solution.
#[test]
fn real_and_complex_solves_reproduce_a_known_solution() {
    let n = 5;
    // J with a zero in the (0, 0) corner of diag − J so that pivoting is needed.
    let mut jac = vec![0.0; n * n];
    for j in 0..n {
        for i in 0..n {
            jac[j * n + i] = ((i * 7 + j * 3) % 5) as f64 - 2.0 + if i == j { 1.0 } else { 0.0 };
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

/// Random sparsity patterns (5, 20 and 60 % dense) on top of a cyclic shift, so that with
/// a small diagonal rows are interchanged at steps whose L column is empty (the kernels
/// then only interchange) and the count of columns to update is odd or even: the
/// reference's factors, solutions and singularity verdicts, bit for bit, across sizes and
/// both instruction sets.
#[test]
fn random_sparse_patterns_match_the_reference_bit_for_bit() {
    for n in [3, 6, 11, 23, 38, 41] {
        for (s, density) in [0.05, 0.2, 0.6].into_iter().enumerate() {
            let mut rnd = stream(100 + 3 * n as u64 + s as u64);
            let mut jac: Vec<f64> = (0..n * n)
                .map(|_| {
                    let v = rnd();
                    if v.abs() < density {
                        1e3 * rnd()
                    } else {
                        0.0
                    }
                })
                .collect();
            for k in 0..n {
                jac[k * n + (k + 1) % n] = 1e4 * (1.0 + rnd().abs());
            }
            for diag in [
                Complex::new(0.0, 0.0),
                Complex::new(1.0, 0.5),
                Complex::new(1e5, 1e5),
            ] {
                for arch in [Arch::new(), Arch::Scalar] {
                    check_against_reference(n, &jac, diag, arch);
                }
            }
        }
    }
}
