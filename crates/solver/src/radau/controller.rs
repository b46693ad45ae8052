//! Step-size selection: the first step, and the proposal after each attempt from the error
//! estimate (h·err^(−1/4) with a safety factor that shrinks with the Newton iterations
//! spent), with Gustafsson's predictive controller on accepted steps (Hairer & Wanner II,
//! IV.8, eq. (8.25)).

use super::{OdeSystem, Radau5};

/// Safety factor.
const SAFE: f64 = 0.9;
/// Largest growth h_new/h.
const GROW_MAX: f64 = 8.0;
/// Largest shrink h/h_new.
const SHRINK_MAX: f64 = 5.0;

/// The controller's memory: the last accepted step and its error.
#[derive(Clone, Debug, Default)]
pub(super) struct Controller {
    h_acc: f64,
    err_acc: f64,
    accepted: usize,
}

impl Controller {
    /// Forget the history (after a discontinuity).
    pub(super) fn reset(&mut self) {
        *self = Self::default();
    }

    /// No step accepted since the start or the last reset.
    pub(super) fn first(&self) -> bool {
        self.accepted == 0
    }

    /// h/h_new from the error alone, for `newt` Newton iterations out of `nit`.
    fn quot(err: f64, newt: usize, nit: usize) -> f64 {
        let fac = SAFE.min(SAFE * (1 + 2 * nit) as f64 / (newt + 2 * nit) as f64);
        (err.powf(0.25) / fac).clamp(1.0 / GROW_MAX, SHRINK_MAX)
    }

    /// The step size to retry with after a step of size h failed the error test (err ≥ 1);
    /// a tenth of it if no step has been accepted yet.
    pub(super) fn rejected(&self, h: f64, err: f64, newt: usize, nit: usize) -> f64 {
        if self.first() {
            0.1 * h
        } else {
            h / Self::quot(err, newt, nit)
        }
    }

    /// The proposal after a step of size h was accepted with error err < 1.
    pub(super) fn accepted(&mut self, h: f64, err: f64, newt: usize, nit: usize) -> f64 {
        let mut quot = Self::quot(err, newt, nit);
        if !self.first() {
            let gus = (self.h_acc / h) * (err * err / self.err_acc).powf(0.25) / SAFE;
            quot = quot.max(gus.clamp(1.0 / GROW_MAX, SHRINK_MAX));
        }
        self.h_acc = h;
        self.err_acc = err.max(1e-2);
        self.accepted += 1;
        h / quot
    }
}

impl Radau5 {
    /// The first step size (Hairer, Nørsett & Wanner I, II.4): from ‖y₀‖, ‖f₀‖ and a
    /// difference quotient of f along an explicit Euler step, for an error ∝ h⁴.
    pub(super) fn initial_step(&mut self, sys: &mut impl OdeSystem) -> f64 {
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
}
