//! Why the integrator stopped: typed errors carrying the time reached, with messages that
//! say what to try.

use thiserror::Error;

/// Why the integrator stopped. Each variant carries the time reached; the state there is
/// still readable with [`Radau5::y`](crate::radau::Radau5::y).
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum RadauError {
    /// An option is out of range.
    #[error("invalid Radau option `{option}`: {message}")]
    InvalidOption {
        /// The option.
        option: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A vector has the wrong length.
    #[error("{what} has {got} values but the system has {expected} states")]
    DimensionMismatch {
        /// Which vector.
        what: &'static str,
        /// The number of states.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// The state or f(t, y) has a NaN or infinity.
    #[error("{what} component {index} is not finite at t = {t}: check the equations there (division by zero, a root or logarithm of a negative value, overflow)")]
    NonFinite {
        /// Time.
        t: f64,
        /// Which component.
        index: usize,
        /// `"state"` or `"f(t, y)"`.
        what: &'static str,
    },
    /// The error test kept failing until the step size reached round-off.
    #[error("step size {h:e} too small at t = {t}: the error test keeps failing; the solution may blow up or jump here — check the equations near t, restart at a discontinuity, or loosen rtol/atol")]
    StepSizeTooSmall {
        /// Time reached.
        t: f64,
        /// The last step size tried.
        h: f64,
    },
    /// Newton kept failing until the step size reached round-off.
    #[error("Newton iteration failed down to step size {h:e} at t = {t}: check the Jacobian (sign, scaling, missing terms), whether f is continuous there, or whether the solution blows up")]
    NewtonDiverged {
        /// Time reached.
        t: f64,
        /// The last step size tried.
        h: f64,
    },
    /// The iteration matrix was singular five times in a row.
    #[error("iteration matrix singular at t = {t} (step size {h:e}): the Jacobian may hold NaN or infinity, or the equations may not define dy/dt")]
    SingularMatrix {
        /// Time reached.
        t: f64,
        /// The last step size tried.
        h: f64,
    },
    /// `step` was asked to go backwards or nowhere.
    #[error("t_stop = {t_stop} is not after t = {t}: the integrator steps forward only")]
    StopNotAhead {
        /// Current time.
        t: f64,
        /// The stop time given.
        t_stop: f64,
    },
    /// `interpolate` was asked for a time outside the last step.
    #[error("t = {t} is outside the last step [{t_prev}, {t_now}]: interpolate only within it, before taking the next step")]
    OutsideStep {
        /// Time asked for.
        t: f64,
        /// Start of the last step.
        t_prev: f64,
        /// End of the last step.
        t_now: f64,
    },
}
