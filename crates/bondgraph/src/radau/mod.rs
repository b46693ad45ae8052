//! Radau IIA with 3 stages (order 5, L-stable): the stiff integrator of Hairer and Wanner's
//! RADAU5, written from its description in E. Hairer, G. Wanner, *Solving Ordinary
//! Differential Equations II*, 2nd ed., Springer 1996, section IV.8.
//!
//! # The method
//! Collocation at the Radau points, with the Butcher tableau
//! ```text
//!  c            | A
//!  (4−√6)/10    | (88−7√6)/360       (296−169√6)/1800   (−2+3√6)/225
//!  (4+√6)/10    | (296+169√6)/1800   (88+7√6)/360       (−2−3√6)/225
//!  1            | (16−√6)/36         (16+√6)/36         1/9
//!  -------------+-------------------------------------------------------
//!  b            | (16−√6)/36         (16+√6)/36         1/9
//! ```
//! It is stiffly accurate (y₁ = Y₃). With zᵢ = Yᵢ − y₀ the stage equations are
//! Z = h(A⊗I)F(Z). One step:
//!
//! 1. **Simplified Newton**, transformed by T with T⁻¹A⁻¹T = diag(γ, [[α, −β], [β, α]])
//!    (γ ≈ 3.6378, α ± iβ ≈ 2.6811 ± 3.0504i): each iteration solves one real system with
//!    (γ/h)I − J and one complex system with ((α + iβ)/h)I − J, both n×n, from one LU each.
//!    J is the Jacobian at the step's start.
//! 2. **Starting values** from the previous step's collocation polynomial, extrapolated.
//! 3. **Convergence**: the rate θ = ‖ΔWₖ‖/‖ΔWₖ₋₁‖ (geometric mean after the second
//!    iteration); stop when η‖ΔWₖ‖ ≤ κ with η = θ/(1 − θ) (at the first iteration, η from the
//!    previous step, to the power 0.8). Give up, shrinking h, when θ ≥ 0.99, when the iteration
//!    limit is reached, or when the predicted error after the remaining iterations still
//!    exceeds κ.
//! 4. **Error estimate** from the embedded order-3 formula (weight γ₀ = 1/γ on f(t₀, y₀)),
//!    filtered: err = ((γ/h)I − J)⁻¹(f(t₀, y₀) + Σₖ dₖzₖ/h). On the first step and after a
//!    rejection an estimate ≥ 1 is filtered a second time, with f(t₀, y₀ + err).
//! 5. **Step size**: h_new = h / clamp(err^(1/4)/fac, 1/8, 5), fac = 0.9·(2k_max + 1)/(k + 2k_max)
//!    for k Newton iterations, and Gustafsson's predictive controller on accepted steps.
//! 6. **Reuse**: the Jacobian is kept across steps while Newton converges fast (θ ≤ 0.001 by
//!    default); it is recomputed after a slow convergence, or after a failure or rejection
//!    unless it is already current. The LU factors are kept when the proposed h_new/h lies in
//!    [1, 1.2] (h is then left unchanged).
//!
//! # Tolerances
//! A step is accepted when the RMS of errᵢ/(atolᵢ + rtol·max(|y₀ᵢ|, |y₁ᵢ|)) is at most 1. The
//! tolerances are not transformed (RADAU5 replaces rtol by 0.1·rtol^(2/3)): rtol bounds the
//! local error *estimate* of the order-3 embedded formula, which over-estimates the error of
//! the order-5 solution, so for smooth problems the global error is usually at or below rtol
//! and falls faster than rtol (the tests measure it).
//!
//! # Using it
//! [`Radau5::new`], then [`Radau5::step`] in a loop towards a stop time (an event or the end),
//! [`Radau5::interpolate`] for output and root location inside the last step, and
//! [`Radau5::restart`] after a discontinuity. Integration runs forward in time only.
//!
//! # Allocation
//! None after [`Radau5::new`]: every buffer, both LU factorisations (our own dense LU with
//! partial pivoting, in place, `lu.rs`) and the Jacobian matrix are allocated once.

mod lu;
mod tableau;

use nalgebra::{Complex, DMatrix};
use thiserror::Error;

use lu::DenseLu;
use tableau::Tableau;

/// What the integrator needs from the equations dy/dt = f(t, y).
pub trait OdeSystem {
    /// Number of states.
    fn n(&self) -> usize;
    /// dy = f(t, y).
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]);
    /// The dense Jacobian ∂f/∂y at (t, y) into the n×n `jac`. `fy` = f(t, y), already
    /// evaluated, for finite differences (which then cost n right-hand sides, not n + 1).
    fn jacobian(&mut self, t: f64, y: &[f64], fy: &[f64], jac: &mut DMatrix<f64>);
}

/// Integrator settings.
#[derive(Clone, Debug)]
pub struct RadauOptions {
    /// Relative tolerance, in (0, 1): see the module doc for what it bounds.
    pub rtol: f64,
    /// Absolute tolerances, one per state, or a single value for all; each > 0.
    pub atol: Vec<f64>,
    /// First step size; `None` chooses one from f(t₀, y₀) and one more rhs evaluation.
    pub h0: Option<f64>,
    /// Largest step size.
    pub h_max: f64,
    /// Newton iterations per step before the step is retried smaller (RADAU5: 7).
    pub max_newton_iterations: usize,
    /// Newton stopping tolerance κ, relative to the error tolerance; `None`:
    /// max(10ε/rtol, min(0.03, √rtol)).
    pub newton_tol: Option<f64>,
    /// Convergence rate θ above which the Jacobian is recomputed for the next step (RADAU5:
    /// 0.001). Larger values (0.1) save Jacobians when they are expensive.
    pub jacobian_theta: f64,
}

impl Default for RadauOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: vec![1e-8],
            h0: None,
            h_max: f64::INFINITY,
            max_newton_iterations: 7,
            newton_tol: None,
            jacobian_theta: 0.001,
        }
    }
}

/// Work done so far.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RadauStats {
    /// Accepted steps.
    pub steps: usize,
    /// Steps rejected by the error test.
    pub rejected: usize,
    /// Right-hand-side evaluations by the integrator (not those inside `jacobian`).
    pub rhs_evaluations: usize,
    /// Jacobian evaluations.
    pub jacobians: usize,
    /// Factorisations, each one real and one complex n×n LU.
    pub lu_decompositions: usize,
    /// Newton iterations (each costs 3 rhs evaluations and one real plus one complex solve).
    pub newton_iterations: usize,
    /// Steps retried smaller because Newton diverged, converged too slowly or hit a
    /// non-finite value.
    pub newton_failures: usize,
    /// Singular iteration matrices (the step is retried at half the size).
    pub singular: usize,
}

/// One accepted step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Start of the step.
    pub t_prev: f64,
    /// End of the step (the integrator's new time).
    pub t: f64,
    /// Whether the step ended exactly on `t_stop`.
    pub reached_stop: bool,
    /// Attempts rejected (error test, Newton, singular matrix) before this one was accepted.
    pub retries: usize,
}

/// Why the integrator stopped. Each variant carries the time reached; the state there is
/// still readable with [`Radau5::y`].
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum RadauError {
    /// An option is out of range.
    #[error("invalid Radau option `{option}`: {message}")]
    InvalidOption {
        /// The option.
        option: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A vector has the wrong length.
    #[error("{what} has {got} values but the system has {expected} states")]
    DimensionMismatch {
        /// Which vector.
        what: &'static str,
        /// The number of states.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// The state or f(t, y) has a NaN or infinity.
    #[error("{what} component {index} is not finite at t = {t}: check the equations there (division by zero, a root or logarithm of a negative value, overflow)")]
    NonFinite {
        /// Time.
        t: f64,
        /// Which component.
        index: usize,
        /// `"state"` or `"f(t, y)"`.
        what: &'static str,
    },
    /// The error test kept failing until the step size reached round-off.
    #[error("step size {h:e} too small at t = {t}: the error test keeps failing; the solution may blow up or jump here — check the equations near t, restart at a discontinuity, or loosen rtol/atol")]
    StepSizeTooSmall {
        /// Time reached.
        t: f64,
        /// The last step size tried.
        h: f64,
    },
    /// Newton kept failing until the step size reached round-off.
    #[error("Newton iteration failed down to step size {h:e} at t = {t}: check the Jacobian (sign, scaling, missing terms), whether f is continuous there, or whether the solution blows up")]
    NewtonDiverged {
        /// Time reached.
        t: f64,
        /// The last step size tried.
        h: f64,
    },
    /// The iteration matrix was singular five times in a row.
    #[error("iteration matrix singular at t = {t} (step size {h:e}): the Jacobian may hold NaN or infinity, or the equations may not define dy/dt")]
    SingularMatrix {
        /// Time reached.
        t: f64,
        /// The last step size tried.
        h: f64,
    },
    /// `step` was asked to go backwards or nowhere.
    #[error("t_stop = {t_stop} is not after t = {t}: the integrator steps forward only")]
    StopNotAhead {
        /// Current time.
        t: f64,
        /// The stop time given.
        t_stop: f64,
    },
    /// `interpolate` was asked for a time outside the last step.
    #[error("t = {t} is outside the last step [{t_prev}, {t_now}]: interpolate only within it, before taking the next step")]
    OutsideStep {
        /// Time asked for.
        t: f64,
        /// Start of the last step.
        t_prev: f64,
        /// End of the last step.
        t_now: f64,
    },
}

/// Safety factor of the step-size controller.
const SAFE: f64 = 0.9;
/// Largest growth h_new/h.
const GROW_MAX: f64 = 8.0;
/// Largest shrink h/h_new.
const SHRINK_MAX: f64 = 5.0;
/// Keep h (and the LU) when the controller proposes h_new/h in this band.
const KEEP_H: (f64, f64) = (1.0, 1.2);
/// Consecutive singular iteration matrices before giving up.
const MAX_SINGULAR: usize = 5;

/// What made the last attempt fail, for the error reported when h becomes too small.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Failure {
    ErrorTest,
    Newton,
}

/// The Radau IIA (order 5) integrator; see the module doc.
#[derive(Clone, Debug)]
pub struct Radau5 {
    n: usize,
    tab: Tableau,
    rtol: f64,
    atol: Vec<f64>,
    h_max: f64,
    nit: usize,
    fnewt: f64,
    thet: f64,

    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    /// f(t, y), valid when `f0_valid`.
    f0: Vec<f64>,
    f0_valid: bool,
    /// Step size of the next attempt.
    h: f64,
    /// Length of the last accepted step (scales the collocation polynomial).
    h_last: f64,
    /// Divided differences of the last step's collocation polynomial, in s = (t − t₁)/h.
    cont: [Vec<f64>; 3],
    has_poly: bool,

    z: [Vec<f64>; 3],
    w: [Vec<f64>; 3],
    fk: [Vec<f64>; 3],
    dw_real: Vec<f64>,
    dw_complex: Vec<Complex<f64>>,
    ytmp: Vec<f64>,
    scal: Vec<f64>,
    err_v: Vec<f64>,
    err_f: Vec<f64>,

    jac: DMatrix<f64>,
    /// The Jacobian was evaluated at the current (t, y).
    jac_current: bool,
    need_jac: bool,
    lu_real: DenseLu<f64>,
    lu_complex: DenseLu<Complex<f64>>,
    /// The step size the LU factors belong to.
    lu_h: Option<f64>,

    /// η of the Newton stopping test, carried from step to step.
    faccon: f64,
    /// Convergence rate of the last Newton iteration.
    theta: f64,
    /// Gustafsson's controller: the last accepted step and its error.
    h_acc: f64,
    err_acc: f64,
    accepted_since_start: usize,
    /// The last attempt was rejected.
    reject: bool,

    stats: RadauStats,
}

impl Radau5 {
    /// Set up at (t0, y0): check the options and y0, evaluate f(t0, y0) and choose the first
    /// step size if `options.h0` is `None`.
    pub fn new(
        sys: &mut impl OdeSystem,
        t0: f64,
        y0: &[f64],
        options: RadauOptions,
    ) -> Result<Self, RadauError> {
        let n = sys.n();
        let bad = |option, message: String| Err(RadauError::InvalidOption { option, message });
        if y0.len() != n {
            return Err(RadauError::DimensionMismatch {
                what: "y0",
                expected: n,
                got: y0.len(),
            });
        }
        if !t0.is_finite() {
            return bad("t0", format!("must be finite, got {t0}"));
        }
        let o = &options;
        if !(o.rtol > 0.0 && o.rtol < 1.0) {
            return bad("rtol", format!("must be in (0, 1), got {}", o.rtol));
        }
        let atol = match o.atol.len() {
            1 => vec![o.atol[0]; n],
            len if len == n => o.atol.clone(),
            len => return bad("atol", format!("needs 1 or {n} values, got {len}")),
        };
        if let Some(a) = atol.iter().find(|a| !(a.is_finite() && **a > 0.0)) {
            return bad(
                "atol",
                format!("each value must be finite and > 0, got {a}"),
            );
        }
        if o.h_max.is_nan() || o.h_max <= 0.0 {
            return bad("h_max", format!("must be > 0, got {}", o.h_max));
        }
        if let Some(h0) = o.h0 {
            if !(h0.is_finite() && h0 > 0.0) {
                return bad("h0", format!("must be finite and > 0, got {h0}"));
            }
        }
        if o.max_newton_iterations < 1 {
            return bad("max_newton_iterations", "must be at least 1".into());
        }
        let fnewt = o
            .newton_tol
            .unwrap_or((10.0 * f64::EPSILON / o.rtol).max(0.03f64.min(o.rtol.sqrt())));
        if !(fnewt > 0.0 && fnewt.is_finite()) {
            return bad("newton_tol", format!("must be finite and > 0, got {fnewt}"));
        }
        if !(o.jacobian_theta >= 0.0 && o.jacobian_theta < 1.0) {
            return bad(
                "jacobian_theta",
                format!("must be in [0, 1), got {}", o.jacobian_theta),
            );
        }
        if let Some(index) = y0.iter().position(|v| !v.is_finite()) {
            return Err(RadauError::NonFinite {
                t: t0,
                index,
                what: "state",
            });
        }
        let buf = || vec![0.0; n];
        let mut s = Self {
            n,
            tab: Tableau::new(),
            rtol: o.rtol,
            atol,
            h_max: o.h_max,
            nit: o.max_newton_iterations,
            fnewt,
            thet: o.jacobian_theta,
            t: t0,
            t_prev: t0,
            y: y0.to_vec(),
            y_prev: y0.to_vec(),
            f0: buf(),
            f0_valid: false,
            h: 0.0,
            h_last: 0.0,
            cont: [buf(), buf(), buf()],
            has_poly: false,
            z: [buf(), buf(), buf()],
            w: [buf(), buf(), buf()],
            fk: [buf(), buf(), buf()],
            dw_real: buf(),
            dw_complex: vec![Complex::new(0.0, 0.0); n],
            ytmp: buf(),
            scal: buf(),
            err_v: buf(),
            err_f: buf(),
            jac: DMatrix::zeros(n, n),
            jac_current: false,
            need_jac: true,
            lu_real: DenseLu::new(n),
            lu_complex: DenseLu::new(n),
            lu_h: None,
            faccon: 1.0,
            theta: o.jacobian_theta,
            h_acc: 0.0,
            err_acc: 0.0,
            accepted_since_start: 0,
            reject: false,
            stats: RadauStats::default(),
        };
        s.eval_f0(sys)?;
        s.h = match o.h0 {
            Some(h0) => h0,
            None => s.initial_step(sys),
        }
        .min(s.h_max);
        Ok(s)
    }

    /// Current time.
    #[must_use]
    pub fn t(&self) -> f64 {
        self.t
    }
    /// Current state.
    #[must_use]
    pub fn y(&self) -> &[f64] {
        &self.y
    }
    /// The step size the next step will try first.
    #[must_use]
    pub fn h(&self) -> f64 {
        self.h
    }
    /// Start of the last accepted step (equal to [`Self::t`] before the first step and after
    /// a restart).
    #[must_use]
    pub fn t_prev(&self) -> f64 {
        self.t_prev
    }
    /// Work done so far.
    #[must_use]
    pub fn stats(&self) -> &RadauStats {
        &self.stats
    }

    /// f(t, y) at the current point, unless already known; refuses a non-finite value.
    fn eval_f0(&mut self, sys: &mut impl OdeSystem) -> Result<(), RadauError> {
        if !self.f0_valid {
            sys.rhs(self.t, &self.y, &mut self.f0);
            self.stats.rhs_evaluations += 1;
            if let Some(index) = self.f0.iter().position(|v| !v.is_finite()) {
                return Err(RadauError::NonFinite {
                    t: self.t,
                    index,
                    what: "f(t, y)",
                });
            }
            self.f0_valid = true;
        }
        Ok(())
    }

    /// RMS norm of v/scal.
    fn norm(v: &[f64], scal: &[f64]) -> f64 {
        let sum: f64 = v.iter().zip(scal).map(|(a, s)| (a / s) * (a / s)).sum();
        (sum / v.len().max(1) as f64).sqrt()
    }

    /// The first step size (Hairer, Nørsett & Wanner I, II.4): from ‖y₀‖, ‖f₀‖ and a
    /// difference quotient of f along an explicit Euler step, for an error ∝ h⁴.
    fn initial_step(&mut self, sys: &mut impl OdeSystem) -> f64 {
        for ((s, a), y) in self.scal.iter_mut().zip(&self.atol).zip(&self.y) {
            *s = a + self.rtol * y.abs();
        }
        let d0 = Self::norm(&self.y, &self.scal);
        let d1 = Self::norm(&self.f0, &self.scal);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        }
        .min(self.h_max);
        for ((yt, y), f) in self.ytmp.iter_mut().zip(&self.y).zip(&self.f0) {
            *yt = y + h0 * f;
        }
        sys.rhs(self.t + h0, &self.ytmp, &mut self.err_f);
        self.stats.rhs_evaluations += 1;
        for ((e, f1), f0) in self.err_v.iter_mut().zip(&self.err_f).zip(&self.f0) {
            *e = f1 - f0;
        }
        let d2 = Self::norm(&self.err_v, &self.scal) / h0;
        let dmax = d1.max(d2);
        let h1 = if dmax.is_finite() && dmax > 1e-15 {
            (0.01 / dmax).powf(0.25)
        } else {
            (h0 * 1e-3).max(1e-6)
        };
        (100.0 * h0).min(h1)
    }

    /// Smallest step size before the integrator gives up at time t.
    fn h_min(t: f64) -> f64 {
        (10.0 * f64::EPSILON * t.abs()).max(f64::MIN_POSITIVE)
    }

    /// Take one accepted step towards `t_stop`, retrying rejected attempts with smaller step
    /// sizes, never past `t_stop`; a step that reaches `t_stop` ends on it exactly.
    pub fn step(
        &mut self,
        sys: &mut impl OdeSystem,
        t_stop: f64,
    ) -> Result<StepReport, RadauError> {
        if sys.n() != self.n {
            return Err(RadauError::DimensionMismatch {
                what: "the system",
                expected: self.n,
                got: sys.n(),
            });
        }
        if !t_stop.is_finite() || t_stop <= self.t {
            return Err(RadauError::StopNotAhead { t: self.t, t_stop });
        }
        self.eval_f0(sys)?;
        let mut retries = 0;
        let mut singular = 0;
        let mut failure = Failure::ErrorTest;
        loop {
            let h_wanted = self.h.min(self.h_max);
            let remaining = t_stop - self.t;
            // Stretch by up to 1 % rather than leave a sliver before t_stop.
            let landing = remaining <= 1.01 * h_wanted;
            let h = if landing { remaining } else { h_wanted };
            if h <= Self::h_min(self.t) {
                if landing {
                    // t_stop is within round-off of t: step onto it, keeping y.
                    self.t = t_stop;
                    return Ok(StepReport {
                        t_prev: self.t_prev,
                        t: self.t,
                        reached_stop: true,
                        retries,
                    });
                }
                let (t, h) = (self.t, self.h);
                return Err(match failure {
                    Failure::ErrorTest => RadauError::StepSizeTooSmall { t, h },
                    Failure::Newton => RadauError::NewtonDiverged { t, h },
                });
            }
            if self.need_jac {
                sys.jacobian(self.t, &self.y, &self.f0, &mut self.jac);
                self.stats.jacobians += 1;
                self.jac_current = true;
                self.need_jac = false;
                self.lu_h = None;
            }
            if self.lu_h.is_none_or(|lh| lh.to_bits() != h.to_bits()) {
                self.stats.lu_decompositions += 1;
                if self.factorise(h).is_err() {
                    self.stats.singular += 1;
                    singular += 1;
                    self.lu_h = None;
                    if singular >= MAX_SINGULAR {
                        return Err(RadauError::SingularMatrix { t: self.t, h });
                    }
                    self.h = 0.5 * h;
                    self.reject = true;
                    retries += 1;
                    continue;
                }
                self.lu_h = Some(h);
            }
            let newt = match self.newton(sys, h) {
                Ok(k) => k,
                Err(shrink) => {
                    self.stats.newton_failures += 1;
                    self.h = h * shrink;
                    self.reject = true;
                    self.need_jac = !self.jac_current;
                    failure = Failure::Newton;
                    retries += 1;
                    continue;
                }
            };
            let err = self.error_estimate(sys, h);
            let fac = SAFE.min(SAFE * (1 + 2 * self.nit) as f64 / (newt + 2 * self.nit) as f64);
            let mut quot = (err.powf(0.25) / fac).clamp(1.0 / GROW_MAX, SHRINK_MAX);
            if err >= 1.0 {
                self.stats.rejected += 1;
                self.h = if self.accepted_since_start == 0 {
                    0.1 * h
                } else {
                    h / quot
                };
                self.reject = true;
                self.need_jac = !self.jac_current;
                failure = Failure::ErrorTest;
                retries += 1;
                continue;
            }
            // Accepted.
            if self.accepted_since_start > 0 {
                let gus = (self.h_acc / h) * (err * err / self.err_acc).powf(0.25) / SAFE;
                quot = quot.max(gus.clamp(1.0 / GROW_MAX, SHRINK_MAX));
            }
            self.h_acc = h;
            self.err_acc = err.max(1e-2);
            self.accept(h, if landing { t_stop } else { self.t + h });
            let mut h_new = (h / quot).min(self.h_max);
            if self.reject {
                h_new = h_new.min(h);
            }
            if landing && h_new >= h {
                // A step shortened to land on t_stop says nothing against the longer one.
                h_new = h_new.max(h_wanted.min(self.h_max));
            }
            self.reject = false;
            let slow = self.theta > self.thet;
            let q = h_new / h;
            self.h = if !slow && !landing && (KEEP_H.0..=KEEP_H.1).contains(&q) {
                h
            } else {
                h_new
            };
            self.need_jac = slow;
            return Ok(StepReport {
                t_prev: self.t_prev,
                t: self.t,
                reached_stop: landing,
                retries,
            });
        }
    }

    /// Form and factorise (γ/h)I − J and ((α + iβ)/h)I − J.
    fn factorise(&mut self, h: f64) -> Result<(), lu::Singular> {
        let jac = self.jac.as_slice();
        self.lu_real.set_shifted(self.tab.gamma / h, jac, |v| v);
        self.lu_real.factor()?;
        let shift = Complex::new(self.tab.alpha / h, self.tab.beta / h);
        self.lu_complex
            .set_shifted(shift, jac, |v| Complex::new(v, 0.0));
        self.lu_complex.factor()
    }

    /// Simplified Newton for the stage values of a step of size h. Returns the number of
    /// iterations, or the factor to shrink h by.
    fn newton(&mut self, sys: &mut impl OdeSystem, h: f64) -> Result<usize, f64> {
        let n = self.n;
        let tab = &self.tab;
        let (c1m1, c2m1) = (tab.c[0] - 1.0, tab.c[1] - 1.0);
        // Starting values: the last collocation polynomial, extrapolated.
        if self.has_poly {
            let ratio = h / self.h_last;
            let s = [tab.c[0] * ratio, tab.c[1] * ratio, tab.c[2] * ratio];
            for i in 0..n {
                let (a1, a2, a3) = (self.cont[0][i], self.cont[1][i], self.cont[2][i]);
                let mut zi = [0.0; 3];
                for k in 0..3 {
                    zi[k] = s[k] * (a1 + (s[k] - c2m1) * (a2 + (s[k] - c1m1) * a3));
                    self.z[k][i] = zi[k];
                }
                for k in 0..3 {
                    self.w[k][i] =
                        tab.ti[k][0] * zi[0] + tab.ti[k][1] * zi[1] + tab.ti[k][2] * zi[2];
                }
            }
        } else {
            for k in 0..3 {
                self.z[k].fill(0.0);
                self.w[k].fill(0.0);
            }
        }
        for ((s, a), y) in self.scal.iter_mut().zip(&self.atol).zip(&self.y) {
            *s = a + self.rtol * y.abs();
        }
        self.faccon = self.faccon.max(f64::EPSILON).powf(0.8);
        self.theta = self.thet;
        let (fac1, alphn, betan) = (tab.gamma / h, tab.alpha / h, tab.beta / h);
        let nit = self.nit;
        let (mut dyno_old, mut thq_old) = (1.0, 1.0);
        let mut newt = 0;
        loop {
            if newt >= nit {
                return Err(0.5);
            }
            for k in 0..3 {
                for ((yt, y), z) in self.ytmp.iter_mut().zip(&self.y).zip(&self.z[k]) {
                    *yt = y + z;
                }
                sys.rhs(self.t + tab.c[k] * h, &self.ytmp, &mut self.fk[k]);
            }
            self.stats.rhs_evaluations += 3;
            // Right-hand sides of the transformed systems.
            for i in 0..n {
                let (a1, a2, a3) = (self.fk[0][i], self.fk[1][i], self.fk[2][i]);
                let g = |k: usize| tab.ti[k][0] * a1 + tab.ti[k][1] * a2 + tab.ti[k][2] * a3;
                let (w1, w2, w3) = (self.w[0][i], self.w[1][i], self.w[2][i]);
                self.dw_real[i] = g(0) - fac1 * w1;
                self.dw_complex[i] = Complex::new(
                    g(1) - (alphn * w2 - betan * w3),
                    g(2) - (betan * w2 + alphn * w3),
                );
            }
            self.lu_real.solve(&mut self.dw_real);
            self.lu_complex.solve(&mut self.dw_complex);
            newt += 1;
            self.stats.newton_iterations += 1;
            let mut sum = 0.0;
            for i in 0..n {
                let s = self.scal[i];
                let (a, b) = (self.dw_real[i] / s, self.dw_complex[i] / s);
                sum += a * a + b.re * b.re + b.im * b.im;
            }
            let dyno = (sum / (3 * n).max(1) as f64).sqrt();
            if !dyno.is_finite() {
                return Err(0.5);
            }
            if newt > 1 && newt < nit {
                let thq = dyno / dyno_old;
                self.theta = if newt == 2 {
                    thq
                } else {
                    (thq * thq_old).sqrt()
                };
                thq_old = thq;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    let remaining = (nit - 1 - newt) as i32;
                    let dyth = self.faccon * dyno * self.theta.powi(remaining) / self.fnewt;
                    if dyth >= 1.0 {
                        // Not going to converge in time: shrink h by the predicted factor.
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        return Err(0.8 * qnewt.powf(-1.0 / (4.0 + f64::from(remaining))));
                    }
                } else {
                    return Err(0.5);
                }
            }
            dyno_old = dyno.max(f64::EPSILON);
            for i in 0..n {
                self.w[0][i] += self.dw_real[i];
                self.w[1][i] += self.dw_complex[i].re;
                self.w[2][i] += self.dw_complex[i].im;
                let (w1, w2, w3) = (self.w[0][i], self.w[1][i], self.w[2][i]);
                for k in 0..3 {
                    self.z[k][i] = tab.t[k][0] * w1 + tab.t[k][1] * w2 + tab.t[k][2] * w3;
                }
            }
            if self.faccon * dyno <= self.fnewt {
                return Ok(newt);
            }
        }
    }

    /// The filtered embedded error estimate, in the RMS norm scaled by the tolerances.
    fn error_estimate(&mut self, sys: &mut impl OdeSystem, h: f64) -> f64 {
        let d = [self.tab.d[0] / h, self.tab.d[1] / h, self.tab.d[2] / h];
        for i in 0..self.n {
            let dz = d[0] * self.z[0][i] + d[1] * self.z[1][i] + d[2] * self.z[2][i];
            self.err_f[i] = dz;
            self.err_v[i] = self.f0[i] + dz;
            let y1 = self.y[i] + self.z[2][i];
            self.scal[i] = self.atol[i] + self.rtol * self.y[i].abs().max(y1.abs());
        }
        self.lu_real.solve(&mut self.err_v);
        let mut err = Self::norm(&self.err_v, &self.scal).max(1e-10);
        if err >= 1.0 && (self.accepted_since_start == 0 || self.reject) {
            // Second filtering: stiff components of the first estimate are unreliable.
            for ((yt, y), e) in self.ytmp.iter_mut().zip(&self.y).zip(&self.err_v) {
                *yt = y + e;
            }
            sys.rhs(self.t, &self.ytmp, &mut self.fk[0]);
            self.stats.rhs_evaluations += 1;
            for ((e, f), dz) in self.err_v.iter_mut().zip(&self.fk[0]).zip(&self.err_f) {
                *e = f + dz;
            }
            self.lu_real.solve(&mut self.err_v);
            err = Self::norm(&self.err_v, &self.scal).max(1e-10);
        }
        if err.is_finite() {
            err
        } else {
            1e10
        }
    }

    /// Move to the end of an accepted step of size h and keep its collocation polynomial.
    fn accept(&mut self, h: f64, t_new: f64) {
        let c = self.tab.c;
        let (c1m1, c2m1, c1mc2) = (c[0] - 1.0, c[1] - 1.0, c[0] - c[1]);
        for i in 0..self.n {
            let (z1, z2, z3) = (self.z[0][i], self.z[1][i], self.z[2][i]);
            self.y_prev[i] = self.y[i];
            self.y[i] += z3;
            // Newton divided differences through s = 0, c₂−1, c₁−1, −1 (values z₃, z₂, z₁, 0
            // relative to y₁ − z₃).
            let d01 = (z2 - z3) / c2m1;
            let d12 = (z1 - z2) / c1mc2;
            let d23 = z1 / c[0];
            let d012 = (d12 - d01) / c1m1;
            let d123 = (d12 - d23) / c[1];
            self.cont[0][i] = d01;
            self.cont[1][i] = d012;
            self.cont[2][i] = d012 - d123;
        }
        self.t_prev = self.t;
        self.t = t_new;
        self.h_last = h;
        self.has_poly = true;
        self.f0_valid = false;
        self.jac_current = false;
        self.accepted_since_start += 1;
        self.stats.steps += 1;
    }

    /// The collocation polynomial of the last accepted step at `t` ∈ [t_prev, t], into `out`
    /// (exactly the step's end values at its ends). Before the first step and after a
    /// restart only the current time is valid.
    pub fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), RadauError> {
        if out.len() != self.n {
            return Err(RadauError::DimensionMismatch {
                what: "the output buffer",
                expected: self.n,
                got: out.len(),
            });
        }
        let slack = 8.0 * f64::EPSILON * (self.t.abs().max(self.t_prev.abs()) + self.h_last);
        if !(t >= self.t_prev - slack && t <= self.t + slack) {
            return Err(RadauError::OutsideStep {
                t,
                t_prev: self.t_prev,
                t_now: self.t,
            });
        }
        if t >= self.t || !self.has_poly {
            out.copy_from_slice(&self.y);
            return Ok(());
        }
        if t <= self.t_prev {
            out.copy_from_slice(&self.y_prev);
            return Ok(());
        }
        let s = (t - self.t) / self.h_last;
        let (c1m1, c2m1) = (self.tab.c[0] - 1.0, self.tab.c[1] - 1.0);
        for (i, o) in out.iter_mut().enumerate() {
            let (a1, a2, a3) = (self.cont[0][i], self.cont[1][i], self.cont[2][i]);
            *o = self.y[i] + s * (a1 + (s - c2m1) * (a2 + (s - c1m1) * a3));
        }
        Ok(())
    }

    /// Continue after a discontinuity at the current time (a parameter switch, a jump of the
    /// state): keep t and y, or take `y`; forget the interpolation polynomial, the Jacobian,
    /// the LU factors and the controller's history. The next step starts from the current
    /// step-size proposal and, as on the first step, divides it by 10 if its error test
    /// fails.
    pub fn restart(&mut self, y: Option<&[f64]>) -> Result<(), RadauError> {
        if let Some(y) = y {
            if y.len() != self.n {
                return Err(RadauError::DimensionMismatch {
                    what: "the restart state",
                    expected: self.n,
                    got: y.len(),
                });
            }
            if let Some(index) = y.iter().position(|v| !v.is_finite()) {
                return Err(RadauError::NonFinite {
                    t: self.t,
                    index,
                    what: "state",
                });
            }
            self.y.copy_from_slice(y);
        }
        self.y_prev.copy_from_slice(&self.y);
        self.t_prev = self.t;
        self.f0_valid = false;
        self.has_poly = false;
        self.jac_current = false;
        self.need_jac = true;
        self.lu_h = None;
        self.faccon = 1.0;
        self.theta = self.thet;
        self.accepted_since_start = 0;
        self.reject = false;
        Ok(())
    }
}
