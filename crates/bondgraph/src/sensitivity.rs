//! Forward parameter sensitivities of a run: s = ∂x/∂p integrated beside the state by
//! Radau's staggered direct method ([`crate::radau::Sensitivities`]), and the sensitivities
//! of the output columns, dy/dp = ∂y/∂x·s + ∂y/∂p.
//!
//! What the sensitivity equations ṡ = J s + ∂f/∂p need at each stage point of each step:
//! * J = ∂f/∂x exactly, from [`StateEquations::jacobian`] (the forward-mode pass of the
//!   plan), at every stage point;
//! * ∂f/∂p_k from a twin of the equations built with p_k + h_k ([`Perturbation`]): a
//!   parameter is a number baked into elements by their builders (a bulk modulus into a
//!   chamber, a payload mass into the arm's mass matrix), so it has no seed in the plan;
//!   the twin's right-hand side at the same (t, x) differences it, one-sided, with
//!   h_k = 2⁻²⁶·max(|p_k|, 10⁻³) (relative error about 10⁻⁸).
//!
//! Output sensitivities are the directional difference of the twin's outputs,
//! (y(t, x + h_k s_k; p + h_k) − y(t, x; p))/h_k, which carries both ∂y/∂x·s and ∂y/∂p.
//! Events (parameter switches) are applied to every twin at the same time, each with its
//! own values; the state and its sensitivities are continuous across them.
//!
//! The run here is Radau alone, without limits or watched minima (a sensitivity run is a
//! study of a run that works; `simulate` reports those).

use nalgebra::DMatrix;

use crate::equations::{StateEquations, Subset};
use crate::error::SimulationError;
use crate::radau::{OdeSystem, Radau5, RadauOptions, Sensitivities, SensitivityRhs};
use crate::simulate::{Event, Output, Settings};

/// The Jacobian renewal threshold of the ordinary Radau run (`simulate`), kept equal so the
/// state's steps are those of `bg-sim run`.
const JACOBIAN_THETA: f64 = 0.03;

/// The step of a one-sided difference in a parameter of value `p`, exact in binary.
#[must_use]
pub fn param_step(p: f64) -> f64 {
    let h = 1.490_116_119_384_765_6e-8 * p.abs().max(1e-3);
    (p + h) - p
}

/// One parameter's twin: the equations built with the parameter at `p + h`.
pub struct Perturbation {
    /// The twin's equations.
    pub eqs: StateEquations,
    /// The step h (the twin's value minus the model's, exactly).
    pub h: f64,
    /// The twin's events, at the model's event times.
    pub events: Vec<Event>,
    /// The parameter does not enter f (an initial state): ∂f/∂p = 0, no twin evaluation.
    pub rhs_free: bool,
}

/// The rows of a sensitivity run.
#[derive(Clone, Debug, Default)]
pub struct SensitivityRun {
    /// Output times.
    pub t: Vec<f64>,
    /// Outputs, row-major (`y[row·m + j]`).
    pub y: Vec<f64>,
    /// dy/dp, row-major (`dy_dp[(row·m + j)·np + k]`).
    pub dy_dp: Vec<f64>,
    /// Accepted steps.
    pub steps: usize,
    /// Iterations of the sensitivity stage solves (all parameters).
    pub stage_iterations: usize,
    /// Exact Jacobians evaluated for the sensitivities (three per step).
    pub jacobians: usize,
}

/// The equations as the integrator sees them.
struct Ode<'e> {
    eqs: &'e StateEquations,
}

impl OdeSystem for Ode<'_> {
    fn n(&self) -> usize {
        self.eqs.n_states()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.eqs.rhs(t, y, dy);
    }
    fn jacobian(&mut self, t: f64, y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
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
        _dense: &mut DMatrix<f64>,
    ) {
        self.eqs.jacobian_sparse(t, y, pattern, values);
    }
}

/// J and ∂f/∂p at the three stage points of a step.
struct StageTerms<'e> {
    eqs: &'e StateEquations,
    twins: &'e [Perturbation],
    n: usize,
    jac: [DMatrix<f64>; 3],
    /// ∂f/∂p at each stage, n × np column by column.
    dfdp: [Vec<f64>; 3],
    f: Vec<f64>,
    fp: Vec<f64>,
    jacobians: usize,
}

impl SensitivityRhs for StageTerms<'_> {
    fn n_params(&self) -> usize {
        self.twins.len()
    }
    fn prepare(&mut self, stage: usize, t: f64, y: &[f64]) {
        let n = self.n;
        self.eqs.jacobian(t, y, &mut self.jac[stage]);
        self.jacobians += 1;
        if self.twins.iter().all(|w| w.rhs_free) {
            self.dfdp[stage].fill(0.0);
            return;
        }
        self.eqs.rhs(t, y, &mut self.f);
        for (k, w) in self.twins.iter().enumerate() {
            let col = &mut self.dfdp[stage][k * n..(k + 1) * n];
            if w.rhs_free {
                col.fill(0.0);
                continue;
            }
            w.eqs.rhs(t, y, &mut self.fp);
            for ((c, fp), f) in col.iter_mut().zip(&self.fp).zip(&self.f) {
                *c = (fp - f) / w.h;
            }
        }
    }
    fn end_jacobian(&self) -> Option<&DMatrix<f64>> {
        Some(&self.jac[2])
    }
    fn apply(&mut self, stage: usize, k: usize, s: &[f64], out: &mut [f64]) {
        let n = self.n;
        out.copy_from_slice(&self.dfdp[stage][k * n..(k + 1) * n]);
        let jac = self.jac[stage].as_slice();
        for (c, &sc) in s.iter().enumerate() {
            if sc == 0.0 {
                continue;
            }
            for (o, j) in out.iter_mut().zip(&jac[c * n..(c + 1) * n]) {
                *o += j * sc;
            }
        }
    }
}

/// Reads the output columns and their sensitivities at (t, x, s).
struct Rows<'e> {
    eqs: &'e StateEquations,
    twins: &'e [Perturbation],
    outputs: &'e [Output],
    /// The stages the outputs need, in the model and in each twin.
    subsets: &'e [Subset],
    xs: Vec<f64>,
    run: SensitivityRun,
}

impl Rows<'_> {
    fn record(&mut self, t: f64, x: &[f64], s: &[f64]) {
        let (n, np, m) = (x.len(), self.twins.len(), self.outputs.len());
        self.run.t.push(t);
        self.eqs.evaluate_only(&self.subsets[0], t, x);
        let base = self.run.y.len();
        for o in self.outputs {
            self.run.y.push(self.eqs.read(o.probe, t, x));
        }
        let d0 = self.run.dy_dp.len();
        self.run.dy_dp.resize(d0 + m * np, 0.0);
        for (k, w) in self.twins.iter().enumerate() {
            for i in 0..n {
                self.xs[i] = x[i] + w.h * s[k * n + i];
            }
            w.eqs.evaluate_only(&self.subsets[k + 1], t, &self.xs);
            for (j, o) in self.outputs.iter().enumerate() {
                let yp = w.eqs.read(o.probe, t, &self.xs);
                self.run.dy_dp[d0 + j * np + k] = (yp - self.run.y[base + j]) / w.h;
            }
        }
    }
}

fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-10 * (1.0 + a.abs().max(b.abs()))
}

fn solver_error(t: f64, e: impl std::fmt::Display) -> SimulationError {
    SimulationError::Solver {
        t,
        message: e.to_string(),
        culprit: String::new(),
        hint: None,
    }
}

/// Apply an event's replacements to `eqs`, all or nothing.
fn apply_event(eqs: &mut StateEquations, ev: Event) -> Result<(), SimulationError> {
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

/// Run the equations from `x0` with the sensitivities from `s0` (n × np, column k =
/// ∂x0/∂p_k), one twin per parameter, and record the outputs and their sensitivities at
/// the output times of `settings`. Radau only (whatever `settings.method` says).
///
/// # Errors
/// The solver's failure, a non-finite state, an event refused.
pub fn simulate_sensitivities(
    eqs: &mut StateEquations,
    x0: &[f64],
    s0: &[f64],
    settings: &Settings,
    outputs: &[Output],
    mut events: Vec<Event>,
    twins: &mut [Perturbation],
) -> Result<SensitivityRun, SimulationError> {
    settings.validate()?;
    let (n, np) = (eqs.n_states(), twins.len());
    if x0.len() != n || s0.len() != n * np {
        return Err(SimulationError::InitialState {
            given: x0.len(),
            expected: n,
        });
    }
    events.sort_by(|a, b| a.t.total_cmp(&b.t));
    let mut twin_events: Vec<std::iter::Peekable<std::vec::IntoIter<Event>>> = twins
        .iter_mut()
        .map(|w| {
            let mut e = std::mem::take(&mut w.events);
            e.sort_by(|a, b| a.t.total_cmp(&b.t));
            e.into_iter().peekable()
        })
        .collect();
    let mut events = events.into_iter().peekable();
    let (t0, t_end, dt) = (settings.t_start, settings.t_end, settings.dt_out);
    let n_grid = ((t_end - t0) / dt + 1e-9).floor() as usize;
    let end_extra = !same_time(t0 + n_grid as f64 * dt, t_end);
    let grid_at = |k: usize| {
        if k <= n_grid {
            Some(t0 + k as f64 * dt)
        } else if k == n_grid + 1 && end_extra {
            Some(t_end)
        } else {
            None
        }
    };
    let nominal: Vec<f64> = eqs.states().iter().map(|s| s.nominal).collect();
    let atol: Vec<f64> = nominal.iter().map(|s| settings.atol * s).collect();
    let mut x = x0.to_vec();
    let mut s = s0.to_vec();
    let mut t = t0;
    let mut next_row = 0usize;
    let probes: Vec<crate::equations::Probe> = outputs.iter().map(|o| o.probe).collect();
    let subsets: Vec<Subset> = std::iter::once(eqs.subset(&probes))
        .chain(twins.iter().map(|w| w.eqs.subset(&probes)))
        .collect();
    let mut xi = vec![0.0; n];
    let mut si = vec![0.0; n * np];
    // every row's storage at once: nothing grows while stepping
    let rows_total = n_grid + 2;
    let m = outputs.len();
    let mut run = SensitivityRun {
        t: Vec::with_capacity(rows_total),
        y: Vec::with_capacity(rows_total * m),
        dy_dp: Vec::with_capacity(rows_total * m * np),
        ..SensitivityRun::default()
    };
    loop {
        // Events due now, on the model and on every twin alike.
        while let Some(ev) = events.next_if(|e| e.t <= t || same_time(e.t, t)) {
            let te = ev.t;
            apply_event(eqs, ev)?;
            for (w, evs) in twins.iter_mut().zip(&mut twin_events) {
                while let Some(e) = evs.next_if(|e| e.t <= te || same_time(e.t, te)) {
                    apply_event(&mut w.eqs, e)?;
                }
            }
        }
        let t_event = events.peek().map_or(t_end, |e| e.t.min(t_end));
        let t_stop = eqs.next_breakpoint(t).map_or(t_event, |b| b.min(t_event));
        eqs.begin_segment(t);
        for w in twins.iter() {
            w.eqs.begin_segment(t);
        }
        let mut rows = Rows {
            eqs,
            twins,
            outputs,
            subsets: &subsets,
            xs: vec![0.0; n],
            run: std::mem::take(&mut run),
        };
        while let Some(tg) = grid_at(next_row).filter(|&g| same_time(g, t)) {
            rows.record(tg, &x, &s);
            next_row += 1;
        }
        if t >= t_end || same_time(t, t_end) {
            run = rows.run;
            break;
        }
        let mut ode = Ode { eqs: rows.eqs };
        let options = RadauOptions {
            rtol: settings.rtol,
            atol: atol.clone(),
            jacobian_theta: JACOBIAN_THETA,
            linear_algebra: settings.linear_algebra,
            ..RadauOptions::default()
        };
        let mut radau = Radau5::new(&mut ode, t, &x, options).map_err(|e| solver_error(t, e))?;
        let mut sens = Sensitivities::new(&radau, np, &s).map_err(|e| solver_error(t, e))?;
        let mut terms = StageTerms {
            eqs: rows.eqs,
            twins: rows.twins,
            n,
            jac: [
                DMatrix::zeros(n, n),
                DMatrix::zeros(n, n),
                DMatrix::zeros(n, n),
            ],
            dfdp: [vec![0.0; n * np], vec![0.0; n * np], vec![0.0; n * np]],
            f: vec![0.0; n],
            fp: vec![0.0; n],
            jacobians: 0,
        };
        let mut steps = 0usize;
        loop {
            let report = radau
                .step(&mut ode, t_stop)
                .map_err(|e| solver_error(radau.t(), e))?;
            sens.step(&mut radau, &mut terms)
                .map_err(|e| solver_error(radau.t(), e))?;
            steps += 1;
            if let Some(i) = radau.y().iter().position(|v| !v.is_finite()) {
                return Err(SimulationError::NonFinite {
                    t: radau.t(),
                    state: rows.eqs.states()[i].name.clone(),
                    element: rows
                        .eqs
                        .graph()
                        .node(rows.eqs.states()[i].element)
                        .name
                        .clone(),
                    value: radau.y()[i],
                    culprit: String::new(),
                });
            }
            // Rows inside the step (those at t_stop wait for the events there).
            while let Some(tg) = grid_at(next_row) {
                if tg >= t_stop || same_time(tg, t_stop) || tg > radau.t() {
                    break;
                }
                radau
                    .interpolate(tg, &mut xi)
                    .map_err(|e| solver_error(tg, e))?;
                sens.interpolate(tg, &mut si)
                    .map_err(|e| solver_error(tg, e))?;
                rows.record(tg, &xi, &si);
                next_row += 1;
            }
            if steps > settings.max_steps {
                return Err(solver_error(radau.t(), "more steps than max_steps"));
            }
            if report.reached_stop {
                break;
            }
        }
        x.copy_from_slice(radau.y());
        s.copy_from_slice(sens.s());
        run = rows.run;
        run.steps += radau.stats().steps;
        run.stage_iterations += sens.iterations;
        run.jacobians += terms.jacobians;
        t = t_stop;
    }
    eqs.end_segment();
    for w in twins.iter() {
        w.eqs.end_segment();
    }
    Ok(run)
}
