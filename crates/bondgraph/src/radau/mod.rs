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
//! The Jacobian threshold θ ≤ 0.001 suits cheap analytic Jacobians; with finite-difference
//! Jacobians (n right-hand sides each) set [`RadauOptions::jacobian_theta`] to about 0.1,
//! which trades Jacobians for a few more Newton iterations.
//!
//! # Using it
//! [`Radau5::new`], then [`Radau5::step`] in a loop towards a stop time (an event or the end),
//! [`Radau5::interpolate`] for output and root location inside the last step, and
//! [`Radau5::restart`] after a discontinuity. Integration runs forward in time only.
//!
//! ```
//! use bondgraph::radau::{OdeSystem, Radau5, RadauOptions};
//! use nalgebra::DMatrix;
//!
//! /// y' = −k·y, with k switched by the caller.
//! struct Decay { k: f64 }
//! impl OdeSystem for Decay {
//!     fn n(&self) -> usize { 1 }
//!     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) { dy[0] = -self.k * y[0]; }
//!     fn jacobian(&mut self, _t: f64, _y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
//!         jac[(0, 0)] = -self.k;
//!     }
//! }
//!
//! let mut sys = Decay { k: 1.0 };
//! let options = RadauOptions { rtol: 1e-8, atol: vec![1e-12], ..RadauOptions::default() };
//! let mut radau = Radau5::new(&mut sys, 0.0, &[1.0], options)?;
//! let mut y_half = [0.0];
//! for (t_stop, k_after) in [(1.0, 10.0), (2.0, 10.0)] {
//!     // Step onto the event (or the end); output rows come from the dense output.
//!     while !radau.step(&mut sys, t_stop)?.reached_stop {
//!         if (radau.t_prev()..=radau.t()).contains(&0.5) {
//!             radau.interpolate(0.5, &mut y_half)?;
//!         }
//!     }
//!     sys.k = k_after; // the event: a parameter switch
//!     radau.restart(None)?;
//! }
//! assert!((y_half[0] - (-0.5f64).exp()).abs() < 1e-7);
//! assert!((radau.y()[0] - (-1.0f64 - 10.0).exp()).abs() < 1e-9);
//! # Ok::<(), bondgraph::radau::RadauError>(())
//! ```
//!
//! # Files
//! `tableau.rs` derives every constant from A and c; `lu.rs` is the LU (dense storage,
//! numerically found zeros skipped, complex on separate real/imaginary planes); `stages.rs`
//! does one attempt (factorisation, Newton, error estimate, collocation polynomial);
//! `controller.rs` chooses step sizes; `error.rs` holds [`RadauError`].
//!
//! # Allocation
//! None after [`Radau5::new`]: every buffer, both LU factorisations and the Jacobian matrix
//! are allocated once. The LU is our own (partial pivoting, in place on preallocated
//! column-major storage, `lu.rs`), because nalgebra's `LU::new` takes the matrix by value and
//! allocates its permutation on every call. Checked with a counting allocator: 0 allocations
//! in 1 169 steps, 3 restarts and 1 169 interpolations of Van der Pol.

mod controller;
mod error;
mod lu;
mod stages;
mod tableau;

/// The Jacobian's matrix type, re-exported so that implementing [`OdeSystem`] needs no
/// direct dependency on nalgebra.
pub use nalgebra::DMatrix;

use controller::Controller;
pub use error::RadauError;
use lu::{ComplexLu, RealLu};
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
    /// 0.001). Larger values (0.1) save Jacobians when they are expensive: on the knuckle-boom
    /// crane (38 states, finite-difference Jacobians) 0.1 needed 3–7× fewer Jacobians and
    /// ran 1.3–1.7× faster than 0.001 at rtol 1e-3 to 1e-6.
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
    /// Real and imaginary parts of the complex system's right-hand side and solution.
    dw_re: Vec<f64>,
    dw_im: Vec<f64>,
    ytmp: Vec<f64>,
    scal: Vec<f64>,
    err_v: Vec<f64>,
    err_f: Vec<f64>,

    jac: DMatrix<f64>,
    /// The Jacobian was evaluated at the current (t, y).
    jac_current: bool,
    need_jac: bool,
    lu_real: RealLu,
    lu_complex: ComplexLu,
    /// The step size the LU factors belong to.
    lu_h: Option<f64>,

    /// η of the Newton stopping test, carried from step to step.
    faccon: f64,
    /// Convergence rate of the last Newton iteration.
    theta: f64,
    /// Step-size controller.
    ctrl: Controller,
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
            dw_re: buf(),
            dw_im: buf(),
            ytmp: buf(),
            scal: buf(),
            err_v: buf(),
            err_f: buf(),
            jac: DMatrix::zeros(n, n),
            jac_current: false,
            need_jac: true,
            lu_real: RealLu::new(n),
            lu_complex: ComplexLu::new(n),
            lu_h: None,
            faccon: 1.0,
            theta: o.jacobian_theta,
            ctrl: Controller::default(),
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
    pub(super) fn norm(v: &[f64], scal: &[f64]) -> f64 {
        let sum: f64 = v.iter().zip(scal).map(|(a, s)| (a / s) * (a / s)).sum();
        (sum / v.len().max(1) as f64).sqrt()
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
            if err >= 1.0 {
                self.stats.rejected += 1;
                self.h = self.ctrl.rejected(h, err, newt, self.nit);
                self.reject = true;
                self.need_jac = !self.jac_current;
                failure = Failure::ErrorTest;
                retries += 1;
                continue;
            }
            // Accepted.
            let mut h_new = self.ctrl.accepted(h, err, newt, self.nit).min(self.h_max);
            self.accept(h, if landing { t_stop } else { self.t + h });
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

    /// The equations changed at the current time while the state did not jump (an input set
    /// to a new value): f(t, y) is evaluated anew before the next step, and the Jacobian no
    /// longer counts as current (a failed step renews it). The step size, the Jacobian and its
    /// LU factors are kept: Newton renews the Jacobian by itself when it converges slowly, and
    /// the error test shrinks a step that the change made too long. Cheaper than
    /// [`Self::restart`], which forgets all of them.
    pub fn equations_changed(&mut self) {
        self.f0_valid = false;
        self.jac_current = false;
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
        self.ctrl.reset();
        self.reject = false;
        Ok(())
    }
}
