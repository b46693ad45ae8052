//! Simulation settings: the method, the tolerances, the output grid's step, and the checks
//! that they make sense before any work.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

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
/// as they are computed ([`simulate_into`](super::simulate_into)), so the bound is a guard against a mistyped
/// `dt_out`, not a memory limit.
pub const MAX_OUTPUT_ROWS: f64 = 1e9;

/// Most values (rows × columns, `t` included) a run that keeps its rows in memory
/// ([`simulate`](super::simulate())) may hold: 5·10⁷ values are 400 MB.
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
        use crate::kind::units::short;
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
                    short(self.t_start),
                    short(self.t_end)
                ),
            );
        }
        if !(self.dt_out.is_finite() && self.dt_out > 0.0) {
            return bad(
                "dt_out",
                format!("must be finite and > 0, got {}", short(self.dt_out)),
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
                format!("must be in [{MIN_RTOL:e}, 1), got {}", short(self.rtol)),
            );
        }
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return bad(
                "atol",
                format!("must be finite and > 0, got {}", short(self.atol)),
            );
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
