//! What a run is given besides its settings (scheduled [`Event`]s) and what it returns: the
//! [`Outcome`] with its rows ([`Trajectory`]), its solver work ([`Statistics`]) and the watched
//! states' minima ([`WatchReport`]).

use std::time::Duration;

use super::{Output, Settings};
use crate::bond::ElementId;
use crate::element::Element;
use crate::error::SimulationError;

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
    /// Exact Jacobians assembled by [`StateEquations::jacobian`](crate::StateEquations::jacobian) (one per new (t, x) at which
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
    /// The column names; the rows, when they are kept in memory ([`simulate`](super::simulate())).
    pub trajectory: Trajectory,
    /// Output rows delivered (to the sink of [`simulate_into`](super::simulate_into), or kept in `trajectory`).
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

/// An outcome with no rows yet.
pub(super) fn start_outcome(settings: &Settings, outputs: &[Output], x0: &[f64]) -> Outcome {
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
