//! The linearised system's modes: eigenvalues of ∂f/∂x as frequency, damping ratio and time
//! constant, each named by the states that take part in it.
//!
//! The eigenvalues come from the real Schur form of the Jacobian (nalgebra's `Schur`). For
//! each one, the right eigenvector v (J v = λ v) and the left eigenvector w (wᵀ J = λ wᵀ) are
//! found by inverse iteration in complex arithmetic on J − μI and Jᵀ − μI, with μ a shift a
//! relative 1e-9 away from λ. The **participation factor** of state i in the mode is
//! p_i = |v_i|·|w_i| / Σ_k |v_k|·|w_k| (Pérez-Arriaga, Verghese & Schweppe 1982, in magnitude):
//! it does not depend on the units of the states, and the shares sum to 1.
//!
//! For λ = σ ± iω_d: natural frequency ω_n = |λ|, damped frequency ω_d, damping ratio
//! ζ = −σ/|λ| and time constant τ = −1/σ (infinite when σ ≥ 0). A complex pair is reported
//! once (ω_d ≥ 0).

use nalgebra::{Complex, DMatrix, DVector};

use crate::equations::StateEquations;

/// One mode of the linearised system.
#[derive(Clone, Debug)]
pub struct Mode {
    /// The eigenvalue (1/s), with Im ≥ 0.
    pub eigenvalue: Complex<f64>,
    /// Natural frequency |λ|/2π (Hz).
    pub natural_hz: f64,
    /// Damped frequency Im λ/2π (Hz); 0 for a real eigenvalue.
    pub damped_hz: f64,
    /// Damping ratio −Re λ/|λ| (1 for a decaying real eigenvalue, 0 for λ = 0).
    pub damping_ratio: f64,
    /// Time constant −1/Re λ (s); infinite if the mode does not decay.
    pub time_constant: f64,
    /// Participation factors (state index, share), largest first, shares summing to 1.
    pub participation: Vec<(usize, f64)>,
}

/// Why the modes could not be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModesError {
    /// The Jacobian has a value that is not finite.
    #[error(
        "the Jacobian is not finite at ∂f({row})/∂x({col}): the model cannot be linearised here"
    )]
    NotFinite {
        /// The state whose derivative it is.
        row: String,
        /// The state it is taken with respect to.
        col: String,
    },
    /// More states than [`MAX_MODES_STATES`]: the analysis is dense.
    #[error("{n} states, more than the {limit} the modal analysis takes: it is dense (the Schur form O(n³), then one O(n³) inverse iteration per eigenvalue: about n⁴; 100 states take about 0.4 s, 200 about 4 s, 400 about a minute)")]
    TooLarge {
        /// Number of states.
        n: usize,
        /// [`MAX_MODES_STATES`].
        limit: usize,
    },
    /// More states than [`crate::linearize::MAX_LINEARIZE_STATES`]: A is written dense.
    #[error("{n} states, more than the {limit} `linearize` takes: A, B, C and D are dense (n² entries of A: {limit} states are {entries} million numbers, {mb} MB, and as many lines of CSV)")]
    LinearizeTooLarge {
        /// Number of states.
        n: usize,
        /// [`crate::linearize::MAX_LINEARIZE_STATES`].
        limit: usize,
        /// limit², in millions (for the message).
        entries: usize,
        /// limit² × 8 bytes, in MB (for the message).
        mb: usize,
    },
    /// The eigenvalue iteration did not converge.
    #[error("the eigenvalues of the {n}×{n} Jacobian did not converge")]
    NoConvergence {
        /// Number of states.
        n: usize,
    },
}

/// The modes of a Jacobian, fastest (largest |λ|) first.
///
/// # Complexity
/// O(n³) for the Schur form, and O(n³) per eigenvalue for the inverse iterations.
pub fn modes_of(jac: &DMatrix<f64>) -> Result<Vec<Mode>, ModesError> {
    let n = jac.nrows();
    if n == 0 {
        return Ok(Vec::new());
    }
    // Balance first (B = D⁻¹JD, D diagonal powers of 2): the eigenvalues and the
    // participation factors are those of J, computed on a matrix of much smaller norm.
    let jac = &balanced(jac);
    let schur = nalgebra::Schur::try_new(jac.clone(), f64::EPSILON, 10_000 * n)
        .ok_or(ModesError::NoConvergence { n })?;
    let mut lambdas: Vec<Complex<f64>> = schur
        .complex_eigenvalues()
        .iter()
        .copied()
        .filter(|l| l.im >= 0.0)
        .collect();
    lambdas.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    let scale = jac.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
    let jc: DMatrix<Complex<f64>> = jac.map(|v| Complex::new(v, 0.0));
    let jt = jc.transpose();
    Ok(lambdas
        .into_iter()
        .map(|l| {
            let v = eigenvector(&jc, l, scale);
            let w = eigenvector(&jt, l, scale);
            let mut p: Vec<(usize, f64)> = (0..n).map(|i| (i, v[i].norm() * w[i].norm())).collect();
            let total: f64 = p.iter().map(|x| x.1).sum();
            if total > 0.0 && total.is_finite() {
                for x in &mut p {
                    x.1 /= total;
                }
            }
            p.sort_by(|a, b| b.1.total_cmp(&a.1));
            mode(l, p)
        })
        .collect())
}

/// Parlett–Reinsch balancing: scale row i by 1/f and column i by f (f a power of 2) until
/// every off-diagonal row and column sum are within a factor 2 of each other.
fn balanced(jac: &DMatrix<f64>) -> DMatrix<f64> {
    let mut b = jac.clone();
    let n = b.nrows();
    for _ in 0..100 {
        let mut done = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in (0..n).filter(|&j| j != i) {
                c += b[(j, i)].abs();
                r += b[(i, j)].abs();
            }
            if !(c > 0.0 && r > 0.0 && c.is_finite() && r.is_finite()) {
                continue;
            }
            let total = c + r;
            let mut f = 1.0;
            while c < r / 2.0 {
                c *= 2.0;
                r /= 2.0;
                f *= 2.0;
            }
            while c >= r * 2.0 {
                c /= 2.0;
                r *= 2.0;
                f /= 2.0;
            }
            if c + r < 0.95 * total {
                done = false;
                for j in 0..n {
                    b[(i, j)] /= f;
                    b[(j, i)] *= f;
                }
            }
        }
        if done {
            break;
        }
    }
    b
}

fn mode(l: Complex<f64>, participation: Vec<(usize, f64)>) -> Mode {
    let two_pi = 2.0 * std::f64::consts::PI;
    let r = l.norm();
    Mode {
        eigenvalue: l,
        natural_hz: r / two_pi,
        damped_hz: l.im / two_pi,
        damping_ratio: if r > 0.0 { -l.re / r } else { 0.0 },
        time_constant: if l.re < 0.0 {
            -1.0 / l.re
        } else {
            f64::INFINITY
        },
        participation,
    }
}

/// Inverse iteration on (a − μI) with μ = λ shifted by a relative 1e-9 (of |λ| or of the
/// matrix's scale), three sweeps from a fixed start; normalised to unit 2-norm.
fn eigenvector(a: &DMatrix<Complex<f64>>, l: Complex<f64>, scale: f64) -> DVector<Complex<f64>> {
    let n = a.nrows();
    let mut v = DVector::from_fn(n, |i, _| {
        Complex::new(1.0 + (i as f64 * 0.618).fract(), 0.3)
    });
    for shift in [1e-9, 1e-7, 1e-5] {
        let d = shift * l.norm().max(1e-6 * scale);
        let mu = l + Complex::new(d, d);
        let mut m = a.clone();
        for i in 0..n {
            m[(i, i)] -= mu;
        }
        let lu = m.lu();
        let mut ok = true;
        for _ in 0..3 {
            match lu.solve(&v) {
                Some(next) => {
                    let norm = next.norm();
                    if !(norm > 0.0 && norm.is_finite()) {
                        ok = false;
                        break;
                    }
                    v = next.unscale(norm);
                }
                None => {
                    ok = false;
                    break;
                }
            }
        }
        if ok {
            return v;
        }
    }
    v
}

/// Most states [`modes`] analyses: its cost grows about as n⁴ (measured on the pipe of
/// `scripts/pipe-model.sh`, release build, loaded 2-core machine: 101 states 0.4 s, 201 states
/// 4.3 s, 401 states 64 s).
pub const MAX_MODES_STATES: usize = 300;

/// The modes of `eqs` linearised at (t, x), fastest first.
///
/// # Errors
/// [`ModesError::TooLarge`] above [`MAX_MODES_STATES`] states, before any work;
/// [`ModesError::NotFinite`], [`ModesError::NoConvergence`].
pub fn modes(eqs: &StateEquations, t: f64, x: &[f64]) -> Result<Vec<Mode>, ModesError> {
    if eqs.n_states() > MAX_MODES_STATES {
        return Err(ModesError::TooLarge {
            n: eqs.n_states(),
            limit: MAX_MODES_STATES,
        });
    }
    let mut jac = DMatrix::zeros(eqs.n_states(), eqs.n_states());
    eqs.jacobian(t, x, &mut jac);
    if let Some(k) = jac.iter().position(|v| !v.is_finite()) {
        let n = eqs.n_states();
        let name = |i: usize| eqs.states()[i].name.clone();
        return Err(ModesError::NotFinite {
            row: name(k % n),
            col: name(k / n),
        });
    }
    modes_of(&jac)
}

/// The stiffness ratio max|λ| / min|λ| over the eigenvalues with |λ| above 1e-9 of the
/// largest (the others count as zero: integrators, rigid-body motion), and the number of
/// those near-zero eigenvalues (complex pairs counted once).
#[must_use]
pub fn stiffness_ratio(modes: &[Mode]) -> (f64, usize) {
    let max = modes
        .iter()
        .map(|m| m.eigenvalue.norm())
        .fold(0.0, f64::max);
    let floor = 1e-9 * max;
    let min = modes
        .iter()
        .map(|m| m.eigenvalue.norm())
        .filter(|&r| r > floor)
        .fold(f64::INFINITY, f64::min);
    let zeros = modes
        .iter()
        .filter(|m| m.eigenvalue.norm() <= floor)
        .count();
    (if min.is_finite() { max / min } else { 1.0 }, zeros)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::{
        assign_causality, BondGraph, Capacitor, Inertia, OneJunction, Resistor, Transformer,
        ZeroJunction,
    };

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// Series RLC: L q̈ + R q̇ + q/C = 0, ω_n = 1/√(LC), ζ = (R/2)·√(C/L).
    #[test]
    fn rlc_circuit_matches_closed_form() {
        let (l, r, c) = (2e-3, 4.0, 5e-6);
        let mut g = BondGraph::new();
        g.add("i", OneJunction).unwrap();
        g.add("coil", Inertia::new(l, 0.0).unwrap()).unwrap();
        g.add("res", Resistor::new(r).unwrap()).unwrap();
        g.add("cap", Capacitor::new(c, 1e-6).unwrap()).unwrap();
        for b in ["coil", "res", "cap"] {
            g.connect_names("i", b).unwrap();
        }
        let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let ms = modes(&eqs, 0.0, &eqs.initial_state()).unwrap();
        assert_eq!(ms.len(), 1, "one complex pair");
        let wn = 1.0 / (l * c).sqrt();
        let zeta = r / 2.0 * (c / l).sqrt();
        let m = &ms[0];
        let e1 = rel(m.natural_hz * 2.0 * std::f64::consts::PI, wn);
        let e2 = rel(m.damping_ratio, zeta);
        let e3 = rel(m.time_constant, 2.0 * l / r);
        eprintln!("RLC: ω_n rel. err {e1:.1e}, ζ {e2:.1e}, τ {e3:.1e}");
        assert!(e1 < 1e-6 && e2 < 1e-6 && e3 < 1e-6, "{m:?}");
        // both states take part equally in an oscillation
        assert!((m.participation[0].1 - 0.5).abs() < 1e-6, "{m:?}");
    }

    /// A mass on a column of oil: V/β compliance behind a piston of area A,
    /// ω = √(β·A²/(V·m)); no damping.
    #[test]
    fn mass_on_a_hydraulic_spring() {
        let (beta, a, v, m) = (1.5e9, 0.01, 2e-3, 500.0);
        let mut g = BondGraph::new();
        g.add("oil", Capacitor::new(v / beta, 0.0).unwrap())
            .unwrap();
        g.add("p", ZeroJunction).unwrap();
        g.add("piston", Transformer::new(1.0 / a).unwrap()).unwrap();
        g.add("x", OneJunction).unwrap();
        g.add("mass", Inertia::new(m, 0.0).unwrap()).unwrap();
        g.connect_names("p", "oil").unwrap();
        g.connect_names("p", "piston").unwrap();
        g.connect_names("piston", "x").unwrap();
        g.connect_names("x", "mass").unwrap();
        let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let ms = modes(&eqs, 0.0, &eqs.initial_state()).unwrap();
        let w = (beta * a * a / (v * m)).sqrt();
        let got = ms[0].damped_hz * 2.0 * std::f64::consts::PI;
        eprintln!(
            "hydraulic spring: ω = {got} vs {w}, rel. {:.1e}",
            rel(got, w)
        );
        assert!(rel(got, w) < 1e-6, "{:?}", ms[0]);
        assert!(ms[0].damping_ratio.abs() < 1e-9);
        assert!(ms[0].time_constant.is_infinite() || ms[0].time_constant > 1e6);
    }

    #[test]
    fn real_eigenvalues_and_the_stiffness_ratio() {
        let j = DMatrix::from_row_slice(3, 3, &[-1.0, 0.0, 0.0, 0.0, -1000.0, 0.0, 0.0, 0.0, 0.0]);
        let ms = modes_of(&j).unwrap();
        assert_eq!(ms.len(), 3);
        assert!(rel(ms[0].time_constant, 1e-3) < 1e-12);
        assert_eq!(ms[0].participation[0].0, 1, "the fast mode is state 1");
        assert!((ms[0].damping_ratio - 1.0).abs() < 1e-12);
        let (ratio, zeros) = stiffness_ratio(&ms);
        assert!(rel(ratio, 1000.0) < 1e-12 && zeros == 1, "{ratio} {zeros}");
    }
}
