//! Output rows: the named columns ([`Output`]), where rows go ([`RowSink`]), the output
//! times ([`Grid`]) and the [`Recorder`] that computes each row and the per-step values.

use std::sync::atomic::{AtomicBool, Ordering};

use super::watch::{watch, Watcher};
use super::Settings;
use crate::equations::{Probe, StateEquations, Subset};
use crate::error::SimulationError;

/// A named output column.
#[derive(Clone, Debug)]
pub struct Output {
    /// Column name.
    pub name: String,
    /// What it reads.
    pub probe: Probe,
}

/// Where a run's output rows go, one at a time, as they are computed ([`simulate_into`](super::simulate_into)): a
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
    /// Whether [`RowSink::step`] reads output column `column` (0: the first output, after
    /// `t`). The recorder evaluates only what the columns read need; the others are NaN.
    fn step_reads(&self, _column: usize) -> bool {
        true
    }
}

impl RowSink for Vec<Vec<f64>> {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        self.push(row.to_vec());
        Ok(())
    }
}

/// The output times `t0, t0 + Δ, …`, and `t_end` if the grid misses it, without storing them.
#[derive(Clone, Copy, Debug)]
pub(super) struct Grid {
    pub(super) t0: f64,
    pub(super) dt: f64,
    /// Index of the last grid point `t0 + n·Δ` at or before `t_end`.
    pub(super) n: usize,
    pub(super) t_end: f64,
    /// `t_end` is one more row (the grid does not land on it).
    pub(super) end_extra: bool,
}

impl Grid {
    pub(super) fn new(s: &Settings) -> Self {
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
    pub(super) fn at(&self, k: usize) -> Option<f64> {
        if k <= self.n {
            Some(self.t0 + k as f64 * self.dt)
        } else if k == self.n + 1 && self.end_extra {
            Some(self.t_end)
        } else {
            None
        }
    }
}

/// What the recorder evaluates, found once per run: the stages the output columns need, and
/// those the columns the sink reads at every accepted step need.
#[derive(Default)]
pub(super) struct Reads {
    rows: Subset,
    steps: Subset,
    /// Per output column: read at steps.
    step_columns: Vec<bool>,
}

impl Reads {
    pub(super) fn new(eqs: &StateEquations, outputs: &[Output], sink: &dyn RowSink) -> Self {
        let probes: Vec<Probe> = outputs.iter().map(|o| o.probe).collect();
        let step_columns: Vec<bool> = if sink.wants_steps() {
            (0..outputs.len()).map(|k| sink.step_reads(k)).collect()
        } else {
            vec![false; outputs.len()]
        };
        let step_probes: Vec<Probe> = probes
            .iter()
            .zip(&step_columns)
            .filter(|(_, &r)| r)
            .map(|(&p, _)| p)
            .collect();
        Self {
            rows: eqs.subset(&probes),
            steps: eqs.subset(&step_probes),
            step_columns,
        }
    }
}

/// What the recorder carries from one segment to the next.
pub(super) struct Progress {
    pub(super) watchers: Vec<Watcher>,
    /// Index of the next grid time.
    pub(super) next: usize,
    /// Rows delivered to the sink.
    pub(super) rows: usize,
    /// Why the run must stop at the next step: the sink refused a row.
    pub(super) stop: Option<SimulationError>,
}

pub(super) struct Recorder<'e> {
    pub(super) eqs: &'e StateEquations,
    pub(super) outputs: &'e [Output],
    pub(super) grid: Grid,
    pub(super) sink: &'e mut dyn RowSink,
    pub(super) interrupt: Option<&'e AtomicBool>,
    pub(super) wants_steps: bool,
    /// The segment ends at an event: its last step is handed on after the switch (as the
    /// output row at an event time is), not before.
    pub(super) event_at: Option<f64>,
    pub(super) buf: Vec<f64>,
    /// What a row and a step evaluate.
    pub(super) reads: &'e Reads,
    pub(super) p: Progress,
    /// The energy audit fed after every accepted step ([`super::simulate_audited`]), if any.
    pub(super) audit: Option<&'e mut crate::energy::EnergyAudit>,
}

impl Recorder<'_> {
    /// `t` and the outputs at (t, x) into `buf`: every output for a row, those the sink
    /// reads for a step (the others NaN). Only the stages they need are evaluated.
    fn values(&mut self, t: f64, x: &[f64], step: bool) {
        let (eqs, reads) = (self.eqs, self.reads);
        eqs.evaluate_only(if step { &reads.steps } else { &reads.rows }, t, x);
        self.buf.clear();
        self.buf.push(t);
        self.buf
            .extend(self.outputs.iter().enumerate().map(|(k, o)| {
                if step && !reads.step_columns[k] {
                    f64::NAN
                } else {
                    eqs.read(o.probe, t, x)
                }
            }));
    }
    /// The row of the pending grid time `t`; after a refused row, rows are skipped.
    pub(super) fn record(&mut self, t: f64, x: &[f64]) {
        self.p.next += 1;
        if self.p.stop.is_some() {
            return;
        }
        self.values(t, x, false);
        match self.sink.row(&self.buf) {
            Ok(()) => self.p.rows += 1,
            Err(message) => self.p.stop = Some(SimulationError::Output { t, message }),
        }
    }
    pub(super) fn pending(&self) -> Option<f64> {
        self.grid.at(self.p.next)
    }
    /// Every accepted step: watched minima, and whether the run must stop (a refused row, or
    /// the interruption flag). The step's outputs follow its rows ([`Self::step_done`]).
    pub(super) fn accepted(&mut self, t: f64, x: &[f64]) -> Result<(), SimulationError> {
        watch(&mut self.p.watchers, t, x);
        self.should_stop(t)
    }
    /// Every accepted step, after its rows: the sink's per-step values, if it wants them
    /// (those of a step onto an event are handed on after the switch).
    pub(super) fn step_done(&mut self, t: f64, x: &[f64]) {
        if self.wants_steps && !self.event_at.is_some_and(|te| same_time(te, t)) {
            self.step_values(t, x);
        }
    }
    /// Hand the outputs at (t, x) to the sink as a step.
    pub(super) fn step_values(&mut self, t: f64, x: &[f64]) {
        self.values(t, x, true);
        self.sink.step(&self.buf);
    }
    pub(super) fn should_stop(&mut self, t: f64) -> Result<(), SimulationError> {
        if let Some(e) = self.p.stop.take() {
            return Err(e);
        }
        if self.interrupt.is_some_and(|f| f.load(Ordering::Relaxed)) {
            return Err(SimulationError::Interrupted { t });
        }
        Ok(())
    }
}

pub(super) fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-10 * (1.0 + a.abs().max(b.abs()))
}
