//! Why a steady state could not be found, and how its residuals are shown.

/// Why a steady state could not be found.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EquilibriumError {
    /// The number of unknowns differs from the number of conditions.
    #[error("{} unknowns ({}) but {} conditions ({}): name as many conditions as unknowns", unknowns.len(), unknowns.join(", "), conditions.len(), conditions.join(", "))]
    CountMismatch {
        /// The unknown states.
        unknowns: Vec<String>,
        /// The conditions.
        conditions: Vec<String>,
    },
    /// A state or condition index is out of range, or an unknown is named twice.
    #[error("invalid steady-state request: {0}")]
    Invalid(String),
    /// A condition depends on none of the unknowns at the start.
    #[error("the condition `{condition}` (residual {residual:.3e}) depends on none of the unknowns {} at the start: name an unknown that moves it", unknowns.join(", "))]
    Unaffected {
        /// The condition.
        condition: String,
        /// Its residual at the start.
        residual: f64,
        /// The unknown states.
        unknowns: Vec<String>,
    },
    /// The conditions do not determine the unknowns.
    #[error("singular system: the conditions do not determine the unknowns {} (scaled Jacobian rank-deficient, smallest/largest singular value {ratio:.1e}); largest residuals: {}", unknowns.join(", "), show(residuals))]
    Singular {
        /// The unknowns of the null direction, largest share first.
        unknowns: Vec<String>,
        /// σ_min/σ_max of the scaled Jacobian.
        ratio: f64,
        /// The largest residuals (condition, residual, scaled).
        residuals: Vec<(String, f64, f64)>,
    },
    /// Newton's method could not reduce the residuals: no equilibrium near the start.
    #[error("no equilibrium found for the unknowns {} after {iterations} Newton iterations; largest residuals: {}", unknowns.join(", "), show(residuals))]
    NoEquilibrium {
        /// The unknown states.
        unknowns: Vec<String>,
        /// Iterations taken.
        iterations: usize,
        /// The largest residuals (condition, residual, scaled).
        residuals: Vec<(String, f64, f64)>,
    },
}

fn show(r: &[(String, f64, f64)]) -> String {
    r.iter()
        .map(|(n, v, s)| format!("{n}: {v:.3e} (scaled {s:.1e})"))
        .collect::<Vec<_>>()
        .join("; ")
}
