//! Simulation: [`StateEquations`](crate::StateEquations) → [`Trajectory`], every method behind one interface.
//!
//! * Methods ([`Method`]): our Radau IIA of order 5 ([`crate::radau`], the default: L-stable,
//!   for stiff models with undamped or lightly damped fast modes), and diffsol's BDF (orders
//!   1–5), ESDIRK34, TR-BDF2 (implicit) and Tsit45 (explicit, for non-stiff checks). Each is a
//!   `Stepper` (`stepper.rs`): one accepted step at a time, dense output inside the last step,
//!   its work counters; one loop (`stepper::drive`) records rows, watches states, stops at a
//!   NaN, a limit, a stalled step or `max_steps`, for every method alike.
//! * The implicit methods use the exact Jacobian of the evaluation plan
//!   ([`StateEquations::jacobian`](crate::StateEquations::jacobian)): Radau asks for it directly; diffsol's Jacobian–vector
//!   products multiply by it, assembled once per (t, x) (`segment.rs`).
//! * Results are written at the output times `t0, t0 + Δ, …, t_end` by the method's dense
//!   interpolation; the solver steps onto every scheduled event time exactly, the event
//!   replaces elements (a parameter switch), and the solver restarts from there. It stops
//!   and restarts likewise at the breakpoints of the external inputs' series
//!   ([`StateEquations::next_breakpoint`](crate::StateEquations::next_breakpoint), unless turned off), each segment evaluating every
//!   series on one piece ([`StateEquations::begin_segment`](crate::StateEquations::begin_segment)). The output
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
//!
//! The files, in the order a run meets them: `settings.rs` ([`Method`], [`Settings`] and their
//! checks), `outcome.rs` (scheduled [`Event`]s in; the [`Outcome`], [`Trajectory`],
//! [`Statistics`], [`WatchReport`] out), `run.rs` ([`simulate`], [`simulate_into`]: the loop
//! over segments between events and breakpoints), `segment.rs` (one segment: diffsol's methods
//! and the dispatch to Radau), `radau.rs` (Radau as a stepper, limits by bisection),
//! `stepper.rs` (the `Stepper` interface and `drive`, the loop over accepted steps),
//! `record.rs` (output columns, [`RowSink`], the output grid, the recorder of rows and per-step
//! values), `watch.rs` (limits as root functions, watched minima), `stepping.rs`
//! ([`Simulation`], a run advanced call by call; its tests in `stepping/tests.rs`).
mod outcome;
mod radau;
mod record;
mod run;
mod segment;
mod settings;
mod stepper;
mod stepping;
mod watch;

pub use outcome::{Event, Outcome, Statistics, Trajectory, WatchReport};
pub use record::{Output, RowSink};
pub use run::{simulate, simulate_audited, simulate_into};
pub use settings::{
    check_in_memory, Method, Settings, MAX_OUTPUT_ROWS, MAX_VALUES_IN_MEMORY, MIN_RTOL,
};
pub use stepping::Simulation;

use outcome::start_outcome;
use record::{same_time, Grid, Progress, Reads, Recorder};
use run::{culprit, SegmentError};
use watch::{bounds, Bound};
