//! Structured and non-finite matrices against the textbook LU: the crane's block pattern,
//! zero blocks, negative zeros, exact cancellations, NaN and ∞ (which forbid the skips).

use nalgebra::Complex;
use pulp::Arch;

use super::{check_against_reference, check_with_rhs, stream};
use crate::lu::{ComplexLu, RealLu};

/// γ and α + iβ of Radau IIA order 5, the shifts the integrator factorises with.
const GAMMA: f64 = 3.637_834_252_744_496;
const ALPHA: f64 = 2.681_082_873_627_752;
const BETA: f64 = 3.050_430_199_247_411;

/// A Jacobian shaped like the crane's (n = 38): states 8..26 a dense block, hydraulic rows
/// 0..8 coupled to it, rows 26..38 coupled to it and sparsely among themselves, rows and
/// columns `zero` all zero, entries from 1e-3 to 1e9 (so that pivoting happens).
fn crane_like(seed: u64, zero: std::ops::Range<usize>) -> Vec<f64> {
    let n = 38;
    let mut rnd = stream(seed);
    let mut jac = vec![0.0; n * n];
    let mut set = |i: usize, j: usize, v: f64| jac[j * n + i] = v;
    for i in 8..n {
        for j in 8..26 {
            set(i, j, 1e2 * rnd());
        }
    }
    for i in 0..8 {
        set(i, i, -1e3 * (1.0 + rnd().abs()));
        for j in (8..26).step_by(2 + i % 3) {
            set(i, j, 1e9 * rnd());
        }
        set(8 + 2 * i, i, 1e-3 * rnd());
    }
    for i in 26..n {
        set(i, 26 + (i + 6 - 26) % 12, 1e4 * rnd());
        set(8 + (i - 26), i, rnd());
    }
    for i in 0..n {
        for j in zero.clone() {
            set(i, j, 0.0);
            set(j, i, 0.0);
        }
    }
    jac
}

/// The crane's block pattern, with and without zero row/column blocks, at the integrator's
/// shifts across step sizes (and a zero shift: singular with zero blocks, alike), both
/// instruction sets: factors and solutions of the textbook LU; and the kernels do skip.
#[test]
fn crane_block_pattern_matches_the_reference() {
    for (seed, zero) in [(1, 0..0), (2, 30..34), (3, 0..2), (4, 36..38)] {
        let jac = crane_like(seed, zero.clone());
        let mut lu = RealLu::new(38);
        lu.set_shifted(GAMMA / 1e-3, &jac);
        assert!(lu.factor().is_ok());
        let trimmed = (0..38).filter(|&k| lu.pat.lo[k] > k + 1).count();
        assert!(trimmed >= 4, "only {trimmed} L columns trimmed");
        for h in [1e-6, 1e-4, 1e-2, 1.0] {
            for arch in [Arch::new(), Arch::Scalar] {
                check_against_reference(38, &jac, Complex::new(ALPHA / h, BETA / h), arch);
                check_against_reference(38, &jac, Complex::new(GAMMA / h, 0.0), arch);
            }
        }
        for arch in [Arch::new(), Arch::Scalar] {
            check_against_reference(38, &jac, Complex::new(0.0, 0.0), arch);
        }
    }
}

/// Negative zeros (J's −0.0 becomes +0.0 in diag·I − J and the reverse), zero blocks, and
/// entries in powers of two whose elimination cancels exactly, so that zeros of U and L
/// appear during the factorisation: the reference's values (±0 equated).
#[test]
fn negative_zeros_and_exact_cancellations_match_the_reference() {
    for n in [5, 9, 16, 38] {
        let mut rnd = stream(500 + n as u64);
        let mut jac: Vec<f64> = (0..n * n)
            .map(|_| {
                let v = rnd();
                match (v * 8.0) as i64 {
                    -8..=-5 => -0.0,
                    -4..=-1 => 0.0,
                    0..=3 => (2.0f64).powi((v * 40.0) as i32 % 5),
                    _ => -(2.0f64).powi((v * 40.0) as i32 % 3),
                }
            })
            .collect();
        // Column n/2 a multiple of column 1 (exact in powers of two): cancels to zeros.
        for i in 0..n {
            jac[(n / 2) * n + i] = 4.0 * jac[n + i];
        }
        for diag in [0.0, 1.0, 0.5, 64.0] {
            for arch in [Arch::new(), Arch::Scalar] {
                check_against_reference(n, &jac, Complex::new(diag, diag / 2.0), arch);
                check_against_reference(n, &jac, Complex::new(diag, 0.0), arch);
            }
        }
    }
}

/// NaN and ∞ in J (in the dense block, in sparse rows, above and below the diagonal),
/// overflow during the elimination, a subnormal pivot (1/pivot = ∞), and non-finite
/// right-hand sides: the textbook's verdicts and values, NaN where it has NaN (0·∞ and
/// NaN·0 are NaN, so the kernels must not skip there).
///
/// A non-finite l or u always reaches a later pivot in the textbook LU (an l row of NaN,
/// or a u column of ∞/NaN below it), so such matrices are refused as singular; skipping
/// x − 0·u there (as the kernels once did for u = NaN) can turn that verdict.
#[test]
fn non_finite_entries_match_the_reference() {
    let odd = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300];
    let mut refused = 0;
    for (c, &v) in odd.iter().enumerate() {
        for place in 0..12 {
            let mut jac = crane_like(10 + place, 30..32);
            let n = 38;
            // Above the diagonal (u rows), below it (L columns), in sparse and dense parts.
            let (i, j) = [
                (2, 20),
                (20, 2),
                (27, 5),
                (5, 27),
                (12, 14),
                (14, 12),
                (33, 36),
                (36, 33),
                (0, 37),
                (37, 0),
                (9, 30),
                (25, 26),
            ][place as usize];
            jac[j * n + i] = v;
            if c >= 3 {
                jac[(j + 1) % n * n + i] = v;
            }
            for arch in [Arch::new(), Arch::Scalar] {
                check_against_reference(n, &jac, Complex::new(ALPHA / 1e-3, BETA / 1e-3), arch);
                check_against_reference(n, &jac, Complex::new(1.0, 0.0), arch);
            }
            let mut lu = RealLu::new(n);
            lu.set_shifted(1.0, &jac);
            let mut clu = ComplexLu::new(n);
            clu.set_shifted(Complex::new(1.0, 1.0), &jac);
            if lu.factor().is_err() && clu.factor().is_err() {
                refused += 1;
            }
        }
    }
    assert!(refused >= 36, "{refused} of the 36 NaN and ∞ cases refused");

    // A subnormal pivot: its column below is zero, 1/pivot = ∞, l = 0·∞ = NaN.
    let n = 6;
    let mut jac = vec![0.0; n * n];
    for k in 0..n {
        jac[k * n + (k + 1) % n] = 1.0;
    }
    jac[0] = -1e-310;
    for j in 1..n {
        jac[j * n + 3] = 0.0;
    }
    jac[n] = 0.0;
    for arch in [Arch::new(), Arch::Scalar] {
        check_against_reference(n, &jac, Complex::new(0.0, 0.0), arch);
    }

    // Finite factors, non-finite right-hand sides.
    let jac = crane_like(5, 0..0);
    let mut rnd = stream(77);
    for (c, &v) in odd.iter().enumerate() {
        let mut b: Vec<f64> = (0..38)
            .map(|i| if i % 3 == 1 { 0.0 } else { rnd() })
            .collect();
        b[(7 * c + 3) % 38] = v;
        b[(11 * c + 20) % 38] = if c % 2 == 0 { v } else { 0.0 };
        for arch in [Arch::new(), Arch::Scalar] {
            check_with_rhs(38, &jac, Complex::new(ALPHA / 1e-2, BETA / 1e-2), arch, &b);
            check_with_rhs(38, &jac, Complex::new(GAMMA / 1e-5, 0.0), arch, &b);
        }
    }
}

/// Non-finite values exactly where the kernels skip: an ∞ or NaN u above an empty L column
/// (the textbook spreads NaN = 0·∞ down its column and refuses the matrix; skipping would
/// not), and ∞ or NaN right-hand side entries over zero rows of L and U (0·∞ is NaN in the
/// textbook's solution).
#[test]
fn non_finite_values_over_skipped_zeros_match_the_reference() {
    let n = 9;
    for v in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        for (i, j) in [(0, 1), (0, 8), (3, 5), (7, 8), (2, 4)] {
            // diag·I − J upper triangular but for one coupling below, with v at (i, j).
            let mut jac = vec![0.0; n * n];
            jac[j * n + i] = v;
            jac[2 * n + 6] = 0.5;
            for arch in [Arch::new(), Arch::Scalar] {
                check_against_reference(n, &jac, Complex::new(1.0, 0.5), arch);
                check_against_reference(n, &jac, Complex::new(2.0, 0.0), arch);
            }
            let mut lu = RealLu::new(n);
            lu.set_shifted(1.0, &jac);
            assert!(lu.factor().is_err(), "({i}, {j}) = {v} must be refused");
        }
    }
    // Sparse finite matrices, a non-finite b at each position in turn.
    for (s, density) in [0.1, 0.3].into_iter().enumerate() {
        let n = 12;
        let mut rnd = stream(900 + s as u64);
        let jac: Vec<f64> = (0..n * n)
            .map(|_| if rnd().abs() < density { rnd() } else { 0.0 })
            .collect();
        for v in [f64::INFINITY, f64::NAN] {
            for at in 0..n {
                let mut b: Vec<f64> = (0..n)
                    .map(|i| if i % 4 == 1 { 0.0 } else { rnd() })
                    .collect();
                b[at] = v;
                for arch in [Arch::new(), Arch::Scalar] {
                    check_with_rhs(n, &jac, Complex::new(3.0, 1.0), arch, &b);
                    check_with_rhs(n, &jac, Complex::new(3.0, 0.0), arch, &b);
                }
            }
        }
    }
}
