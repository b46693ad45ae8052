//! Typed errors of the bond-graph core. Each variant carries the culprit (element, bond,
//! time) and, where one helps, a hint; only the CLI flattens them into text.

use thiserror::Error;

/// A parameter given to an element constructor is not acceptable.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum ParamError {
    /// The value is outside the valid range.
    #[error("parameter `{param}` = {value} is invalid: it must be {requirement}")]
    OutOfRange {
        /// Parameter name.
        param: String,
        /// The value given.
        value: f64,
        /// What it must be ("finite and > 0").
        requirement: &'static str,
    },
    /// Lengths or dimensions do not match.
    #[error("parameter `{param}`: {message}")]
    Shape {
        /// Parameter name.
        param: String,
        /// What is wrong.
        message: String,
    },
}

impl ParamError {
    /// `param` = `value` is not `requirement` ("finite and > 0").
    #[must_use]
    pub fn invalid(param: &str, value: f64, requirement: &'static str) -> Self {
        Self::OutOfRange {
            param: param.to_owned(),
            value,
            requirement,
        }
    }
    /// Lengths, indices or shapes of `param` that do not fit together.
    #[must_use]
    pub fn shape(param: &str, message: impl Into<String>) -> Self {
        Self::Shape {
            param: param.to_owned(),
            message: message.into(),
        }
    }
    /// Check `value` is finite and `> 0`.
    pub fn positive(param: &str, value: f64) -> Result<f64, Self> {
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(Self::OutOfRange {
                param: param.into(),
                value,
                requirement: "finite and > 0",
            })
        }
    }
    /// Check `value` is finite and `>= 0`.
    pub fn non_negative(param: &str, value: f64) -> Result<f64, Self> {
        if value.is_finite() && value >= 0.0 {
            Ok(value)
        } else {
            Err(Self::OutOfRange {
                param: param.into(),
                value,
                requirement: "finite and >= 0",
            })
        }
    }
    /// Check `value` is finite.
    pub fn finite(param: &str, value: f64) -> Result<f64, Self> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(Self::OutOfRange {
                param: param.into(),
                value,
                requirement: "finite",
            })
        }
    }
    /// Check `value` is finite and non-zero.
    pub fn non_zero(param: &str, value: f64) -> Result<f64, Self> {
        if value.is_finite() && value != 0.0 {
            Ok(value)
        } else {
            Err(Self::OutOfRange {
                param: param.into(),
                value,
                requirement: "finite and non-zero",
            })
        }
    }
}

/// The graph's structure is inconsistent.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum GraphError {
    /// Two elements share a name.
    #[error("element name `{name}` is used twice; hint: names must be unique")]
    DuplicateName {
        /// The name.
        name: String,
    },
    /// A port index or name does not exist.
    #[error("element `{element}` ({kind}) has no port `{port}`; its ports are: {available}")]
    NoSuchPort {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// The port asked for.
        port: String,
        /// The ports it has.
        available: String,
    },
    /// A port already has a bond.
    #[error("port `{port}` of element `{element}` ({kind}) already has a bond; hint: connect several bonds through a 0- or 1-junction")]
    PortInUse {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// Port name.
        port: String,
    },
    /// An element has no free port left for another bond.
    #[error("element `{element}` ({kind}) has {n_ports} port(s), all already bonded; hint: connect several bonds through a junction")]
    NoFreePort {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// Number of ports.
        n_ports: usize,
    },
    /// A port has no bond.
    #[error("port `{port}` of element `{element}` ({kind}) is not connected; hint: every port of an element needs exactly one bond")]
    Unconnected {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// Port name.
        port: String,
    },
    /// A junction with no bonds.
    #[error("junction `{element}` has no bonds; hint: remove it or connect it")]
    EmptyJunction {
        /// Element name.
        element: String,
    },
    /// Dimensions disagree.
    #[error("dimension mismatch at `{element}`: {message}")]
    DimensionMismatch {
        /// Element name.
        element: String,
        /// What disagrees.
        message: String,
    },
    /// A signal name does not resolve.
    #[error("element `{element}` reads signal `{signal}`, which does not exist; hint: {hint}")]
    UnknownSignal {
        /// Reading element.
        element: String,
        /// Signal asked for.
        signal: String,
        /// Suggestions.
        hint: String,
    },
    /// A signal has the wrong dimension.
    #[error(
        "element `{element}` reads signal `{signal}` of dimension {found}, but needs {expected}"
    )]
    SignalDimension {
        /// Reading element.
        element: String,
        /// Signal name.
        signal: String,
        /// Expected dimension.
        expected: usize,
        /// Actual dimension.
        found: usize,
    },
    /// An element named in an API call does not exist.
    #[error("no element named `{name}`")]
    UnknownElement {
        /// The name.
        name: String,
    },
    /// A replacement element (scheduled event) does not have the shape of the original.
    #[error("element `{element}` cannot be replaced: {message}")]
    Replacement {
        /// Element name.
        element: String,
        /// What differs.
        message: String,
    },
    /// An element's stages do not compute what its causality requires (a bug in that element).
    #[error("element `{element}` ({kind}) breaks the Element contract: {message}")]
    Contract {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// What is wrong.
        message: String,
    },
}

/// Causality assignment or equation ordering failed.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum CausalityError {
    /// A storage element would be in derivative causality.
    #[error("derivative causality: {element} ({kind}) would be in derivative causality on bond {bond}; {chain}; hint: {hint}")]
    Derivative {
        /// The storage element.
        element: String,
        /// Its kind.
        kind: String,
        /// The bond.
        bond: String,
        /// How the causality reached it.
        chain: String,
        /// What to do.
        hint: String,
    },
    /// Two elements impose the same variable.
    #[error("causal conflict at {element} ({kind}) on bond {bond}; {chain}; hint: {hint}")]
    Conflict {
        /// Element where the conflict shows.
        element: String,
        /// Its kind.
        kind: String,
        /// The bond.
        bond: String,
        /// How the causality reached it.
        chain: String,
        /// What to do.
        hint: String,
    },
    /// The equations contain an algebraic loop.
    #[error("algebraic loop through elements [{}] and bonds [{}]; hint: {hint}", elements.join(", "), bonds.join(", "))]
    AlgebraicLoop {
        /// Elements in the loop.
        elements: Vec<String>,
        /// Bonds in the loop.
        bonds: Vec<String>,
        /// What to do.
        hint: String,
    },
}

/// A simulation stopped early or could not start.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum SimulationError {
    /// Settings are invalid.
    #[error("invalid simulation settings: {0}")]
    Settings(String),
    /// One setting is invalid.
    #[error("invalid simulation setting `{setting}`: {message}")]
    InvalidSetting {
        /// The setting (`t_end`, `dt_out`, `rtol`, `atol`).
        setting: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The solver failed.
    #[error("solver failed at t = {t:.9} s: {message}{culprit}")]
    Solver {
        /// Time reached.
        t: f64,
        /// The solver's message.
        message: String,
        /// Where a non-finite value first appeared, if one did.
        culprit: String,
    },
    /// A state became NaN or infinite.
    #[error("state `{state}` of element `{element}` became {value} at t = {t:.9} s{culprit}; hint: check parameters of `{element}` and the elements feeding it, or tighten tolerances")]
    NonFinite {
        /// Time.
        t: f64,
        /// State name.
        state: String,
        /// Element owning the state.
        element: String,
        /// The value (NaN or inf).
        value: f64,
        /// Where a non-finite value first appeared in the equations.
        culprit: String,
    },
    /// A state reached a bound its element set ([`Limit`](crate::element::Limit)).
    #[error("state `{state}` of element `{element}` reached its {which} limit {limit} at t = {t:.9} s: {message}")]
    LimitReached {
        /// Time of the crossing.
        t: f64,
        /// State name.
        state: String,
        /// Element owning the state.
        element: String,
        /// `lower` or `upper`.
        which: &'static str,
        /// The bound.
        limit: f64,
        /// The element's explanation.
        message: String,
    },
    /// The run was interrupted ([`Settings::interrupt`](crate::Settings::interrupt): SIGINT,
    /// SIGTERM) after the step that reached `t`.
    #[error("interrupted at t = {t:.9} s")]
    Interrupted {
        /// Time reached.
        t: f64,
    },
    /// The sink of the output rows refused one (a full disk, a closed file).
    #[error("the output row at t = {t:.9} s could not be written: {message}")]
    Output {
        /// Time of the refused row.
        t: f64,
        /// Why.
        message: String,
    },
    /// A scheduled event could not be applied.
    #[error("event at t = {t} s: {source}")]
    Event {
        /// Event time.
        t: f64,
        /// Why.
        source: GraphError,
    },
}

/// Any error of this crate.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// See [`ParamError`].
    #[error(transparent)]
    Param(#[from] ParamError),
    /// See [`GraphError`].
    #[error(transparent)]
    Graph(#[from] GraphError),
    /// See [`CausalityError`].
    #[error(transparent)]
    Causality(#[from] CausalityError),
    /// See [`SimulationError`].
    #[error(transparent)]
    Simulation(#[from] SimulationError),
}
