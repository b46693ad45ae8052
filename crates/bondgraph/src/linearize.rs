//! The model linearised at an operating point, for control design:
//!
//! ```text
//! dδx/dt = A δx + B δu,    δy = C δx + D δu
//! A = ∂f/∂x,  B = ∂f/∂u,  C = ∂y/∂x,  D = ∂y/∂u   at (t, x, u)
//! ```
//!
//! All four are exact: one forward-mode pass of the Jacobian over the whole evaluation plan
//! ([`StateEquations::linear_jacobians`]), the inputs seeded as columns of their own (an
//! input is the signal of an element that reads nothing). The outputs are any probe:
//! a state, an effort, a flow, a signal, a power, a state derivative.
//!
//! From (A, B, C, D): the poles (eigenvalues of A, as [`crate::modes`] finds them), the
//! frequency response G(jω) = C (jωI − A)⁻¹ B + D of one input–output pair (a complex LU per
//! frequency), Bode data (magnitude in dB, phase in degrees, unwrapped along the
//! frequencies) and the DC gains G(0) = D − C A⁻¹ B (one real LU of A for all pairs).
//!
//! # Size
//! Everything here is dense. [`linearize`] refuses more than [`MAX_LINEARIZE_STATES`] states
//! before any work; the poles follow [`crate::modes`] and its limit
//! ([`crate::MAX_MODES_STATES`], the eigen-solver costs about n⁴); a frequency response costs
//! one complex n×n LU per frequency ([`MAX_BODE_STATES`]).

pub use nalgebra::Complex;
use nalgebra::{DMatrix, DVector};

use crate::equations::{Probe, StateEquations};
use crate::modes::ModesError;

/// Most states [`linearize`] takes: A is dense, n² numbers (2 000 states: 4 million, 32 MB,
/// and as many lines in `bg-sim linearize --format csv`).
pub const MAX_LINEARIZE_STATES: usize = 2000;

/// Most states of a frequency response ([`Linearization::bode`]): one complex n×n LU per
/// frequency, ≈ (8/3)n³ flops (300 states: 72 Mflop a frequency, about 10 s for 400).
pub const MAX_BODE_STATES: usize = 300;

/// (A, B, C, D) with the names of their rows and columns.
#[derive(Clone, Debug)]
pub struct Linearization {
    /// Time of the operating point.
    pub t: f64,
    /// State of the operating point.
    pub x: Vec<f64>,
    /// State names (rows and columns of A).
    pub states: Vec<String>,
    /// Input names (columns of B and D).
    pub inputs: Vec<String>,
    /// Output names (rows of C and D).
    pub outputs: Vec<String>,
    /// ∂f/∂x, n×n.
    pub a: DMatrix<f64>,
    /// ∂f/∂u, n×m.
    pub b: DMatrix<f64>,
    /// ∂y/∂x, p×n.
    pub c: DMatrix<f64>,
    /// ∂y/∂u, p×m.
    pub d: DMatrix<f64>,
}

/// One frequency of a Bode diagram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodePoint {
    /// Frequency (Hz).
    pub f_hz: f64,
    /// |G(j2πf)|.
    pub magnitude: f64,
    /// 20·log₁₀|G| (dB).
    pub db: f64,
    /// arg G (degrees), unwrapped along the frequencies.
    pub phase_deg: f64,
}

/// Linearise `eqs` at (t, x) with respect to the signals `inputs` (name, signal offset: an
/// external input's value) for the probes `outputs` (name, probe).
///
/// # Errors
/// [`ModesError::LinearizeTooLarge`] above [`MAX_LINEARIZE_STATES`] states, before any work;
/// [`ModesError::NotFinite`] naming the first entry of A, B, C or D that is not finite.
pub fn linearize(
    eqs: &StateEquations,
    t: f64,
    x: &[f64],
    inputs: &[(String, usize)],
    outputs: &[(String, Probe)],
) -> Result<Linearization, ModesError> {
    let n = eqs.n_states();
    if n > MAX_LINEARIZE_STATES {
        let limit = MAX_LINEARIZE_STATES;
        return Err(ModesError::LinearizeTooLarge {
            n,
            limit,
            entries: limit * limit / 1_000_000,
            mb: limit * limit * 8 / 1_000_000,
        });
    }
    let m = inputs.len();
    let seeds: Vec<usize> = inputs.iter().map(|i| i.1).collect();
    let probes: Vec<Probe> = outputs.iter().map(|o| o.1).collect();
    let (mut fx, mut yx) = (DMatrix::zeros(0, 0), DMatrix::zeros(0, 0));
    eqs.linear_jacobians(t, x, &seeds, &probes, &mut fx, &mut yx);
    let states: Vec<String> = eqs.states().iter().map(|s| s.name.clone()).collect();
    let inputs: Vec<String> = inputs.iter().map(|i| i.0.clone()).collect();
    let outputs: Vec<String> = outputs.iter().map(|o| o.0.clone()).collect();
    let col = |j: usize| {
        if j < n {
            states[j].clone()
        } else {
            inputs[j - n].clone()
        }
    };
    if let Some(k) = fx.iter().position(|v| !v.is_finite()) {
        return Err(ModesError::NotFinite {
            row: format!("{}.dot", states[k % n]),
            col: col(k / n),
        });
    }
    if let Some(k) = yx.iter().position(|v| !v.is_finite()) {
        let p = outputs.len();
        return Err(ModesError::NotFinite {
            row: outputs[k % p].clone(),
            col: col(k / p),
        });
    }
    Ok(Linearization {
        t,
        x: x.to_vec(),
        a: fx.columns(0, n).into_owned(),
        b: fx.columns(n, m).into_owned(),
        c: yx.columns(0, n).into_owned(),
        d: yx.columns(n, m).into_owned(),
        states,
        inputs,
        outputs,
    })
}

impl Linearization {
    /// Every eigenvalue of A (complex pairs both), fastest (largest |λ|) first.
    ///
    /// # Errors
    /// [`ModesError::TooLarge`] above [`crate::MAX_MODES_STATES`] states, before any work;
    /// [`ModesError::NoConvergence`] if the eigenvalue iteration fails.
    pub fn poles(&self) -> Result<Vec<Complex<f64>>, ModesError> {
        let n = self.a.nrows();
        if n > crate::MAX_MODES_STATES {
            return Err(ModesError::TooLarge {
                n,
                limit: crate::MAX_MODES_STATES,
            });
        }
        let mut out = Vec::new();
        for m in crate::modes::modes_of(&self.a)? {
            out.push(m.eigenvalue);
            if m.eigenvalue.im > 0.0 {
                out.push(m.eigenvalue.conj());
            }
        }
        Ok(out)
    }

    /// G(jω) of input `i` to output `o`: C (jωI − A)⁻¹ B + D; `None` if jωI − A is singular
    /// (a pole on the imaginary axis at ω).
    #[must_use]
    pub fn response(&self, i: usize, o: usize, omega: f64) -> Option<Complex<f64>> {
        let n = self.a.nrows();
        let mut m: DMatrix<Complex<f64>> = self.a.map(|v| Complex::new(-v, 0.0));
        for k in 0..n {
            m[(k, k)] += Complex::new(0.0, omega);
        }
        let b = DVector::from_fn(n, |k, _| Complex::new(self.b[(k, i)], 0.0));
        let v = if n == 0 { b } else { m.lu().solve(&b)? };
        let g: Complex<f64> = (0..n).map(|k| v[k] * self.c[(o, k)]).sum();
        let g = g + self.d[(o, i)];
        (g.re.is_finite() && g.im.is_finite()).then_some(g)
    }

    /// The DC gain G(0) = D − C A⁻¹ B of input `i` to output `o`; `None` if A is singular
    /// (an integrator: the gain is infinite).
    #[must_use]
    pub fn dc_gain(&self, i: usize, o: usize) -> Option<f64> {
        self.response(i, o, 0.0).map(|g| g.re)
    }

    /// Every DC gain at once: G(0) = D − C A⁻¹ B, outputs × inputs, from one real LU of A;
    /// `None` if A is singular (an integrator: the gains are infinite).
    #[must_use]
    pub fn dc_gains(&self) -> Option<DMatrix<f64>> {
        let n = self.a.nrows();
        if n == 0 {
            return Some(self.d.clone());
        }
        let x = self.a.clone().lu().solve(&self.b)?;
        let g = &self.d - &self.c * x;
        g.iter().all(|v| v.is_finite()).then_some(g)
    }

    /// Bode data of input `i` to output `o` at the frequencies `f_hz` (ascending), the phase
    /// unwrapped from the first frequency on. Frequencies at a pole are left out.
    #[must_use]
    pub fn bode(&self, i: usize, o: usize, f_hz: &[f64]) -> Vec<BodePoint> {
        let mut out: Vec<BodePoint> = Vec::with_capacity(f_hz.len());
        for &f in f_hz {
            let Some(g) = self.response(i, o, 2.0 * std::f64::consts::PI * f) else {
                continue;
            };
            let magnitude = g.norm();
            let mut phase = g.arg().to_degrees();
            if let Some(prev) = out.last() {
                phase += 360.0 * ((prev.phase_deg - phase) / 360.0).round();
            }
            out.push(BodePoint {
                f_hz: f,
                magnitude,
                db: 20.0 * magnitude.log10(),
                phase_deg: phase,
            });
        }
        out
    }
}

/// `count` frequencies from `lo` to `hi` (Hz, both > 0), evenly spaced on a log scale.
#[must_use]
pub fn log_frequencies(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    if count < 2 {
        return vec![lo];
    }
    let (a, b) = (lo.ln(), hi.ln());
    (0..count)
        .map(|k| (a + (b - a) * k as f64 / (count - 1) as f64).exp())
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)] // exact values by intent
    use super::*;
    use crate::StateEquations;

    /// m = 1, k = 100, c = 2 (no input: A and C only).
    fn msd() -> StateEquations {
        crate::test_models::msd(1.0, 0.01, 2.0, 0.0, None)
    }

    #[test]
    fn poles_of_the_mass_spring_damper() {
        let eqs = msd();
        let x = eqs.initial_state();
        let outputs = [
            ("x".to_owned(), eqs.probe("spring.q").unwrap()),
            ("v".to_owned(), eqs.probe("mass.f").unwrap()),
            ("F_spring".to_owned(), eqs.probe("spring.e").unwrap()),
        ];
        let lin = linearize(&eqs, 0.0, &x, &[], &outputs).unwrap();
        let poles = lin.poles().unwrap();
        assert_eq!(poles.len(), 2);
        for p in &poles {
            assert!((p.re + 1.0).abs() < 1e-12, "{p}");
            assert!((p.im.abs() - 99f64.sqrt()).abs() < 1e-12, "{p}");
        }
        // C: x = q (spring state), v = p/m, F = q/C.
        let iq = lin.states.iter().position(|s| s == "spring.q").unwrap();
        let ip = lin.states.iter().position(|s| s == "mass.p").unwrap();
        assert_eq!(lin.c[(0, iq)], 1.0);
        assert!((lin.c[(1, ip)] - 1.0).abs() < 1e-15);
        assert!((lin.c[(2, iq)] - 100.0).abs() < 1e-12);
        assert_eq!((lin.b.ncols(), lin.d.shape()), (0, (3, 0)));
    }

    /// The MSD driven by an input `F` through a modulated effort source.
    fn msd_with_input() -> StateEquations {
        crate::test_models::msd(1.0, 0.01, 2.0, 0.0, Some(0.0))
    }

    /// B = ∂f/∂F and D: exact; the DC gain is 1/k; |G(jω)| = 1/|k − mω² + jcω|; the force
    /// itself as an output has D = 1.
    #[test]
    fn input_columns_dc_gain_and_frequency_response() {
        let eqs = msd_with_input();
        let x = eqs.initial_state();
        let f = eqs.input_signal_offset(0).unwrap();
        let outputs = [
            ("x".to_owned(), eqs.probe("spring.q").unwrap()),
            ("force".to_owned(), eqs.probe("force.e").unwrap()),
            ("P".to_owned(), eqs.probe("force.P").unwrap()),
        ];
        let lin = linearize(&eqs, 0.0, &x, &[("F".into(), f)], &outputs).unwrap();
        let ip = lin.states.iter().position(|s| s == "mass.p").unwrap();
        let iq = lin.states.iter().position(|s| s == "spring.q").unwrap();
        assert_eq!(lin.b[(ip, 0)], 1.0, "dp/dt = F − …");
        assert_eq!(lin.b[(iq, 0)], 0.0);
        assert_eq!(lin.d[(0, 0)], 0.0);
        assert_eq!(lin.d[(1, 0)], 1.0, "the source's effort is F");
        assert_eq!(lin.d[(2, 0)], 0.0, "P = F·v, v = 0 at rest");
        let dc = lin.dc_gain(0, 0).unwrap();
        assert!((dc - 0.01).abs() < 1e-15, "{dc}");
        // all pairs from one real LU = each pair from its complex solve at ω = 0
        let all = lin.dc_gains().unwrap();
        assert_eq!(all.shape(), (3, 1));
        for o in 0..3 {
            let one = lin.dc_gain(0, o).unwrap();
            assert!(
                (all[(o, 0)] - one).abs() <= 1e-15 * one.abs().max(1.0),
                "{o}"
            );
        }
        let mut worst = 0.0f64;
        for w in [0.1, 1.0, 9.0, 10.0, 99f64.sqrt(), 30.0, 300.0] {
            let g = lin.response(0, 0, w).unwrap();
            let want = 1.0 / Complex::new(100.0 - w * w, 2.0 * w);
            worst = worst.max((g - want).norm() / want.norm());
        }
        assert!(worst < 1e-12, "{worst}");
        let b = lin.bode(0, 0, &log_frequencies(0.01, 100.0, 200));
        assert!((b[0].db - 20.0 * 0.01f64.log10()).abs() < 1e-3);
        assert!(
            b[0].phase_deg.abs() < 0.1 && (b[199].phase_deg + 180.0).abs() < 1.0,
            "{:?}",
            b[199]
        );
        // the phase is unwrapped: it falls monotonically from 0 to −180°
        assert!(b
            .windows(2)
            .all(|p| p[1].phase_deg <= p[0].phase_deg + 1e-9));
        // B against a central difference of f in F at a state away from rest
        let x1 = [0.3, -0.02];
        let lin1 = linearize(&eqs, 0.0, &x1, &[("F".into(), f)], &outputs).unwrap();
        let mut fp = [0.0; 2];
        let mut fm = [0.0; 2];
        eqs.set_input(0, 1e-3).unwrap();
        eqs.rhs(0.0, &x1, &mut fp);
        eqs.set_input(0, -1e-3).unwrap();
        eqs.rhs(0.0, &x1, &mut fm);
        for i in 0..2 {
            assert!((lin1.b[(i, 0)] - (fp[i] - fm[i]) / 2e-3).abs() < 1e-9);
        }
        // P = F·v: ∂P/∂F = v = p/m at x1
        assert!(
            (lin1.d[(2, 0)] - x1[ip]).abs() < 1e-15,
            "{}",
            lin1.d[(2, 0)]
        );
    }

    #[test]
    fn a_singular_a_has_no_dc_gains_and_the_size_limits_hold() {
        // a free mass: dp/dt = F, A = 0 (an integrator)
        let lin = Linearization {
            t: 0.0,
            x: vec![0.0],
            states: vec!["p".into()],
            inputs: vec!["F".into()],
            outputs: vec!["p".into()],
            a: DMatrix::zeros(1, 1),
            b: DMatrix::from_element(1, 1, 1.0),
            c: DMatrix::from_element(1, 1, 1.0),
            d: DMatrix::zeros(1, 1),
        };
        assert!(lin.dc_gains().is_none());
        assert!(lin.dc_gain(0, 0).is_none());
        // the poles refuse a matrix above the modal analysis' limit, before any work
        let n = crate::MAX_MODES_STATES + 1;
        let big = Linearization {
            a: DMatrix::identity(n, n),
            b: DMatrix::zeros(n, 0),
            c: DMatrix::zeros(0, n),
            d: DMatrix::zeros(0, 0),
            states: vec![String::new(); n],
            x: vec![0.0; n],
            ..lin
        };
        assert!(matches!(
            big.poles(),
            Err(ModesError::TooLarge { n: k, limit }) if k == n && limit == crate::MAX_MODES_STATES
        ));
        assert!(big.dc_gains().is_some());
    }

    #[test]
    fn log_frequencies_span_the_range() {
        let f = log_frequencies(0.1, 100.0, 4);
        let want = [0.1, 1.0, 10.0, 100.0];
        for (a, b) in f.iter().zip(want) {
            assert!((a / b - 1.0).abs() < 1e-12, "{f:?}");
        }
    }
}
