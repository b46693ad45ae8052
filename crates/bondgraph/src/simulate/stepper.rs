//! The interface every integration method sits behind ([`Stepper`]), diffsol's solvers as
//! steppers, and the one loop that drives any of them through a segment ([`drive`]).

use std::cell::RefCell;

use diffsol::{OdeEquations, OdeSolverMethod, OdeSolverStopReason};

use super::{culprit, same_time, Bound, Recorder, SegmentError, Statistics};
use crate::equations::StateEquations;
use crate::error::SimulationError;

/// How a step ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum StepEnd {
    /// An ordinary accepted step.
    Internal,
    /// The step landed on the stop time.
    StopReached,
    /// A limit's root function crossed zero at this time inside the step (index of the limit).
    Root(f64, usize),
}

/// Work counters of one method instance (they start at zero for each segment).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Work {
    pub(super) steps: usize,
    pub(super) error_test_failures: usize,
    pub(super) newton_iterations: usize,
    pub(super) newton_failures: usize,
    pub(super) lu: usize,
}

/// What the run loop needs of an integration method: one accepted step at a time, its state,
/// dense output inside the last step, and its work. Every method sits behind it, so events,
/// limits, output rows, NaN checks and partial results work alike for each.
pub(super) trait Stepper {
    /// Set the segment's end: steps land on it exactly.
    fn set_stop_time(&mut self, t_stop: f64) -> Result<(), String>;
    /// Take one accepted step (never past the segment's stop time).
    fn step(&mut self) -> Result<StepEnd, String>;
    /// Current time and step size.
    fn t_h(&self) -> (f64, f64);
    /// Current state, into `out` (resized to it).
    fn y_into(&self, out: &mut Vec<f64>);
    /// The state at `t` inside the last step.
    fn interpolate(&self, t: f64) -> Result<Vec<f64>, String>;
    /// [`Stepper::interpolate`] into `out` (the energy audit's nodes; Radau without
    /// allocating).
    fn interpolate_into(&self, t: f64, out: &mut [f64]) -> Result<(), String> {
        out.copy_from_slice(&self.interpolate(t)?);
        Ok(())
    }
    /// Work so far.
    fn work(&self) -> Work;
}

/// A diffsol solver as a [`Stepper`].
pub(super) struct Diffsol<S, Eqn>(S, std::marker::PhantomData<Eqn>);

impl<S, Eqn> Diffsol<S, Eqn> {
    pub(super) fn new(s: S) -> Self {
        Self(s, std::marker::PhantomData)
    }
}

impl<'a, Eqn, S> Stepper for Diffsol<S, Eqn>
where
    Eqn: OdeEquations<T = f64, V = diffsol::NalgebraVec<f64>> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    fn set_stop_time(&mut self, t_stop: f64) -> Result<(), String> {
        self.0.set_stop_time(t_stop).map_err(|e| e.to_string())
    }
    fn step(&mut self) -> Result<StepEnd, String> {
        match self.0.step() {
            Ok(OdeSolverStopReason::InternalTimestep) => Ok(StepEnd::Internal),
            Ok(OdeSolverStopReason::TstopReached) => Ok(StepEnd::StopReached),
            Ok(OdeSolverStopReason::RootFound(t, i)) => Ok(StepEnd::Root(t, i)),
            Err(e) => Err(e.to_string()),
        }
    }
    fn t_h(&self) -> (f64, f64) {
        let st = self.0.state();
        (st.t, st.h)
    }
    fn y_into(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(self.0.state().y.batch_as_slice(0));
    }
    fn interpolate(&self, t: f64) -> Result<Vec<f64>, String> {
        self.0
            .interpolate(t)
            .map(|y| y.batch_as_slice(0).to_vec())
            .map_err(|e| e.to_string())
    }
    fn work(&self) -> Work {
        let st = self.0.get_statistics();
        Work {
            steps: st.number_of_steps,
            error_test_failures: st.number_of_error_test_failures,
            newton_iterations: st.number_of_nonlinear_solver_iterations,
            newton_failures: st.number_of_nonlinear_solver_fails,
            lu: st.number_of_linear_solver_setups,
        }
    }
}

/// Step `s` to `t_stop`, recording the output rows, watching the states, and stopping at a
/// non-finite state, a limit, a stalled step size or `max_steps`.
pub(super) fn drive(
    s: &mut dyn Stepper,
    rec: &mut Recorder<'_>,
    t_stop: f64,
    settings: &super::Settings,
    limits: &[Bound],
    bad: &RefCell<Option<(f64, Vec<f64>)>>,
    stats: &mut Statistics,
) -> Result<Vec<f64>, SegmentError> {
    let eqs = rec.eqs;
    let max_steps = settings.max_steps;
    let finish = |s: &dyn Stepper, stats: &mut Statistics| {
        let w = s.work();
        stats.steps += w.steps;
        stats.error_test_failures += w.error_test_failures;
        stats.newton_iterations += w.newton_iterations;
        stats.newton_failures += w.newton_failures;
        stats.lu_factorisations += w.lu;
    };
    let mut t_prev = s.t_h().0;
    // The state after each step and at each row, in buffers kept over the segment.
    let (mut x, mut xi) = (Vec::new(), Vec::new());
    loop {
        let step = s.step();
        let (t, h) = s.t_h();
        s.y_into(&mut x);
        let reason = match step {
            Err(e) => {
                finish(s, stats);
                return Err((t, x, solver_error(t, e, culprit(eqs, bad))));
            }
            Ok(r) => r,
        };
        let stalled = !t.is_finite() || !h.is_finite() || h.abs() < 1e-14 * t.abs().max(1.0);
        let too_many = s.work().steps + stats.steps >= max_steps;
        if stalled || too_many {
            finish(s, stats);
            let (message, hint) = if stalled {
                (
                    format!(
                        "the step size collapsed to {h:e}{}",
                        fastest(eqs, t, &x, settings)
                    ),
                    Some("the state named changes fastest for its tolerance: look at what drives it (a stiff or singular term, a value that blows up, an event the model needs)"),
                )
            } else {
                (
                    format!("more than {max_steps} steps"),
                    Some("the model may be much stiffer than the method (try radau5 or bdf) or max_steps too small"),
                )
            };
            let culprit = culprit(eqs, bad);
            return Err((
                t,
                x,
                SimulationError::Solver {
                    t,
                    message,
                    culprit,
                    hint,
                },
            ));
        }
        // The run observes an interruption (`Settings::interrupt`) and a refused row here, in
        // one place, after every accepted step.
        let end = match rec.accepted(t, &x) {
            Err(e) => Some(Err((t, x.clone(), e))),
            Ok(()) => after_step(
                s,
                rec,
                (t_prev, t),
                &x,
                &mut xi,
                reason,
                t_stop,
                limits,
                bad,
            ),
        };
        // The outputs at the step itself (checks), after the rows up to it: in time order,
        // and the elements' values cached at x serve the next step's f(t, x).
        rec.step_done(t, &x);
        if let Some(end) = end {
            finish(s, stats);
            return end;
        }
        t_prev = t;
    }
}

/// The state with the largest weighted rate |dx/dt|/(atol + rtol·|x|) at (t, x) — the one
/// whose local error bounds the step where the step size collapses — as "; fastest state
/// `name` (x = …, dx/dt = …)"; empty if the rates are not finite. Evaluated once, at the
/// failure.
fn fastest(eqs: &StateEquations, t: f64, x: &[f64], s: &super::Settings) -> String {
    if x.is_empty() || x.iter().any(|v| !v.is_finite()) {
        return String::new();
    }
    let mut dx = vec![0.0; x.len()];
    eqs.rhs(t, x, &mut dx);
    let weighted = |k: usize| dx[k].abs() / (s.atol + s.rtol * x[k].abs());
    let Some(k) = (0..x.len())
        .filter(|&k| weighted(k).is_finite())
        .max_by(|&a, &b| weighted(a).total_cmp(&weighted(b)))
    else {
        return String::new();
    };
    let name = eqs.states().get(k).map_or("?", |s| s.name.as_str());
    format!(
        "; fastest state for its tolerance: `{name}` (x = {:e}, dx/dt = {:e})",
        x[k], dx[k]
    )
}

fn solver_error(t: f64, message: String, culprit: String) -> SimulationError {
    SimulationError::Solver {
        t,
        message,
        culprit,
        hint: None,
    }
}

/// After an accepted step [t0, t] to state `x`: the finite-state check, the energy audit, the
/// rows up to t (or up to a limit's crossing inside the step) and the segment's end. `None`:
/// go on stepping.
#[allow(clippy::too_many_arguments)]
fn after_step(
    s: &dyn Stepper,
    rec: &mut Recorder<'_>,
    (t0, t): (f64, f64),
    x: &[f64],
    xi: &mut Vec<f64>,
    reason: StepEnd,
    t_stop: f64,
    limits: &[Bound],
    bad: &RefCell<Option<(f64, Vec<f64>)>>,
) -> Option<Result<Vec<f64>, SegmentError>> {
    let eqs = rec.eqs;
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        let info = &eqs.states()[i];
        let err = SimulationError::NonFinite {
            t,
            state: info.name.clone(),
            element: eqs.graph().node(info.element).name.clone(),
            value: x[i],
            culprit: culprit(eqs, bad),
        };
        return Some(Err((t, x.to_vec(), err)));
    }
    // A limit reached inside the step: rows up to the crossing, then stop there.
    let root = match reason {
        StepEnd::Root(tr, idx) => Some((tr, idx)),
        _ => None,
    };
    let t_rows = root.map_or(t, |(tr, _)| tr);
    // The energy audit: the power at the step's quadrature nodes (`crate::energy`).
    if let Some(audit) = rec.audit.as_deref_mut() {
        let audited = if root.is_some() {
            let mut xr = x.to_vec();
            s.interpolate_into(t_rows, &mut xr)
                .and_then(|()| audit.step(eqs, t0, t_rows, &xr, |tq, y| s.interpolate_into(tq, y)))
        } else {
            audit.step(eqs, t0, t, x, |tq, y| s.interpolate_into(tq, y))
        };
        if let Err(e) = audited {
            let message = format!("energy audit at t = {t}: {e}");
            return Some(Err((
                t,
                x.to_vec(),
                solver_error(t, message, String::new()),
            )));
        }
    }
    while let Some(tg) = rec.pending() {
        if tg > t_rows
            || same_time(tg, t_stop)
            || tg > t_stop
            || (root.is_some() && same_time(tg, t_rows))
        {
            break;
        }
        if same_time(tg, t) {
            rec.record(tg, x);
        } else {
            xi.resize(x.len(), 0.0);
            if let Err(e) = s.interpolate_into(tg, xi) {
                let message = format!("interpolation at t = {tg}: {e}");
                return Some(Err((
                    t,
                    x.to_vec(),
                    solver_error(t, message, String::new()),
                )));
            }
            rec.record(tg, xi);
        }
    }
    if let Some((tr, idx)) = root {
        let xr = s.interpolate(tr).unwrap_or_else(|_| x.to_vec());
        let err = limits.get(idx).map_or_else(
            || {
                let message = format!("root {idx} found, but no limit has that index");
                solver_error(tr, message, String::new())
            },
            |b| b.error(tr),
        );
        return Some(Err((tr, xr, err)));
    }
    (reason == StepEnd::StopReached).then(|| Ok(x.to_vec()))
}
