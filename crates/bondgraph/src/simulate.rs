//! Simulation: [`StateEquations`] → [`Trajectory`] with diffsol's stiff solvers.
//!
//! * Methods: BDF (variable order 1–5, the default), ESDIRK34, TR-BDF2 (implicit), Tsit45
//!   (explicit, for non-stiff checks).
//! * The implicit methods need Jacobian–vector products. We form them by forward finite
//!   differences, `Jv ≈ (f(x + σv) − f(x))/σ` with `σ = √ε·max(|x_j|, nominal_j)/‖v‖∞`,
//!   caching `f(x)` between the n products that make up one dense Jacobian: a Jacobian costs
//!   n + 1 right-hand-side evaluations. diffsol re-evaluates it rarely (every ~20 steps or on
//!   a convergence failure), so for our sizes this is a small share of the run time.
//! * Results are written at the output times `t0, t0 + Δ, …, t_end` by the solver's dense
//!   interpolation; the solver steps onto every scheduled event time exactly, the event
//!   replaces elements (a parameter switch), and the solver restarts from there. The output
//!   row at an event time is computed after the switch.
//! * After every accepted step the state is checked: a NaN or infinity stops the run with the
//!   time, the state and its element named, and keeps the rows computed so far. A solver
//!   failure does the same.

use std::cell::{Cell, RefCell};
use std::time::{Duration, Instant};

use diffsol::{
    NalgebraLU, NalgebraMat, OdeBuilder, OdeEquations, OdeSolverMethod, OdeSolverStopReason, Op,
};

use crate::bond::ElementId;
use crate::element::Element;
use crate::equations::{Probe, StateEquations};
use crate::error::SimulationError;

type M = NalgebraMat<f64>;
type LS = NalgebraLU<f64>;

/// Integration method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// Variable-order BDF (NDF), orders 1–5: the default for stiff systems.
    #[default]
    Bdf,
    /// Explicit-first-stage singly diagonally implicit Runge–Kutta, order 3 (4 stages).
    Esdirk34,
    /// TR-BDF2, order 2.
    TrBdf2,
    /// Tsitouras 5(4), explicit: only for non-stiff models.
    Tsit45,
}

impl Method {
    /// Parse `bdf`, `esdirk34`, `tr-bdf2`, `tsit45`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().replace('_', "-").as_str() {
            "bdf" => Some(Self::Bdf),
            "esdirk34" | "esdirk" => Some(Self::Esdirk34),
            "tr-bdf2" | "trbdf2" => Some(Self::TrBdf2),
            "tsit45" | "tsit5" => Some(Self::Tsit45),
            _ => None,
        }
    }
    /// The name `parse` accepts.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Bdf => "bdf",
            Self::Esdirk34 => "esdirk34",
            Self::TrBdf2 => "tr-bdf2",
            Self::Tsit45 => "tsit45",
        }
    }
    /// All methods.
    pub const ALL: [Method; 4] = [
        Method::Bdf,
        Method::Esdirk34,
        Method::TrBdf2,
        Method::Tsit45,
    ];
}

/// Simulation settings.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Start time (s).
    pub t_start: f64,
    /// End time (s).
    pub t_end: f64,
    /// Output interval (s).
    pub dt_out: f64,
    /// Method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance, scaled per state by its nominal magnitude.
    pub atol: f64,
    /// Most accepted steps before the run is stopped (a stalled or far too stiff run).
    pub max_steps: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            t_start: 0.0,
            t_end: 1.0,
            dt_out: 0.01,
            method: Method::Bdf,
            rtol: 1e-6,
            atol: 1e-8,
            max_steps: 10_000_000,
        }
    }
}

impl Settings {
    /// Check the settings make sense.
    pub fn validate(&self) -> Result<(), SimulationError> {
        let bad =
            |setting, message: String| Err(SimulationError::InvalidSetting { setting, message });
        if !self.t_start.is_finite() || !self.t_end.is_finite() || self.t_end <= self.t_start {
            return bad(
                "t_end",
                format!(
                    "need finite t_start < t_end, got t_start = {}, t_end = {}",
                    self.t_start, self.t_end
                ),
            );
        }
        if !(self.dt_out.is_finite() && self.dt_out > 0.0) {
            return bad(
                "dt_out",
                format!("must be finite and > 0, got {}", self.dt_out),
            );
        }
        if (self.t_end - self.t_start) / self.dt_out > 1e7 {
            return bad(
                "dt_out",
                format!("{} gives more than 1e7 output rows", self.dt_out),
            );
        }
        if !(self.rtol.is_finite() && self.rtol > 0.0 && self.rtol < 1.0) {
            return bad("rtol", format!("must be in (0, 1), got {}", self.rtol));
        }
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return bad("atol", format!("must be finite and > 0, got {}", self.atol));
        }
        Ok(())
    }
}

/// A scheduled event: at time `t`, replace elements (switch parameters).
#[derive(Debug)]
pub struct Event {
    /// Time (s).
    pub t: f64,
    /// Replacement elements, each of the same shape as the one it replaces.
    pub replacements: Vec<(ElementId, Box<dyn Element>)>,
}

/// Solver work, summed over all segments between events.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Statistics {
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations requested by the solver.
    pub rhs_evals: usize,
    /// Right-hand-side evaluations spent in finite-difference Jacobian–vector products
    /// (none since the Jacobian is assembled exactly: see `jac_assemblies`).
    pub jac_rhs_evals: usize,
    /// Jacobian evaluations requested by the solver.
    pub jac_evals: usize,
    /// Exact Jacobians assembled by [`StateEquations::jacobian`] (one per new (t, x) at which
    /// the solver asks for Jacobian–vector products).
    pub jac_assemblies: usize,
    /// LU factorisations.
    pub lu_factorisations: usize,
    /// Rejected steps (local error test failures).
    pub error_test_failures: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Newton convergence failures.
    pub newton_failures: usize,
    /// Scheduled events applied.
    pub events: usize,
    /// Wall time of the integration.
    pub wall_time: Duration,
}

impl std::fmt::Display for Statistics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "steps {}, rhs evals {} (+{} for Jacobians), Jacobian evals {} ({} assembled), LU factorisations {}, error-test failures {}, Newton iterations {}, Newton failures {}, events {}, wall time {:.3} s",
            self.steps,
            self.rhs_evals,
            self.jac_rhs_evals,
            self.jac_evals,
            self.jac_assemblies,
            self.lu_factorisations,
            self.error_test_failures,
            self.newton_iterations,
            self.newton_failures,
            self.events,
            self.wall_time.as_secs_f64()
        )
    }
}

/// Results: one row per output time, first column `t`.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    /// Column names, `t` first.
    pub columns: Vec<String>,
    /// Rows of values.
    pub rows: Vec<Vec<f64>>,
}

impl Trajectory {
    /// The column called `name`.
    #[must_use]
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[j]).collect())
    }
}

/// What a run produced: the rows so far, the statistics, and the error that stopped it, if any.
#[derive(Debug)]
pub struct Outcome {
    /// Output rows computed.
    pub trajectory: Trajectory,
    /// Solver work.
    pub stats: Statistics,
    /// Time reached.
    pub t_final: f64,
    /// State reached.
    pub x_final: Vec<f64>,
    /// Why the run stopped early, if it did.
    pub error: Option<SimulationError>,
    /// The watched states' minima over every accepted step.
    pub watched: Vec<WatchReport>,
}

/// The minimum a watched state reached.
#[derive(Clone, Debug, PartialEq)]
pub struct WatchReport {
    /// The element.
    pub element: String,
    /// The state's global name (`cyl1_piston_chamber.p`).
    pub state: String,
    /// What it is (`pressure`).
    pub name: String,
    /// Minimum over every accepted step.
    pub min: f64,
    /// When it was reached.
    pub t_min: f64,
    /// A warning, if the minimum fell below the element's threshold.
    pub warning: Option<String>,
}

/// One side of a [`Limit`](crate::element::Limit), as a root function of the solver.
#[derive(Clone, Debug)]
struct Bound {
    index: usize,
    value: f64,
    upper: bool,
    element: String,
    state: String,
    message: String,
}

impl Bound {
    /// Positive inside the bound, zero on it.
    fn margin(&self, x: &[f64]) -> f64 {
        if self.upper {
            self.value - x[self.index]
        } else {
            x[self.index] - self.value
        }
    }
    fn error(&self, t: f64) -> SimulationError {
        SimulationError::LimitReached {
            t,
            state: self.state.clone(),
            element: self.element.clone(),
            which: if self.upper { "upper" } else { "lower" },
            limit: self.value,
            message: self.message.clone(),
        }
    }
}

fn bounds(eqs: &StateEquations) -> Vec<Bound> {
    let mut v = Vec::new();
    for id in 0..eqs.graph().n_elements() {
        let node = eqs.graph().node(id);
        for l in node.element.limits() {
            let Some(index) = eqs.state_index(id, l.state) else {
                continue;
            };
            let info = &eqs.states()[index];
            for (value, upper) in [(l.lower, false), (l.upper, true)] {
                if value.is_finite() {
                    v.push(Bound {
                        index,
                        value,
                        upper,
                        element: node.name.clone(),
                        state: info.name.clone(),
                        message: l.message.clone(),
                    });
                }
            }
        }
    }
    v
}

struct Watcher {
    index: usize,
    report: WatchReport,
    warn_below: Option<f64>,
    warning: String,
}

fn watchers(eqs: &StateEquations) -> Vec<Watcher> {
    let mut v = Vec::new();
    for id in 0..eqs.graph().n_elements() {
        let node = eqs.graph().node(id);
        for w in node.element.watches() {
            let Some(index) = eqs.state_index(id, w.state) else {
                continue;
            };
            let info = &eqs.states()[index];
            v.push(Watcher {
                index,
                report: WatchReport {
                    element: node.name.clone(),
                    state: info.name.clone(),
                    name: w.name,
                    min: f64::INFINITY,
                    t_min: f64::NAN,
                    warning: None,
                },
                warn_below: w.warn_below,
                warning: w.warning,
            });
        }
    }
    v
}

fn watch(w: &mut [Watcher], t: f64, x: &[f64]) {
    for w in w {
        if x[w.index] < w.report.min {
            w.report.min = x[w.index];
            w.report.t_min = t;
        }
    }
}

fn reports(w: Vec<Watcher>) -> Vec<WatchReport> {
    w.into_iter()
        .map(|w| {
            let mut r = w.report;
            if let Some(lim) = w.warn_below {
                if r.min < lim {
                    r.warning = Some(format!(
                        "{} of `{}` fell to {:.6e} at t = {:.6} s, below {lim:e}: {}",
                        r.name, r.element, r.min, r.t_min, w.warning
                    ));
                }
            }
            r
        })
        .collect()
}

/// A named output column.
#[derive(Clone, Debug)]
pub struct Output {
    /// Column name.
    pub name: String,
    /// What it reads.
    pub probe: Probe,
}

struct Recorder<'e> {
    eqs: &'e StateEquations,
    watchers: Vec<Watcher>,
    outputs: &'e [Output],
    grid: Vec<f64>,
    next: usize,
    rows: Vec<Vec<f64>>,
}

impl Recorder<'_> {
    fn record(&mut self, t: f64, x: &[f64]) {
        self.eqs.evaluate(t, x);
        let mut row = Vec::with_capacity(self.outputs.len() + 1);
        row.push(t);
        row.extend(self.outputs.iter().map(|o| self.eqs.read(o.probe, t, x)));
        self.rows.push(row);
        self.next += 1;
    }
    fn pending(&self) -> Option<f64> {
        self.grid.get(self.next).copied()
    }
}

fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-10 * (1.0 + a.abs().max(b.abs()))
}

/// Run a simulation.
///
/// # Arguments
/// * `eqs` — the equations; scheduled events replace elements in it (they stay replaced).
/// * `x0` — initial state (use [`StateEquations::initial_state`]).
/// * `settings`, `outputs` — solver settings and the columns to record besides `t`.
/// * `events` — scheduled parameter switches, applied at their times (events at or before
///   `t_start` are applied before the run).
///
/// # Returns
/// An [`Outcome`] that always carries the rows computed, even when the run failed.
pub fn simulate(
    eqs: &mut StateEquations,
    x0: &[f64],
    settings: &Settings,
    outputs: &[Output],
    mut events: Vec<Event>,
) -> Outcome {
    let columns = std::iter::once("t".to_owned())
        .chain(outputs.iter().map(|o| o.name.clone()))
        .collect();
    let mut out = Outcome {
        trajectory: Trajectory {
            columns,
            rows: Vec::new(),
        },
        stats: Statistics::default(),
        t_final: settings.t_start,
        x_final: x0.to_vec(),
        error: None,
        watched: Vec::new(),
    };
    if let Err(e) = settings.validate() {
        out.error = Some(e);
        return out;
    }
    if x0.len() != eqs.n_states() {
        out.error = Some(SimulationError::Settings(format!(
            "initial state has {} values, the model {} states",
            x0.len(),
            eqs.n_states()
        )));
        return out;
    }
    if let Some((i, v)) = x0.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        let s = &eqs.states()[i];
        out.error = Some(SimulationError::NonFinite {
            t: settings.t_start,
            state: s.name.clone(),
            element: eqs.graph().node(s.element).name.clone(),
            value: *v,
            culprit: " (initial value)".into(),
        });
        return out;
    }
    if let Some(b) = bounds(eqs).iter().find(|b| b.margin(x0) < 0.0) {
        out.error = Some(b.error(settings.t_start));
        return out;
    }
    let start = Instant::now();
    events.sort_by(|a, b| a.t.total_cmp(&b.t));
    let (t0, t_end) = (settings.t_start, settings.t_end);
    let n_out = ((t_end - t0) / settings.dt_out + 1e-9).floor() as usize;
    let mut grid: Vec<f64> = (0..=n_out)
        .map(|k| t0 + k as f64 * settings.dt_out)
        .collect();
    if grid.last().is_some_and(|&t| !same_time(t, t_end)) {
        grid.push(t_end);
    }
    let mut x = x0.to_vec();
    let mut t = t0;
    let mut events = events.into_iter().peekable();
    let mut rows = Vec::new();
    let mut watchers = watchers(eqs);
    watch(&mut watchers, t0, x0);
    loop {
        // Apply every event due now.
        while let Some(ev) = events.next_if(|e| e.t <= t || same_time(e.t, t)) {
            // All or nothing: check every replacement before applying any.
            let refused = ev
                .replacements
                .iter()
                .find_map(|(id, el)| eqs.check_replacement(*id, el.as_ref()).err());
            if let Some(source) = refused {
                out.error = Some(SimulationError::Event { t: ev.t, source });
                break;
            }
            for (id, el) in ev.replacements {
                if let Err(source) = eqs.replace(id, el) {
                    out.error = Some(SimulationError::Event { t: ev.t, source });
                }
            }
            out.stats.events += 1;
        }
        if out.error.is_some() {
            break;
        }
        let mut rec = Recorder {
            eqs,
            watchers: std::mem::take(&mut watchers),
            outputs,
            grid: std::mem::take(&mut grid),
            next: 0,
            rows: std::mem::take(&mut rows),
        };
        // Rows due at the current time (after the events).
        rec.next = rec.rows.len();
        while rec.pending().is_some_and(|g| same_time(g, t)) {
            rec.record(t, &x);
        }
        let t_stop = events.peek().map_or(t_end, |e| e.t.min(t_end));
        if t >= t_end || same_time(t, t_end) {
            rows = rec.rows;
            watchers = rec.watchers;
            break;
        }
        let seg = run_segment(&mut rec, settings, t, t_stop, &x, &mut out.stats);
        grid = rec.grid;
        rows = rec.rows;
        watchers = rec.watchers;
        match seg {
            Ok(xs) => {
                x = xs;
                t = t_stop;
            }
            Err((te, xe, err)) => {
                t = te;
                x = xe;
                out.error = Some(err);
                break;
            }
        }
    }
    out.trajectory.rows = rows;
    out.watched = reports(watchers);
    out.t_final = t;
    out.x_final = x;
    out.stats.wall_time = start.elapsed();
    out
}

type SegmentError = (f64, Vec<f64>, SimulationError);

/// Integrate from `t` to `t_stop`, recording grid rows strictly before `t_stop`.
fn run_segment(
    rec: &mut Recorder<'_>,
    settings: &Settings,
    t: f64,
    t_stop: f64,
    x: &[f64],
    stats: &mut Statistics,
) -> Result<Vec<f64>, SegmentError> {
    let eqs = rec.eqs;
    let n = x.len();
    let nominal: Vec<f64> = eqs.states().iter().map(|s| s.nominal).collect();
    let atol: Vec<f64> = nominal.iter().map(|s| settings.atol * s).collect();
    let rhs_calls = Cell::new(0usize);
    let jac_calls = Cell::new(0usize);
    let bad: RefCell<Option<(f64, Vec<f64>)>> = RefCell::new(None);
    let cache = RefCell::new(JacCache {
        x: vec![f64::NAN; n],
        t: f64::NAN,
        jac: nalgebra::DMatrix::zeros(n, n),
    });
    let rhs = |x: &[f64], _p: &[f64], t: f64, dx: &mut [f64]| {
        rhs_calls.set(rhs_calls.get() + 1);
        eqs.rhs(t, x, dx);
        if bad.borrow().is_none() && dx.iter().any(|v| !v.is_finite()) {
            *bad.borrow_mut() = Some((t, x.to_vec()));
        }
    };
    // The exact Jacobian, assembled once per (t, x) (bitwise): diffsol asks for it column
    // by column (v = unit vectors) and for products with Newton updates.
    let jvp = |x: &[f64], _p: &[f64], t: f64, v: &[f64], jv: &mut [f64]| {
        let mut c = cache.borrow_mut();
        let JacCache { x: cx, t: ct, jac } = &mut *c;
        if ct.to_bits() != t.to_bits() || cx.iter().zip(x).any(|(a, b)| a.to_bits() != b.to_bits())
        {
            eqs.jacobian(t, x, jac);
            jac_calls.set(jac_calls.get() + 1);
            cx.copy_from_slice(x);
            *ct = t;
        }
        jv.fill(0.0);
        for (k, &vk) in v.iter().enumerate() {
            if vk != 0.0 {
                for (j, a) in jv.iter_mut().zip(jac.column(k).iter()) {
                    *j += a * vk;
                }
            }
        }
    };
    // Equations that are not finite where the segment starts would send the solver after a
    // NaN step size: refuse at once, naming the culprit.
    {
        let mut dx = vec![0.0; n];
        eqs.rhs(t, x, &mut dx);
        if dx.iter().any(|v| !v.is_finite()) {
            let c = eqs
                .first_non_finite(t, x)
                .map(|c| format!("; {c}"))
                .unwrap_or_default();
            return Err((
                t,
                x.to_vec(),
                SimulationError::Solver {
                    t,
                    message: "the equations are not finite at the start".into(),
                    culprit: c,
                },
            ));
        }
    }
    let x0 = x.to_vec();
    let limits = bounds(eqs);
    let n_roots = limits.len();
    let roots_of = limits.clone();
    let problem = OdeBuilder::<M>::new()
        .t0(t)
        .rtol(settings.rtol)
        .atol(atol)
        .rhs_implicit(rhs, jvp)
        .init(move |_p, _t, y| y.copy_from_slice(&x0), n)
        .root(
            move |x, _p, _t, g| {
                for (gk, b) in g.iter_mut().zip(&roots_of) {
                    *gk = b.margin(x);
                }
            },
            n_roots,
        )
        .build();
    let mut problem = match problem {
        Ok(p) => p,
        Err(e) => return Err((t, x.to_vec(), SimulationError::Settings(format!("{e}")))),
    };
    // diffsol counts Newton failures cumulatively over a solver's life: recovered failures
    // must not end a long segment, but a NaN step size never trips the step-size check, so
    // the limit stays finite.
    problem.ode_options.max_nonlinear_solver_failures = 10_000;
    problem.ode_options.max_error_test_failures = 100;
    let result = match settings.method {
        Method::Bdf => problem
            .bdf::<LS>()
            .map_err(|e| e.to_string())
            .map(|s| drive(s, rec, t_stop, settings.max_steps, &limits, &bad, stats)),
        Method::Esdirk34 => problem
            .esdirk34::<LS>()
            .map_err(|e| e.to_string())
            .map(|s| drive(s, rec, t_stop, settings.max_steps, &limits, &bad, stats)),
        Method::TrBdf2 => problem
            .tr_bdf2::<LS>()
            .map_err(|e| e.to_string())
            .map(|s| drive(s, rec, t_stop, settings.max_steps, &limits, &bad, stats)),
        Method::Tsit45 => problem
            .tsit45()
            .map_err(|e| e.to_string())
            .map(|s| drive(s, rec, t_stop, settings.max_steps, &limits, &bad, stats)),
    };
    stats.rhs_evals += rhs_calls.get();
    stats.jac_assemblies += jac_calls.get();
    stats.jac_evals += problem.eqn.rhs().statistics().number_of_matrix_evals;
    match result {
        Ok(r) => r,
        Err(message) => Err((
            t,
            x.to_vec(),
            SimulationError::Solver {
                t,
                message,
                culprit: String::new(),
            },
        )),
    }
}

struct JacCache {
    x: Vec<f64>,
    t: f64,
    jac: nalgebra::DMatrix<f64>,
}

fn culprit(eqs: &StateEquations, bad: &RefCell<Option<(f64, Vec<f64>)>>) -> String {
    bad.borrow()
        .as_ref()
        .and_then(|(t, x)| {
            eqs.first_non_finite(*t, x)
                .map(|c| format!("; first non-finite value at t = {t:.9} s: {c}"))
        })
        .unwrap_or_default()
}

fn drive<'a, Eqn, S>(
    mut s: S,
    rec: &mut Recorder<'_>,
    t_stop: f64,
    max_steps: usize,
    limits: &[Bound],
    bad: &RefCell<Option<(f64, Vec<f64>)>>,
    stats: &mut Statistics,
) -> Result<Vec<f64>, SegmentError>
where
    Eqn: OdeEquations<T = f64, V = diffsol::NalgebraVec<f64>> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    let eqs = rec.eqs;
    let finish = |s: &S, stats: &mut Statistics| {
        let st = s.get_statistics();
        stats.steps += st.number_of_steps;
        stats.error_test_failures += st.number_of_error_test_failures;
        stats.newton_iterations += st.number_of_nonlinear_solver_iterations;
        stats.newton_failures += st.number_of_nonlinear_solver_fails;
        stats.lu_factorisations += st.number_of_linear_solver_setups;
    };
    let state_of = |s: &S| -> (f64, Vec<f64>) {
        let st = s.state();
        (st.t, st.y.batch_as_slice(0).to_vec())
    };
    if let Err(e) = s.set_stop_time(t_stop) {
        let (t, x) = state_of(&s);
        return Err((
            t,
            x,
            SimulationError::Solver {
                t,
                message: e.to_string(),
                culprit: String::new(),
            },
        ));
    }
    loop {
        let step = s.step();
        let (t, x) = state_of(&s);
        match step {
            Err(e) => {
                finish(&s, stats);
                return Err((
                    t,
                    x,
                    SimulationError::Solver {
                        t,
                        message: e.to_string(),
                        culprit: culprit(eqs, bad),
                    },
                ));
            }
            Ok(reason) => {
                let h = s.state().h;
                let stalled =
                    !t.is_finite() || !h.is_finite() || h.abs() < 1e-14 * t.abs().max(1.0);
                let too_many = s.get_statistics().number_of_steps + stats.steps >= max_steps;
                if stalled || too_many {
                    finish(&s, stats);
                    let message = if stalled {
                        format!("the step size collapsed to {h:e}")
                    } else {
                        format!("more than {max_steps} steps; hint: the model may be much stiffer than the method (try bdf) or max_steps too small")
                    };
                    return Err((
                        t,
                        x,
                        SimulationError::Solver {
                            t,
                            message,
                            culprit: culprit(eqs, bad),
                        },
                    ));
                }
                watch(&mut rec.watchers, t, &x);
                if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                    finish(&s, stats);
                    let info = &eqs.states()[i];
                    let err = SimulationError::NonFinite {
                        t,
                        state: info.name.clone(),
                        element: eqs.graph().node(info.element).name.clone(),
                        value: x[i],
                        culprit: culprit(eqs, bad),
                    };
                    return Err((t, x, err));
                }
                // A limit reached inside the step: rows up to the crossing, then stop there.
                let root = match reason {
                    OdeSolverStopReason::RootFound(tr, idx) => Some((tr, idx)),
                    _ => None,
                };
                let t_rows = root.map_or(t, |(tr, _)| tr);
                while let Some(tg) = rec.pending() {
                    if tg > t_rows
                        || same_time(tg, t_stop)
                        || tg > t_stop
                        || (root.is_some() && same_time(tg, t_rows))
                    {
                        break;
                    }
                    if same_time(tg, t) {
                        rec.record(tg, &x);
                    } else {
                        match s.interpolate(tg) {
                            Ok(y) => rec.record(tg, y.batch_as_slice(0)),
                            Err(e) => {
                                finish(&s, stats);
                                return Err((
                                    t,
                                    x,
                                    SimulationError::Solver {
                                        t,
                                        message: format!("interpolation at t = {tg}: {e}"),
                                        culprit: String::new(),
                                    },
                                ));
                            }
                        }
                    }
                }
                if let Some((tr, idx)) = root {
                    finish(&s, stats);
                    let xr = match s.interpolate(tr) {
                        Ok(y) => y.batch_as_slice(0).to_vec(),
                        Err(_) => x,
                    };
                    let err = limits.get(idx).map_or_else(
                        || SimulationError::Solver {
                            t: tr,
                            message: format!("root {idx} found, but no limit has that index"),
                            culprit: String::new(),
                        },
                        |b| b.error(tr),
                    );
                    return Err((tr, xr, err));
                }
                if matches!(reason, OdeSolverStopReason::TstopReached) {
                    finish(&s, stats);
                    return Ok(x);
                }
            }
        }
    }
}
