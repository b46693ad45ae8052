//! The sparse LU against nalgebra's dense LU on random sparse matrices, real and complex;
//! refactorisation with new values; the fallback to pivot search where a stored pivot fails.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::c64;
use nalgebra::{Complex, DMatrix, DVector};

use super::{SparseLu, SparsePattern};

/// A small deterministic generator (LCG), values in [−1, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn below(&mut self, n: usize) -> usize {
        ((self.next() + 1.0) * 0.5 * n as f64) as usize % n
    }
}

/// A random pattern with about `per_col` off-diagonal entries a column, and J on it.
fn random_jacobian(rng: &mut Rng, n: usize, per_col: usize) -> (SparsePattern, Vec<f64>) {
    let cols: Vec<Vec<usize>> = (0..n)
        .map(|_| (0..per_col).map(|_| rng.below(n)).collect())
        .collect();
    let pattern = SparsePattern::from_columns(n, &cols).unwrap();
    let jac = (0..pattern.nnz()).map(|_| 10.0 * rng.next()).collect();
    (pattern, jac)
}

/// shift·I − J, dense.
fn dense<T: nalgebra::ComplexField<RealField = f64> + Copy>(
    pattern: &SparsePattern,
    jac: &[f64],
    shift: T,
) -> DMatrix<T> {
    let n = pattern.n();
    let mut a = DMatrix::from_element(n, n, T::zero());
    for j in 0..n {
        for s in pattern.col_ptr()[j]..pattern.col_ptr()[j + 1] {
            a[(pattern.row_idx()[s], j)] = T::from_real(-jac[s]);
        }
        a[(j, j)] += shift;
    }
    a
}

/// max |x − y| / max |y|.
fn rel_diff<T: nalgebra::ComplexField<RealField = f64> + Copy>(x: &[T], y: &[T]) -> f64 {
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.modulus()));
    let diff = x
        .iter()
        .zip(y)
        .fold(0.0f64, |m, (a, b)| m.max((*a - *b).modulus()));
    diff / scale
}

/// Relative agreement with the dense LU (both partial pivoting, well-conditioned
/// matrices: round-off only).
const TOL: f64 = 1e-10;

fn check_real(lu: &mut SparseLu<f64>, pattern: &SparsePattern, jac: &[f64], shift: f64) {
    let n = pattern.n();
    let b: Vec<f64> = (0..n).map(|i| ((i * 7 + 1) as f64).sin()).collect();
    let want = dense(pattern, jac, shift)
        .lu()
        .solve(&DVector::from_vec(b.clone()));
    let mut x = b;
    lu.solve(&mut x);
    let d = rel_diff(&x, want.unwrap().as_slice());
    assert!(d <= TOL, "real: relative difference {d:e} (n = {n})");
}

fn check_complex(lu: &mut SparseLu<c64>, pattern: &SparsePattern, jac: &[f64], shift: c64) {
    let n = pattern.n();
    let (mut re, mut im): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|i| (((i * 7 + 1) as f64).sin(), ((i * 3) as f64).cos()))
        .unzip();
    let b: Vec<Complex<f64>> = re.iter().zip(&im).map(|(&r, &i)| c64::new(r, i)).collect();
    let want = dense(pattern, jac, shift).lu().solve(&DVector::from_vec(b));
    lu.solve(&mut re, &mut im);
    let x: Vec<Complex<f64>> = re.iter().zip(&im).map(|(&r, &i)| c64::new(r, i)).collect();
    let d = rel_diff(&x, want.unwrap().as_slice());
    assert!(d <= TOL, "complex: relative difference {d:e} (n = {n})");
}

/// Random sparse matrices, real and complex, factorised and then refactorised with new
/// values (J scaled and perturbed, the shift changed): every solve agrees with the dense
/// LU, and the later ones ran on the stored pivot order unless partial pivoting changed it.
#[test]
fn random_matrices_agree_with_dense_lu() {
    let mut rng = Rng(7);
    for &(n, per_col) in &[(1, 1), (5, 2), (40, 3), (200, 3), (300, 6)] {
        let (pattern, jac) = random_jacobian(&mut rng, n, per_col);
        let mut real = SparseLu::<f64>::new(&pattern).unwrap();
        let mut complex = SparseLu::<c64>::new(&pattern).unwrap();
        for round in 0..6 {
            let jac: Vec<f64> = jac
                .iter()
                .map(|v| v * (1.0 + 0.1 * round as f64) + 0.01 * rng.next())
                .collect();
            let (gamma, shift) = (
                20.0 + 5.0 * round as f64,
                c64::new(15.0, 8.0 - round as f64),
            );
            real.factor(&pattern, gamma, &jac).unwrap();
            check_real(&mut real, &pattern, &jac, gamma);
            complex.factor(&pattern, shift, &jac).unwrap();
            check_complex(&mut complex, &pattern, &jac, shift);
        }
        for c in [real.counts(), complex.counts()] {
            assert_eq!(c.refactorised + c.pivoted, 6, "{c:?}");
            assert!(c.pivoted >= 1, "{c:?}");
        }
    }
}

/// The refactorisation on an unchanged pivot order gives the pivoted factorisation's
/// solution to the bit (the same operations in the same order).
#[test]
fn refactorisation_repeats_pivoted_bits() {
    let mut rng = Rng(11);
    let (pattern, jac) = random_jacobian(&mut rng, 150, 3);
    let mut lu = SparseLu::<c64>::new(&pattern).unwrap();
    let shift = c64::new(40.0, 12.0);
    lu.factor(&pattern, shift, &jac).unwrap();
    let jac2: Vec<f64> = jac.iter().map(|v| v * 1.001).collect();
    lu.factor(&pattern, shift, &jac2).unwrap();
    assert_eq!(lu.counts().refactorised, 1, "{:?}", lu.counts());
    let n = pattern.n();
    let (mut re, mut im) = (vec![1.0; n], vec![0.5; n]);
    lu.solve(&mut re, &mut im);
    lu.factor_pivoted(&pattern, shift, &jac2).unwrap();
    let (mut re2, mut im2) = (vec![1.0; n], vec![0.5; n]);
    lu.solve(&mut re2, &mut im2);
    assert_eq!(re, re2);
    assert_eq!(im, im2);
}

/// A stored pivot that becomes zero (the first matrix diagonally dominant, the second with
/// a zero diagonal) forces a pivoted factorisation, which solves correctly; a refactorisation
/// that would keep it cannot (its pivot is 0).
#[test]
fn lost_pivot_falls_back_to_pivot_search() {
    let n = 4;
    let pattern = SparsePattern::dense(n);
    // J column by column; A = shift·I − J.
    let jac1: Vec<f64> = (0..n * n)
        .map(|s| if s % (n + 1) == 0 { 0.0 } else { 0.5 })
        .collect();
    let mut real = SparseLu::<f64>::new(&pattern).unwrap();
    let mut complex = SparseLu::<c64>::new(&pattern).unwrap();
    real.factor(&pattern, 10.0, &jac1).unwrap();
    complex
        .factor(&pattern, c64::new(10.0, 1.0), &jac1)
        .unwrap();
    // Second matrix: zero diagonal (shift 0, J_ii = 0), off-diagonal entries of all sizes.
    let jac2: Vec<f64> = (0..n * n)
        .map(|s| {
            if s % (n + 1) == 0 {
                0.0
            } else {
                1.0 + s as f64
            }
        })
        .collect();
    real.factor(&pattern, 0.0, &jac2).unwrap();
    check_real(&mut real, &pattern, &jac2, 0.0);
    complex.factor(&pattern, c64::new(0.0, 0.0), &jac2).unwrap();
    check_complex(&mut complex, &pattern, &jac2, c64::new(0.0, 0.0));
    for c in [real.counts(), complex.counts()] {
        assert_eq!((c.refactorised, c.pivoted), (0, 2), "{c:?}");
    }
    // And back: the new order refactorises the second matrix scaled.
    let jac3: Vec<f64> = jac2.iter().map(|v| 2.0 * v).collect();
    real.factor(&pattern, 0.0, &jac3).unwrap();
    check_real(&mut real, &pattern, &jac3, 0.0);
    assert_eq!(real.counts().refactorised, 1);
}

/// A pivot order that partial pivoting would change although no pivot is zero: column 0
/// had its diagonal the largest in either column, now the off-diagonal entries are larger.
#[test]
fn overtaken_pivot_falls_back() {
    let pattern = SparsePattern::dense(2);
    let mut lu = SparseLu::<f64>::new(&pattern).unwrap();
    // A = [[3, 1], [1, 3]], then [[1, 3], [2, 1]] (A = −J by columns, shift 0).
    lu.factor(&pattern, 0.0, &[-3.0, -1.0, -1.0, -3.0]).unwrap();
    lu.factor(&pattern, 0.0, &[-1.0, -2.0, -3.0, -1.0]).unwrap();
    assert_eq!(lu.counts().pivoted, 2, "{:?}", lu.counts());
    let mut x = vec![4.0, 3.0];
    lu.solve(&mut x);
    // x + 3y = 4, 2x + y = 3: x = 1, y = 1.
    assert!(
        (x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15,
        "{x:?}"
    );
}
