//! `[simulation]`: times, tolerances and the solver, into [`Settings`]. [`solver`] is the
//! one reading of a solver name, for the file, `--set simulation.solver=…` and the CLI's
//! `--solver` alike.

use bondgraph::{Method, Settings, SimulationError};
use toml::Spanned;

use super::parse::SimulationSpec;
use super::source::Source;
use crate::error::{clip, ErrorKind, ModelError};

/// A solver name nobody knows.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown solver `{name}`")]
pub struct UnknownSolver {
    /// The name given (cut to [`crate::error::MAX_ECHO`] characters).
    pub name: String,
}

impl UnknownSolver {
    /// The solvers there are.
    #[must_use]
    pub fn hint(&self) -> String {
        format!("solvers are {}", Method::names())
    }
}

/// The integration method called `name` (`radau5`, `bdf`, `tr-bdf2`, …; case and `_` for
/// `-` do not matter).
///
/// # Errors
/// [`UnknownSolver`], whose [`hint`](UnknownSolver::hint) lists the methods.
pub fn solver(name: &str) -> Result<Method, UnknownSolver> {
    Method::parse(name).ok_or_else(|| UnknownSolver { name: clip(name) })
}

/// The settings `[simulation]` gives (defaults for what it leaves out); problems go to
/// `problems`, each at its key.
pub(super) fn read(
    sim: &SimulationSpec,
    source: &Source,
    problems: &mut Vec<ModelError>,
) -> Settings {
    let before = problems.len();
    let mut settings = Settings::default();
    let mut num = |v: &Option<Spanned<f64>>, default: f64, key: &str| -> f64 {
        match v {
            None => default,
            Some(s) if s.get_ref().is_finite() => *s.get_ref(),
            Some(s) => {
                problems.push(source.err(
                    ErrorKind::Settings,
                    Some(&s.span()),
                    format!("[simulation] {key} must be finite"),
                ));
                default
            }
        }
    };
    settings.t_start = num(&sim.t_start, 0.0, "t_start");
    settings.t_end = num(&sim.t_end, 1.0, "t_end");
    settings.dt_out = num(
        &sim.dt_out,
        (settings.t_end - settings.t_start) / 100.0,
        "dt_out",
    );
    settings.rtol = num(&sim.rtol, 1e-6, "rtol");
    settings.atol = num(&sim.atol, 1e-8, "atol");
    if let Some(s) = &sim.solver {
        match solver(s.get_ref()) {
            Ok(m) => settings.method = m,
            Err(e) => problems.push(
                source
                    .err(ErrorKind::Settings, Some(&s.span()), e.to_string())
                    .hint(e.hint())
                    .with_source(e),
            ),
        }
    }
    if let Some(s) = &sim.linear_algebra {
        match bondgraph::radau::LinearAlgebra::from_name(s.get_ref()) {
            Some(la) => settings.linear_algebra = la,
            None => problems.push(
                source
                    .err(
                        ErrorKind::Settings,
                        Some(&s.span()),
                        format!("[simulation] unknown linear_algebra `{}`", s.get_ref()),
                    )
                    .hint("linear_algebra is \"dense\", \"sparse\" or \"auto\" (the default: sparse for large, sparse Jacobians)"),
            ),
        }
    }
    if problems.len() > before {
        return settings;
    }
    if let Err(e) = settings.validate() {
        problems.push(invalid(sim, source, e));
    }
    settings
}

/// An invalid setting at its key.
fn invalid(sim: &SimulationSpec, source: &Source, e: SimulationError) -> ModelError {
    let span_of = |v: &Option<Spanned<f64>>| v.as_ref().map(Spanned::span);
    let span = match &e {
        SimulationError::InvalidSetting { setting, .. } => match *setting {
            "dt_out" => span_of(&sim.dt_out),
            "rtol" => span_of(&sim.rtol),
            "atol" => span_of(&sim.atol),
            _ => span_of(&sim.t_end).or_else(|| span_of(&sim.t_start)),
        },
        _ => None,
    };
    let hint = e
        .hint()
        .unwrap_or_else(|| "t_start < t_end, dt_out > 0, 0 < rtol < 1, atol > 0".to_owned());
    source
        .err(
            ErrorKind::Settings,
            span.as_ref(),
            format!("[simulation] {}", e.message()),
        )
        .hint(hint)
        .with_source(e)
}
