//! Simulation: [`StateEquations`] → [`Trajectory`], every method behind one interface.
//!
//! * Methods ([`Method`]): our Radau IIA of order 5 ([`crate::radau`], the default: L-stable,
//!   for stiff models with undamped or lightly damped fast modes), and diffsol's BDF (orders
//!   1–5), ESDIRK34, TR-BDF2 (implicit) and Tsit45 (explicit, for non-stiff checks). Each is a
//!   `Stepper` (`stepper.rs`): one accepted step at a time, dense output inside the last step,
//!   its work counters; one loop (`stepper::drive`) records rows, watches states, stops at a
//!   NaN, a limit, a stalled step or `max_steps`, for every method alike.
//! * The implicit methods use the exact Jacobian of the evaluation plan
//!   ([`StateEquations::jacobian`]): Radau asks for it directly; diffsol's Jacobian–vector
//!   products multiply by it, assembled once per (t, x) (`segment.rs`).
//! * Results are written at the output times `t0, t0 + Δ, …, t_end` by the method's dense
//!   interpolation; the solver steps onto every scheduled event time exactly, the event
//!   replaces elements (a parameter switch), and the solver restarts from there. It stops
//!   and restarts likewise at the breakpoints of the external inputs' series
//!   ([`StateEquations::next_breakpoint`], unless turned off), each segment evaluating every
//!   series on one piece ([`StateEquations::begin_segment`]). The output
//!   row at an event time is computed after the switch. Element limits are located by root
//!   finding (diffsol's, or bisection on Radau's dense output: `radau.rs`).
//! * After every accepted step the state is checked: a NaN or infinity stops the run with the
//!   time, the state and its element named, and keeps the rows computed so far. A solver
//!   failure does the same.
//! * Rows go to a [`RowSink`] as they are computed ([`simulate_into`]; a file, in `bg-sim
//!   run`), or are kept in memory ([`simulate`], bounded by [`MAX_VALUES_IN_MEMORY`]). A sink
//!   may also ask for the outputs at every accepted step (checks that must hold between
//!   rows). A refused row or [`Settings::interrupt`] stops the run after the current step.
//! * A model with no states is not integrated: its rows are its outputs at the output times.

mod radau;
mod segment;
mod stepper;
mod stepping;

pub use stepping::Simulation;

use segment::run_segment;

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::bond::ElementId;
use crate::element::Element;
use crate::equations::{Probe, StateEquations};
use crate::error::SimulationError;

/// Integration method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// Variable-order BDF (NDF), orders 1–5.
    Bdf,
    /// Explicit-first-stage singly diagonally implicit Runge–Kutta, order 3 (4 stages).
    Esdirk34,
    /// TR-BDF2, order 2.
    TrBdf2,
    /// Tsitouras 5(4), explicit: only for non-stiff models.
    Tsit45,
    /// Radau IIA, order 5 (3-stage, L-stable): the default, for stiff systems, lightly
    /// damped oscillations included (see [`radau`](crate::radau)).
    #[default]
    Radau5,
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
            "radau5" | "radau" => Some(Self::Radau5),
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
            Self::Radau5 => "radau5",
        }
    }
    /// The names `parse` accepts, for hints: `bdf, esdirk34, …`.
    #[must_use]
    pub fn names() -> String {
        Self::ALL.map(Self::name).join(", ")
    }
    /// All methods.
    pub const ALL: [Method; 5] = [
        Method::Bdf,
        Method::Esdirk34,
        Method::TrBdf2,
        Method::Tsit45,
        Method::Radau5,
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
    /// Radau's linear algebra: dense, sparse, or chosen by size and density (`auto`).
    pub linear_algebra: crate::radau::LinearAlgebra,
    /// Set it to `true` (a SIGINT/SIGTERM handler, another thread) to stop the run after the
    /// current step: the rows so far are kept and the outcome's error is
    /// [`SimulationError::Interrupted`].
    pub interrupt: Option<Arc<AtomicBool>>,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            t_start: 0.0,
            t_end: 1.0,
            dt_out: 0.01,
            method: Method::Radau5,
            rtol: 1e-6,
            atol: 1e-8,
            max_steps: 10_000_000,
            linear_algebra: crate::radau::LinearAlgebra::Auto,
            interrupt: None,
        }
    }
}

/// Most output rows a run may ask for (`(t_end − t_start)/dt_out`). Rows stream to their sink
/// as they are computed ([`simulate_into`]), so the bound is a guard against a mistyped
/// `dt_out`, not a memory limit.
pub const MAX_OUTPUT_ROWS: f64 = 1e9;

/// Most values (rows × columns, `t` included) a run that keeps its rows in memory
/// ([`simulate`]) may hold: 5·10⁷ values are 400 MB.
pub const MAX_VALUES_IN_MEMORY: f64 = 5e7;

/// Smallest relative tolerance: below it the error test asks for more than f64 resolves.
pub const MIN_RTOL: f64 = 1e-14;

/// The solver's time resolution near `t_start`, `t_end`: a step shorter than this counts as a
/// collapsed step size (see `drive`).
fn time_resolution(s: &Settings) -> f64 {
    1e-14 * s.t_start.abs().max(s.t_end.abs()).max(1.0)
}

impl Settings {
    /// Check the settings make sense.
    pub fn validate(&self) -> Result<(), SimulationError> {
        let bad = |setting, message: String| {
            Err(SimulationError::InvalidSetting {
                setting,
                message,
                hint: None,
            })
        };
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
        let res = time_resolution(self);
        if self.t_end - self.t_start < 1e4 * res {
            return Err(SimulationError::InvalidSetting {
                setting: "t_end",
                message: format!(
                    "t_end − t_start = {:e} s is too short to integrate at times near {:e} s, where f64 times are {:e} s apart and the shortest step is {res:e} s; it must be at least {:e} s",
                    self.t_end - self.t_start,
                    self.t_start.abs().max(self.t_end.abs()),
                    f64::EPSILON * self.t_start.abs().max(self.t_end.abs()),
                    1e4 * res
                ),
                hint: Some("start the time at 0"),
            });
        }
        if self.dt_out < res {
            return bad(
                "dt_out",
                format!(
                    "{:e} s is below the time resolution {res:e} s at these times",
                    self.dt_out
                ),
            );
        }
        if (self.t_end - self.t_start) / self.dt_out > MAX_OUTPUT_ROWS {
            return bad(
                "dt_out",
                format!(
                    "{} gives {:.3e} output rows, more than {MAX_OUTPUT_ROWS:e}",
                    self.dt_out,
                    (self.t_end - self.t_start) / self.dt_out
                ),
            );
        }
        if !(self.rtol.is_finite() && (MIN_RTOL..1.0).contains(&self.rtol)) {
            return bad(
                "rtol",
                format!("must be in [{MIN_RTOL:e}, 1), got {}", self.rtol),
            );
        }
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return bad("atol", format!("must be finite and > 0, got {}", self.atol));
        }
        Ok(())
    }

    /// The number of output rows: `t_start, t_start + dt_out, …` up to `t_end`, and `t_end`.
    #[must_use]
    pub fn output_rows(&self) -> f64 {
        let n = ((self.t_end - self.t_start) / self.dt_out + 1e-9).floor();
        n + 2.0
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
            "steps {}, rhs evals {}, Jacobian evals {} ({} assembled), LU factorisations {}, error-test failures {}, Newton iterations {}, Newton failures {}, events {}, wall time {:.3} s",
            self.steps,
            self.rhs_evals,
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
    /// The column names; the rows, when they are kept in memory ([`simulate`]).
    pub trajectory: Trajectory,
    /// Output rows delivered (to the sink of [`simulate_into`], or kept in `trajectory`).
    pub rows: usize,
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
    hint: Option<String>,
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
            hint: self.hint.clone(),
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
                        hint: l.hint.clone(),
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

/// Where a run's output rows go, one at a time, as they are computed ([`simulate_into`]): a
/// file, a check, a plot. `Vec<Vec<f64>>` is a sink that keeps them in memory.
pub trait RowSink {
    /// One output row: `t`, then the outputs in order. An error stops the run; the outcome's
    /// error is then [`SimulationError::Output`] and the rows before this one were delivered.
    fn row(&mut self, row: &[f64]) -> Result<(), String>;
    /// Whether [`RowSink::step`] wants the outputs at every accepted solver step too.
    fn wants_steps(&self) -> bool {
        false
    }
    /// The outputs (`t` first) at an accepted solver step, between output rows: what a check
    /// that must hold at every step reads. Called only if [`RowSink::wants_steps`].
    fn step(&mut self, _values: &[f64]) {}
}

impl RowSink for Vec<Vec<f64>> {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        self.push(row.to_vec());
        Ok(())
    }
}

/// The output times `t0, t0 + Δ, …`, and `t_end` if the grid misses it, without storing them.
#[derive(Clone, Copy, Debug)]
struct Grid {
    t0: f64,
    dt: f64,
    /// Index of the last grid point `t0 + n·Δ` at or before `t_end`.
    n: usize,
    t_end: f64,
    /// `t_end` is one more row (the grid does not land on it).
    end_extra: bool,
}

impl Grid {
    fn new(s: &Settings) -> Self {
        let n = ((s.t_end - s.t_start) / s.dt_out + 1e-9).floor() as usize;
        let last = s.t_start + n as f64 * s.dt_out;
        Self {
            t0: s.t_start,
            dt: s.dt_out,
            n,
            t_end: s.t_end,
            end_extra: !same_time(last, s.t_end),
        }
    }
    fn at(&self, k: usize) -> Option<f64> {
        if k <= self.n {
            Some(self.t0 + k as f64 * self.dt)
        } else if k == self.n + 1 && self.end_extra {
            Some(self.t_end)
        } else {
            None
        }
    }
}

/// What the recorder carries from one segment to the next.
struct Progress {
    watchers: Vec<Watcher>,
    /// Index of the next grid time.
    next: usize,
    /// Rows delivered to the sink.
    rows: usize,
    /// Why the run must stop at the next step: the sink refused a row.
    stop: Option<SimulationError>,
}

struct Recorder<'e> {
    eqs: &'e StateEquations,
    outputs: &'e [Output],
    grid: Grid,
    sink: &'e mut dyn RowSink,
    interrupt: Option<&'e AtomicBool>,
    wants_steps: bool,
    /// The segment ends at an event: its last step is handed on after the switch (as the
    /// output row at an event time is), not before.
    event_at: Option<f64>,
    buf: Vec<f64>,
    p: Progress,
    /// The energy audit fed after every accepted step ([`simulate_audited`]), if any.
    audit: Option<&'e mut crate::energy::EnergyAudit>,
}

impl Recorder<'_> {
    /// `t` and the outputs at (t, x) into `buf`.
    fn values(&mut self, t: f64, x: &[f64]) {
        self.eqs.evaluate(t, x);
        self.buf.clear();
        self.buf.push(t);
        let eqs = self.eqs;
        self.buf
            .extend(self.outputs.iter().map(|o| eqs.read(o.probe, t, x)));
    }
    /// The row of the pending grid time `t`; after a refused row, rows are skipped.
    fn record(&mut self, t: f64, x: &[f64]) {
        self.p.next += 1;
        if self.p.stop.is_some() {
            return;
        }
        self.values(t, x);
        match self.sink.row(&self.buf) {
            Ok(()) => self.p.rows += 1,
            Err(message) => self.p.stop = Some(SimulationError::Output { t, message }),
        }
    }
    fn pending(&self) -> Option<f64> {
        self.grid.at(self.p.next)
    }
    /// Every accepted step: watched minima, the sink's per-step values, and whether the run
    /// must stop (a refused row, or the interruption flag).
    fn accepted(&mut self, t: f64, x: &[f64]) -> Result<(), SimulationError> {
        watch(&mut self.p.watchers, t, x);
        if self.wants_steps && !self.event_at.is_some_and(|te| same_time(te, t)) {
            self.step_values(t, x);
        }
        self.should_stop(t)
    }
    /// Hand the outputs at (t, x) to the sink as a step.
    fn step_values(&mut self, t: f64, x: &[f64]) {
        self.values(t, x);
        self.sink.step(&self.buf);
    }
    fn should_stop(&mut self, t: f64) -> Result<(), SimulationError> {
        if let Some(e) = self.p.stop.take() {
            return Err(e);
        }
        if self.interrupt.is_some_and(|f| f.load(Ordering::Relaxed)) {
            return Err(SimulationError::Interrupted { t });
        }
        Ok(())
    }
}

fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-10 * (1.0 + a.abs().max(b.abs()))
}

/// An outcome with no rows yet.
fn start_outcome(settings: &Settings, outputs: &[Output], x0: &[f64]) -> Outcome {
    let columns = std::iter::once("t".to_owned())
        .chain(outputs.iter().map(|o| o.name.clone()))
        .collect();
    Outcome {
        trajectory: Trajectory {
            columns,
            rows: Vec::new(),
        },
        rows: 0,
        stats: Statistics::default(),
        t_final: settings.t_start,
        x_final: x0.to_vec(),
        error: None,
        watched: Vec::new(),
    }
}

/// Refuse a run whose rows, kept in memory, would exceed [`MAX_VALUES_IN_MEMORY`].
///
/// # Errors
/// [`SimulationError::InvalidSetting`] on `dt_out`, saying how many values it asks for.
pub fn check_in_memory(settings: &Settings, columns: usize) -> Result<(), SimulationError> {
    let values = settings.output_rows() * columns as f64;
    if values > MAX_VALUES_IN_MEMORY {
        return Err(SimulationError::InvalidSetting {
            setting: "dt_out",
            message: format!(
                "{} gives {:.3e} rows × {columns} columns = {values:.3e} values, more than the {MAX_VALUES_IN_MEMORY:e} a run kept in memory may hold",
                settings.dt_out,
                settings.output_rows()
            ),
            hint: Some(
                "stream the rows to a file: `bg-sim run` does, `simulate_into` in a program",
            ),
        });
    }
    Ok(())
}

/// Run a simulation and keep its rows in memory (in `trajectory.rows`).
///
/// As [`simulate_into`] with a sink that collects; refused (the outcome's error, no rows) if
/// the rows would hold more than [`MAX_VALUES_IN_MEMORY`] values.
///
/// # Returns
/// An [`Outcome`] that always carries the rows computed, even when the run failed.
pub fn simulate(
    eqs: &mut StateEquations,
    x0: &[f64],
    settings: &Settings,
    outputs: &[Output],
    events: Vec<Event>,
) -> Outcome {
    if let Err(e) = settings
        .validate()
        .and_then(|()| check_in_memory(settings, outputs.len() + 1))
    {
        let mut out = start_outcome(settings, outputs, x0);
        out.error = Some(e);
        return out;
    }
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut out = simulate_into(eqs, x0, settings, outputs, events, &mut rows);
    out.trajectory.rows = rows;
    out
}

/// Run a simulation, handing each output row to `sink` as it is computed.
///
/// # Arguments
/// * `eqs` — the equations; scheduled events replace elements in it (they stay replaced).
/// * `x0` — initial state (use [`StateEquations::initial_state`]).
/// * `settings`, `outputs` — solver settings and the columns to record besides `t`.
/// * `events` — scheduled parameter switches, applied at their times (events at or before
///   `t_start` are applied before the run; events after `t_end` are not reached).
/// * `sink` — receives every output row in time order; if it asks, the outputs at every
///   accepted step too. A refused row stops the run.
///
/// A model with no states is not integrated: its rows are its outputs at the output times.
/// The run stops early, keeping what the sink received, when the solver fails, a state is
/// not finite, a limit is reached, the sink refuses a row or `settings.interrupt` is set.
///
/// # Returns
/// An [`Outcome`] with the statistics, the number of rows delivered, and why the run stopped
/// early, if it did; its `trajectory` has the column names and no rows.
pub fn simulate_into(
    eqs: &mut StateEquations,
    x0: &[f64],
    settings: &Settings,
    outputs: &[Output],
    events: Vec<Event>,
    sink: &mut dyn RowSink,
) -> Outcome {
    simulate_audited(eqs, x0, settings, outputs, events, sink, None)
}

/// [`simulate_into`] with an energy audit ([`crate::energy`]) fed after every accepted step
/// (`None`: exactly [`simulate_into`]). Read the audit with
/// [`EnergyAudit::report`](crate::energy::EnergyAudit::report) afterwards.
pub fn simulate_audited(
    eqs: &mut StateEquations,
    x0: &[f64],
    settings: &Settings,
    outputs: &[Output],
    mut events: Vec<Event>,
    sink: &mut dyn RowSink,
    mut audit: Option<&mut crate::energy::EnergyAudit>,
) -> Outcome {
    let mut out = start_outcome(settings, outputs, x0);
    if let Err(e) = settings.validate() {
        out.error = Some(e);
        return out;
    }
    if x0.len() != eqs.n_states() {
        out.error = Some(SimulationError::InitialState {
            given: x0.len(),
            expected: eqs.n_states(),
        });
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
    let grid = Grid::new(settings);
    let interrupt = settings.interrupt.as_deref();
    let wants_steps = sink.wants_steps();
    let mut x = x0.to_vec();
    let mut t = t0;
    let mut events = events.into_iter().peekable();
    let mut progress = Progress {
        watchers: watchers(eqs),
        next: 0,
        rows: 0,
        stop: None,
    };
    let mut buf = Vec::with_capacity(outputs.len() + 1);
    watch(&mut progress.watchers, t0, x0);
    loop {
        // Apply every event due now.
        let mut switched = false;
        while let Some(ev) = events.next_if(|e| e.t <= t || same_time(e.t, t)) {
            switched = true;
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
        let t_event = events.peek().map_or(t_end, |e| e.t.min(t_end));
        // The inputs' next breakpoint (a sample's corner) is a stop too, not an event.
        let t_stop = eqs.next_breakpoint(t).map_or(t_event, |b| b.min(t_event));
        eqs.begin_segment(t);
        let mut rec = Recorder {
            eqs,
            outputs,
            grid,
            sink: &mut *sink,
            interrupt,
            wants_steps,
            event_at: (t_event < t_end && same_time(t_event, t_stop)).then_some(t_stop),
            buf: std::mem::take(&mut buf),
            p: progress,
            audit: audit.as_deref_mut(),
        };
        if let Some(a) = rec.audit.as_deref_mut() {
            a.begin_segment(rec.eqs, t, &x);
        }
        // The step that reached an event time, after the switch.
        if switched && wants_steps && t > t0 {
            rec.step_values(t, &x);
        }
        // Rows due at the current time (after the events).
        while rec.pending().is_some_and(|g| same_time(g, t)) {
            rec.record(t, &x);
        }
        let seg = if t >= t_end || same_time(t, t_end) {
            None
        } else if x.is_empty() {
            Some(record_without_states(&mut rec, t_stop))
        } else {
            Some(run_segment(
                &mut rec,
                settings,
                t,
                t_stop,
                &x,
                &mut out.stats,
            ))
        };
        if let Some(a) = rec.audit.as_deref_mut() {
            match &seg {
                Some(Ok(xs)) => a.end_segment(rec.eqs, t_stop, xs),
                Some(Err((te, xe, _))) => a.end_segment(rec.eqs, *te, xe),
                None => a.end_segment(rec.eqs, t, &x),
            }
        }
        // A row refused at the end of the segment stops the run here.
        let refused = rec.p.stop.take();
        buf = rec.buf;
        progress = rec.p;
        let seg = match (seg, refused) {
            (Some(Ok(xs)), Some(e)) => Err((t_stop, xs, e)),
            (None, Some(e)) => Err((t, x.clone(), e)),
            (Some(s), _) => s,
            (None, None) => break,
        };
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
    eqs.end_segment();
    out.rows = progress.rows;
    out.watched = reports(progress.watchers);
    out.t_final = t;
    out.x_final = x;
    out.stats.wall_time = start.elapsed();
    out
}

/// A model with no states has nothing to integrate: its rows strictly before `t_stop` are its
/// outputs at the output times.
fn record_without_states(rec: &mut Recorder<'_>, t_stop: f64) -> Result<Vec<f64>, SegmentError> {
    while let Some(tg) = rec.pending() {
        if tg > t_stop || same_time(tg, t_stop) {
            break;
        }
        rec.accepted(tg, &[]).map_err(|e| (tg, Vec::new(), e))?;
        rec.record(tg, &[]);
    }
    Ok(Vec::new())
}

type SegmentError = (f64, Vec<f64>, SimulationError);

fn culprit(eqs: &StateEquations, bad: &RefCell<Option<(f64, Vec<f64>)>>) -> String {
    bad.borrow()
        .as_ref()
        .and_then(|(t, x)| {
            eqs.first_non_finite(*t, x)
                .map(|c| format!("; first non-finite value at t = {t:.9} s: {c}"))
        })
        .unwrap_or_default()
}
