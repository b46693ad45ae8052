//! [`Simulation`]: a run advanced by the caller, call by call, with the solver's state kept
//! in between — for a controller written outside the model (Python, a test bench) that reads
//! the model, sets its inputs and lets it run on for one sample.
//!
//! The method is our Radau IIA ([`crate::radau`]). Between calls it keeps everything a run
//! keeps between steps: the step size the controller proposed, the Jacobian and its LU
//! factors, the collocation polynomial (the next Newton's starting values). A call ends
//! exactly on its target time (the last step is shortened to land there, which does not
//! shrink the step size proposed for the next call), so advancing in many short calls costs
//! what one run costs plus, per call, one short landing step and the LU factorisations of
//! its step size and of the next (at most two per call; an LU of the crane's 38 states costs
//! about as much as a right-hand side) — no Jacobian per call.
//!
//! What changes the equations at the current time without a jump of the state — an input
//! set to a new value ([`Simulation::set_input`]), a corner of an input's series (a stop, as
//! in a run) — costs one right-hand side: the
//! integrator evaluates f(t, y) anew and keeps its step size, Jacobian and LU (Newton renews
//! the Jacobian itself when it converges slowly; the error test shrinks a step the change
//! made too long). A scheduled [`Event`] (elements replaced) and [`Simulation::restart`] make
//! a full restart: Jacobian, LU and step-size history are forgotten.
//!
//! Limits, non-finite states, `max_steps` and `Settings::interrupt` stop a call as they
//! stop a run (the same loop, `stepper::drive`); after an error the simulation refuses to go
//! on.

use std::cell::RefCell;

use super::radau::{RadauEquations, RadauStepper, RADAU_JACOBIAN_THETA};
use super::stepper::drive;
use super::{
    bounds, same_time, Bound, Event, Grid, Progress, Reads, Recorder, Settings, Statistics,
};
use crate::equations::{Probe, StateEquations, Subset};
use crate::error::SimulationError;
use crate::radau::{Radau5, RadauOptions};

/// A run advanced call by call ([`Simulation::advance_to`]); see the module doc.
#[derive(Debug)]
pub struct Simulation {
    eqs: StateEquations,
    /// `None` only for a model without states (nothing to integrate).
    radau: Option<Radau5>,
    /// The time of a model without states.
    t: f64,
    limits: Vec<Bound>,
    /// Scheduled events not yet applied, latest first.
    events: Vec<Event>,
    settings: Settings,
    rhs_calls: usize,
    jac_calls: usize,
    events_applied: usize,
    /// Wall time spent in `advance_to`.
    wall: std::time::Duration,
    /// Why the simulation cannot go on, once it failed.
    failed: Option<SimulationError>,
    /// The stages each probe read so far needs ([`Simulation::read`]), found at its first read.
    reads: RefCell<Vec<(Probe, Subset)>>,
}

impl Simulation {
    /// Start at (`t0`, `x0`) with the tolerances and `max_steps` of `settings` (its times and
    /// method are not used: the method is Radau IIA). `events` are applied at their times;
    /// those at or before `t0` at once.
    ///
    /// # Errors
    /// A state count or value that does not fit, a limit already crossed, bad tolerances, or
    /// equations that are not finite at the start.
    pub fn start(
        mut eqs: StateEquations,
        t0: f64,
        x0: &[f64],
        settings: &Settings,
        mut events: Vec<Event>,
    ) -> Result<Self, SimulationError> {
        let bad_setting = |setting, message: String| SimulationError::InvalidSetting {
            setting,
            message,
            hint: None,
        };
        if !t0.is_finite() {
            return Err(bad_setting("t0", format!("must be finite, got {t0}")));
        }
        if !(settings.rtol.is_finite() && (super::MIN_RTOL..1.0).contains(&settings.rtol)) {
            return Err(bad_setting(
                "rtol",
                format!(
                    "must be in [{:e}, 1), got {}",
                    super::MIN_RTOL,
                    settings.rtol
                ),
            ));
        }
        if !(settings.atol.is_finite() && settings.atol > 0.0) {
            return Err(bad_setting(
                "atol",
                format!("must be finite and > 0, got {}", settings.atol),
            ));
        }
        if x0.len() != eqs.n_states() {
            return Err(SimulationError::InitialState {
                given: x0.len(),
                expected: eqs.n_states(),
            });
        }
        if let Some((i, v)) = x0.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let s = &eqs.states()[i];
            return Err(SimulationError::NonFinite {
                t: t0,
                state: s.name.clone(),
                element: eqs.graph().node(s.element).name.clone(),
                value: *v,
                culprit: " (initial value)".into(),
            });
        }
        let limits = bounds(&eqs);
        if let Some(b) = limits.iter().find(|b| b.margin(x0) < 0.0) {
            return Err(b.error(t0));
        }
        events.sort_by(|a, b| b.t.total_cmp(&a.t));
        let mut applied = 0;
        while events
            .last()
            .is_some_and(|e| e.t <= t0 || same_time(e.t, t0))
        {
            if let Some(ev) = events.pop() {
                apply(&mut eqs, ev)?;
                applied += 1;
            }
        }
        let radau = if x0.is_empty() {
            None
        } else {
            let atol: Vec<f64> = eqs
                .states()
                .iter()
                .map(|s| settings.atol * s.nominal)
                .collect();
            let options = RadauOptions {
                rtol: settings.rtol,
                atol,
                jacobian_theta: RADAU_JACOBIAN_THETA,
                ..RadauOptions::default()
            };
            let bad = RefCell::new(None);
            let mut sys = RadauEquations {
                eqs: &eqs,
                bad: &bad,
                rhs_calls: 0,
                jac_calls: 0,
            };
            let r =
                Radau5::new(&mut sys, t0, x0, options).map_err(|e| SimulationError::Solver {
                    t: t0,
                    message: e.to_string(),
                    culprit: super::culprit(&eqs, &bad),
                    hint: None,
                })?;
            Some(r)
        };
        Ok(Self {
            eqs,
            radau,
            t: t0,
            limits,
            events,
            settings: settings.clone(),
            rhs_calls: 1,
            jac_calls: 0,
            events_applied: applied,
            wall: std::time::Duration::ZERO,
            failed: None,
            reads: RefCell::new(Vec::new()),
        })
    }

    /// The current time.
    #[must_use]
    pub fn t(&self) -> f64 {
        self.radau.as_ref().map_or(self.t, Radau5::t)
    }

    /// The current state, in the order of [`StateEquations::states`].
    #[must_use]
    pub fn state(&self) -> &[f64] {
        self.radau.as_ref().map_or(&[], Radau5::y)
    }

    /// The equations (names, probes).
    #[must_use]
    pub fn equations(&self) -> &StateEquations {
        &self.eqs
    }

    /// The equations, to change them at the current time (an input's value). Call
    /// [`Self::equations_changed`] afterwards if f changed.
    pub fn equations_mut(&mut self) -> &mut StateEquations {
        &mut self.eqs
    }

    /// Give the equations back.
    #[must_use]
    pub fn into_equations(self) -> StateEquations {
        self.eqs
    }

    /// The equations changed at the current time, the state did not jump: one right-hand side
    /// before the next step, nothing forgotten (see the module doc).
    pub fn equations_changed(&mut self) {
        if let Some(r) = self.radau.as_mut() {
            r.equations_changed();
        }
    }

    /// Hold input `i` at `value` from now on. A new value changes f at the current time:
    /// the integrator re-evaluates it before the next step and keeps its step size,
    /// Jacobian and LU ([`Self::equations_changed`]); the same value changes nothing.
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`](crate::GraphError::UnknownInput) for an index out of range.
    pub fn set_input(&mut self, i: usize, value: f64) -> Result<(), crate::GraphError> {
        let t = self.t();
        let same = self.eqs.input_series(i)?.is_none()
            && self.eqs.input_value(i, t)?.to_bits() == value.to_bits();
        if !same {
            self.eqs.set_input(i, value)?;
            self.equations_changed();
        }
        Ok(())
    }

    /// Make input `i` follow `series` from now on (its corners become stops, as in a run).
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`](crate::GraphError::UnknownInput) for an index out of range.
    pub fn set_input_series(
        &mut self,
        i: usize,
        series: crate::elements::Series,
    ) -> Result<(), crate::GraphError> {
        self.eqs.set_input_series(i, series)?;
        self.equations_changed();
        Ok(())
    }

    /// Restart the integrator at the current time, optionally from a new state: the
    /// Jacobian, its LU and the step-size history are forgotten.
    ///
    /// # Errors
    /// A state of the wrong length or not finite.
    pub fn restart(&mut self, x: Option<&[f64]>) -> Result<(), SimulationError> {
        let t = self.t();
        if let Some(r) = self.radau.as_mut() {
            r.restart(x).map_err(|e| SimulationError::Solver {
                t,
                message: e.to_string(),
                culprit: String::new(),
                hint: None,
            })?;
        }
        Ok(())
    }

    /// The value of `probe` at the current time and state: only the stages it needs are
    /// evaluated (found at its first read, then kept: later reads allocate nothing).
    #[must_use]
    pub fn read(&self, probe: Probe) -> f64 {
        let (t, x) = (self.t(), self.state());
        if let Probe::State(i) = probe {
            return x[i];
        }
        let mut reads = self.reads.borrow_mut();
        let k = reads
            .iter()
            .position(|(p, _)| *p == probe)
            .unwrap_or_else(|| {
                reads.push((probe, self.eqs.subset(&[probe])));
                reads.len() - 1
            });
        self.eqs.evaluate_only(&reads[k].1, t, x);
        self.eqs.read(probe, t, x)
    }

    /// Solver work since the start, summed over every call.
    #[must_use]
    pub fn stats(&self) -> Statistics {
        let mut s = Statistics {
            rhs_evals: self.rhs_calls,
            jac_evals: self.jac_calls,
            jac_assemblies: self.jac_calls,
            events: self.events_applied,
            wall_time: self.wall,
            ..Statistics::default()
        };
        if let Some(r) = &self.radau {
            let w = r.stats();
            s.steps = w.steps;
            s.error_test_failures = w.rejected;
            s.newton_iterations = w.newton_iterations;
            s.newton_failures = w.newton_failures;
            s.lu_factorisations = w.lu_decompositions;
        }
        s
    }

    /// Advance by `dt` (> 0).
    ///
    /// # Errors
    /// As [`Self::advance_to`].
    pub fn advance(&mut self, dt: f64) -> Result<(), SimulationError> {
        self.advance_to(self.t() + dt)
    }

    /// Integrate on to `t_target`, landing on it exactly, applying the events due on the way.
    /// A target equal to the current time does nothing.
    ///
    /// # Errors
    /// A target behind the current time; the solver failing, a state not finite, a limit
    /// reached, `max_steps` or an interruption (the state is then where it stopped, and every
    /// later call returns the same error).
    pub fn advance_to(&mut self, t_target: f64) -> Result<(), SimulationError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        let t_now = self.t();
        if !t_target.is_finite() || t_target < t_now {
            return Err(SimulationError::InvalidSetting {
                setting: "t",
                message: format!(
                    "cannot advance to t = {t_target}: the simulation is at t = {t_now} and only goes forward"
                ),
                hint: None,
            });
        }
        let start = std::time::Instant::now();
        let result = self.advance_inner(t_target);
        self.wall += start.elapsed();
        if let Err(e) = &result {
            self.failed = Some(e.clone());
        }
        result
    }

    fn advance_inner(&mut self, t_target: f64) -> Result<(), SimulationError> {
        loop {
            let t = self.t();
            if same_time(t, t_target) || t >= t_target {
                // what is read here sees the inputs as a run's row at t does: a series on
                // the piece holding t (at a sample of a held series, the value from t on)
                self.eqs.begin_segment(t);
                return Ok(());
            }
            let next_event = self.events.last().map(|e| e.t);
            let t_stop = next_event.map_or(t_target, |te| te.min(t_target));
            // An input series' corner is a stop too: the series is evaluated on one piece
            // up to it, and f changes there as it does when an input is set.
            let corner = self.eqs.next_breakpoint(t).filter(|&b| b < t_stop);
            let t_stop = corner.unwrap_or(t_stop);
            self.eqs.begin_segment(t);
            if !same_time(t, t_stop) {
                self.integrate(t_stop)?;
            }
            if corner.is_some() {
                self.equations_changed();
            }
            if next_event.is_some_and(|te| same_time(te, t_stop) || te <= t_stop) {
                while self
                    .events
                    .last()
                    .is_some_and(|e| same_time(e.t, t_stop) || e.t <= t_stop)
                {
                    if let Some(ev) = self.events.pop() {
                        apply(&mut self.eqs, ev)?;
                        self.events_applied += 1;
                    }
                }
                self.restart(None)?;
            }
            if self.radau.is_none() {
                self.t = t_stop;
            }
        }
    }

    /// Step the integrator onto `t_stop` through the run's loop (`drive`).
    fn integrate(&mut self, t_stop: f64) -> Result<(), SimulationError> {
        let Some(radau) = self.radau.take() else {
            return Ok(());
        };
        let bad = RefCell::new(None);
        let mut none: Vec<Vec<f64>> = Vec::new();
        let mut rec = Recorder {
            eqs: &self.eqs,
            outputs: &[],
            // An empty grid: no rows (`pending` is always `None`).
            grid: Grid {
                t0: t_stop,
                dt: 1.0,
                n: 0,
                t_end: t_stop,
                end_extra: false,
            },
            sink: &mut none,
            interrupt: self.settings.interrupt.as_deref(),
            wants_steps: false,
            event_at: None,
            buf: Vec::new(),
            reads: &Reads::default(),
            p: Progress {
                watchers: Vec::new(),
                next: 1,
                rows: 0,
                stop: None,
            },
            audit: None,
        };
        let mut stepper = RadauStepper {
            radau,
            sys: RadauEquations {
                eqs: &self.eqs,
                bad: &bad,
                rhs_calls: 0,
                jac_calls: 0,
            },
            t_stop,
            limits: &self.limits,
        };
        // Steps are counted by the integrator over its life; `drive` only needs them for
        // `max_steps`.
        let mut scratch = Statistics::default();
        let result = drive(
            &mut stepper,
            &mut rec,
            t_stop,
            &self.settings,
            &self.limits,
            &bad,
            &mut scratch,
        );
        self.rhs_calls += stepper.sys.rhs_calls;
        self.jac_calls += stepper.sys.jac_calls;
        self.radau = Some(stepper.radau);
        result.map(|_| ()).map_err(|(_, _, e)| e)
    }
}

/// Apply one event's replacements, all or nothing.
fn apply(eqs: &mut StateEquations, ev: Event) -> Result<(), SimulationError> {
    if let Some(source) = ev
        .replacements
        .iter()
        .find_map(|(id, el)| eqs.check_replacement(*id, el.as_ref()).err())
    {
        return Err(SimulationError::Event { t: ev.t, source });
    }
    for (id, el) in ev.replacements {
        eqs.replace(id, el)
            .map_err(|source| SimulationError::Event { t: ev.t, source })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests;
