//! The run: [`simulate`] (rows kept in memory) and [`simulate_into`] (rows to a sink),
//! segment by segment between events and the inputs' breakpoints.

use std::cell::RefCell;
use std::time::Instant;

use super::record::{same_time, Grid, Progress, Reads, Recorder};
use super::segment::run_segment;
use super::watch::{bounds, reports, watch, watchers};
use super::{check_in_memory, start_outcome, Event, Outcome, Output, RowSink, Settings};
use crate::equations::StateEquations;
use crate::error::SimulationError;

/// Run a simulation and keep its rows in memory (in `trajectory.rows`).
///
/// As [`simulate_into`] with a sink that collects; refused (the outcome's error, no rows) if
/// the rows would hold more than [`MAX_VALUES_IN_MEMORY`](super::MAX_VALUES_IN_MEMORY) values.
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
    let reads = Reads::new(eqs, outputs, &*sink);
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
            reads: &reads,
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
        // Rows due at the current time (after the events) — none where the equations are not
        // finite: the segment refuses to start there, and the row would be NaN.
        if rec.pending().is_some_and(|g| same_time(g, t)) && finite_at(rec.eqs, t, &x) {
            while rec.pending().is_some_and(|g| same_time(g, t)) {
                rec.record(t, &x);
            }
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
        let go_on = rec.accepted(tg, &[]);
        if go_on.is_ok() {
            rec.record(tg, &[]);
        }
        rec.step_done(tg, &[]);
        go_on.map_err(|e| (tg, Vec::new(), e))?;
    }
    Ok(Vec::new())
}

pub(super) type SegmentError = (f64, Vec<f64>, SimulationError);

/// Whether the equations are finite at (t, x) (always, without states: nothing to refuse).
fn finite_at(eqs: &StateEquations, t: f64, x: &[f64]) -> bool {
    if x.is_empty() {
        return true;
    }
    let mut dx = vec![0.0; x.len()];
    eqs.rhs(t, x, &mut dx);
    dx.iter().all(|v| v.is_finite())
}

pub(super) fn culprit(eqs: &StateEquations, bad: &RefCell<Option<(f64, Vec<f64>)>>) -> String {
    bad.borrow()
        .as_ref()
        .and_then(|(t, x)| {
            eqs.first_non_finite(*t, x)
                .map(|c| format!("; first non-finite value at t = {t:.9} s: {c}"))
        })
        .unwrap_or_default()
}
