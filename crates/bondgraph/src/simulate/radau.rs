//! [`Radau5`] as a [`Stepper`]: the equations with their exact Jacobian, limits located by
//! bisection on the dense output.

use std::cell::RefCell;

use super::stepper::{drive, StepEnd, Stepper, Work};
use super::{culprit, Bound, Recorder, SegmentError, Settings, Statistics};
use crate::equations::StateEquations;
use crate::error::SimulationError;
use crate::radau::{OdeSystem, Radau5, RadauOptions};

/// The equations as the Radau integrator sees them: calls counted, the first non-finite
/// derivative noted for the error report.
pub(super) struct RadauEquations<'e> {
    pub(super) eqs: &'e StateEquations,
    pub(super) bad: &'e RefCell<Option<(f64, Vec<f64>)>>,
    pub(super) rhs_calls: usize,
    pub(super) jac_calls: usize,
}

impl OdeSystem for RadauEquations<'_> {
    fn n(&self) -> usize {
        self.eqs.n_states()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.rhs_calls += 1;
        self.eqs.rhs(t, y, dy);
        if self.bad.borrow().is_none() && dy.iter().any(|v| !v.is_finite()) {
            *self.bad.borrow_mut() = Some((t, y.to_vec()));
        }
    }
    fn jacobian(&mut self, t: f64, y: &[f64], _fy: &[f64], jac: &mut nalgebra::DMatrix<f64>) {
        // Exact, through the evaluation plan (StateEquations::jacobian).
        self.jac_calls += 1;
        self.eqs.jacobian(t, y, jac);
    }
    fn jacobian_pattern(&self) -> Option<crate::radau::SparsePattern> {
        self.eqs.jacobian_pattern()
    }
    fn jacobian_sparse(
        &mut self,
        t: f64,
        y: &[f64],
        _fy: &[f64],
        pattern: &crate::radau::SparsePattern,
        values: &mut [f64],
        _dense: &mut nalgebra::DMatrix<f64>,
    ) {
        // Straight into the pattern's slots (StateEquations::jacobian_sparse).
        self.jac_calls += 1;
        self.eqs.jacobian_sparse(t, y, pattern, values);
    }
}

/// [`Radau5`] as a [`Stepper`]: limits are located inside each step by bisection on the
/// dense output.
pub(super) struct RadauStepper<'e> {
    pub(super) radau: Radau5,
    pub(super) sys: RadauEquations<'e>,
    pub(super) t_stop: f64,
    pub(super) limits: &'e [Bound],
}

impl RadauStepper<'_> {
    /// The earliest crossing of a limit inside the last step, if any.
    fn crossing(&self) -> Option<(f64, usize)> {
        if self.limits.iter().all(|b| b.margin(self.radau.y()) >= 0.0) {
            return None;
        }
        let (t0, t1) = (self.radau.t_prev(), self.radau.t());
        let mut y = vec![0.0; self.radau.y().len()];
        let mut first: Option<(f64, usize)> = None;
        for (k, b) in self.limits.iter().enumerate() {
            if b.margin(self.radau.y()) >= 0.0 {
                continue;
            }
            // margin ≥ 0 at t0, < 0 at t1: bisect to round-off.
            let (mut a, mut c) = (t0, t1);
            for _ in 0..80 {
                let m = 0.5 * (a + c);
                if m <= a || m >= c {
                    break;
                }
                if self.radau.interpolate(m, &mut y).is_err() {
                    break;
                }
                if b.margin(&y) >= 0.0 {
                    a = m;
                } else {
                    c = m;
                }
            }
            if first.is_none_or(|(tf, _)| c < tf) {
                first = Some((c, k));
            }
        }
        first
    }
}

impl Stepper for RadauStepper<'_> {
    fn set_stop_time(&mut self, t_stop: f64) -> Result<(), String> {
        self.t_stop = t_stop;
        Ok(())
    }
    fn step(&mut self) -> Result<StepEnd, String> {
        let report = self
            .radau
            .step(&mut self.sys, self.t_stop)
            .map_err(|e| e.to_string())?;
        if let Some((t, k)) = self.crossing() {
            return Ok(StepEnd::Root(t, k));
        }
        Ok(if report.reached_stop {
            StepEnd::StopReached
        } else {
            StepEnd::Internal
        })
    }
    fn t_h(&self) -> (f64, f64) {
        (self.radau.t(), self.radau.h())
    }
    fn y_into(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(self.radau.y());
    }
    fn interpolate(&self, t: f64) -> Result<Vec<f64>, String> {
        let mut y = vec![0.0; self.radau.y().len()];
        self.radau
            .interpolate(t, &mut y)
            .map_err(|e| e.to_string())?;
        Ok(y)
    }
    fn interpolate_into(&self, t: f64, out: &mut [f64]) -> Result<(), String> {
        self.radau.interpolate(t, out).map_err(|e| e.to_string())
    }
    fn work(&self) -> Work {
        let s = self.radau.stats();
        Work {
            steps: s.steps,
            error_test_failures: s.rejected,
            newton_iterations: s.newton_iterations,
            newton_failures: s.newton_failures,
            lu: s.lu_decompositions,
        }
    }
}

/// Newton convergence rate above which Radau5 evaluates a new Jacobian for the next step.
/// RADAU5's 0.001 renews it almost every step on the crane; at 0.03 the Jacobians fall by
/// 2.2× for 2 % more steps (docs/performance.md).
pub(super) const RADAU_JACOBIAN_THETA: f64 = 0.03;

#[allow(clippy::too_many_arguments)]
pub(super) fn run_radau(
    rec: &mut Recorder<'_>,
    settings: &Settings,
    t: f64,
    t_stop: f64,
    x: &[f64],
    atol: &[f64],
    limits: Vec<Bound>,
    bad: &RefCell<Option<(f64, Vec<f64>)>>,
    stats: &mut Statistics,
) -> Result<Vec<f64>, SegmentError> {
    let mut sys = RadauEquations {
        eqs: rec.eqs,
        bad,
        rhs_calls: 0,
        jac_calls: 0,
    };
    let options = RadauOptions {
        rtol: settings.rtol,
        atol: atol.to_vec(),
        jacobian_theta: RADAU_JACOBIAN_THETA,
        linear_algebra: settings.linear_algebra,
        ..RadauOptions::default()
    };
    let radau = match Radau5::new(&mut sys, t, x, options) {
        Ok(r) => r,
        Err(e) => {
            stats.rhs_evals += sys.rhs_calls;
            let culprit = culprit(rec.eqs, bad);
            return Err((
                t,
                x.to_vec(),
                SimulationError::Solver {
                    t,
                    message: e.to_string(),
                    culprit,
                    hint: None,
                },
            ));
        }
    };
    let mut stepper = RadauStepper {
        radau,
        sys,
        t_stop,
        limits: &limits,
    };
    let result = drive(&mut stepper, rec, t_stop, settings, &limits, bad, stats);
    stats.rhs_evals += stepper.sys.rhs_calls;
    stats.jac_evals += stepper.sys.jac_calls;
    stats.jac_assemblies += stepper.sys.jac_calls;
    result
}
