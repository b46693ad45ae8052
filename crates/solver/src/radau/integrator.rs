//! The integrator's life cycle: set-up, one accepted step (with its retries), dense output
//! and restarts.

use super::{
    Controller, Failure, Linear, OdeSystem, Radau5, RadauError, RadauOptions, RadauStats,
    StepReport, Tableau, KEEP_H, MAX_SINGULAR,
};

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
            lin: Linear::new(sys, n, o.linear_algebra),
            jac_current: false,
            need_jac: true,
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
    /// Whether the sparse linear algebra is in use (see [`RadauOptions::linear_algebra`]).
    #[must_use]
    pub fn is_sparse(&self) -> bool {
        self.lin.is_sparse()
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
                self.lin.jacobian(sys, self.t, &self.y, &self.f0);
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
