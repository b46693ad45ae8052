//! Typed errors of the bond-graph core. Each variant carries the culprit (element, bond,
//! time) and, where one helps, a hint as data (`hint()`, apart from `message()`); `Display`
//! writes both, `message; hint: hint`.

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
///
/// [`message`](Self::message) says what is wrong, [`hint`](Self::hint) what to do about it
/// (as data: a caller that shows hints apart takes them from there); `Display` writes
/// `message; hint: hint`.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum GraphError {
    /// Two elements share a name.
    DuplicateName {
        /// The name.
        name: String,
    },
    /// A port index or name does not exist.
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
    PortInUse {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// Port name.
        port: String,
    },
    /// An element has no free port left for another bond.
    NoFreePort {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// Number of ports.
        n_ports: usize,
    },
    /// A port has no bond.
    Unconnected {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// Port name.
        port: String,
    },
    /// A junction with no bonds.
    EmptyJunction {
        /// Element name.
        element: String,
    },
    /// Dimensions disagree.
    DimensionMismatch {
        /// Element name.
        element: String,
        /// What disagrees.
        message: String,
    },
    /// A signal name does not resolve.
    UnknownSignal {
        /// Reading element.
        element: String,
        /// Signal asked for.
        signal: String,
        /// Suggestions.
        hint: String,
    },
    /// A signal has the wrong dimension.
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
    UnknownElement {
        /// The name.
        name: String,
    },
    /// An input named (or numbered) in an API call does not exist.
    UnknownInput {
        /// The name (or `#index`).
        name: String,
        /// The inputs there are, or the near miss.
        hint: String,
    },
    /// A replacement element (scheduled event) does not have the shape of the original.
    Replacement {
        /// Element name.
        element: String,
        /// What differs.
        message: String,
        /// What to do, if something can be done.
        hint: Option<String>,
    },
    /// An element's stages do not compute what its causality requires (a bug in that element).
    Contract {
        /// Element name.
        element: String,
        /// Element kind.
        kind: String,
        /// What is wrong.
        message: String,
    },
}

impl GraphError {
    /// What is wrong, without the hint.
    #[must_use]
    pub fn message(&self) -> String {
        match self {
            Self::DuplicateName { name } => format!("element name `{name}` is used twice"),
            Self::NoSuchPort {
                element,
                kind,
                port,
                available,
            } => format!(
                "element `{element}` ({kind}) has no port `{port}`; its ports are: {available}"
            ),
            Self::PortInUse {
                element,
                kind,
                port,
            } => format!("port `{port}` of element `{element}` ({kind}) already has a bond"),
            Self::NoFreePort {
                element,
                kind,
                n_ports,
            } => format!(
                "element `{element}` ({kind}) has {n_ports} port(s), all already bonded"
            ),
            Self::Unconnected {
                element,
                kind,
                port,
            } => format!("port `{port}` of element `{element}` ({kind}) is not connected"),
            Self::EmptyJunction { element } => format!("junction `{element}` has no bonds"),
            Self::DimensionMismatch { element, message } => {
                format!("dimension mismatch at `{element}`: {message}")
            }
            Self::UnknownSignal {
                element, signal, ..
            } => format!("element `{element}` reads signal `{signal}`, which does not exist"),
            Self::SignalDimension {
                element,
                signal,
                expected,
                found,
            } => format!(
                "element `{element}` reads signal `{signal}` of dimension {found}, but needs {expected}"
            ),
            Self::UnknownElement { name } => format!("no element named `{name}`"),
            Self::UnknownInput { name, .. } => format!("the model has no input `{name}`"),
            Self::Replacement {
                element, message, ..
            } => format!("element `{element}` cannot be replaced: {message}"),
            Self::Contract {
                element,
                kind,
                message,
            } => format!("element `{element}` ({kind}) breaks the Element contract: {message}"),
        }
    }

    /// What to do about it, where the core knows.
    #[must_use]
    pub fn hint(&self) -> Option<String> {
        let h = match self {
            Self::DuplicateName { .. } => "names must be unique",
            Self::PortInUse { .. } => "connect several bonds through a 0- or 1-junction",
            Self::NoFreePort { .. } => "connect several bonds through a junction",
            Self::Unconnected { .. } => "every port of an element needs exactly one bond",
            Self::EmptyJunction { .. } => "remove it or connect it",
            Self::UnknownSignal { hint, .. } | Self::UnknownInput { hint, .. } => hint,
            Self::Replacement { hint, .. } => return hint.clone(),
            _ => return None,
        };
        Some(h.to_owned())
    }
}

/// `message; hint: hint`, the text of an error that is shown whole.
fn message_and_hint(
    f: &mut std::fmt::Formatter<'_>,
    message: &str,
    hint: Option<String>,
) -> std::fmt::Result {
    f.write_str(message)?;
    match hint {
        Some(h) => write!(f, "; hint: {h}"),
        None => Ok(()),
    }
}

impl std::fmt::Display for GraphError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        message_and_hint(f, &self.message(), self.hint())
    }
}

/// Causality assignment or equation ordering failed. `Display` writes `message; hint: hint`
/// ([`message`](Self::message), [`hint`](Self::hint)).
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum CausalityError {
    /// A storage element would be in derivative causality.
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
    AlgebraicLoop {
        /// Elements in the loop.
        elements: Vec<String>,
        /// Bonds in the loop.
        bonds: Vec<String>,
        /// What to do.
        hint: String,
    },
}

impl CausalityError {
    /// What is wrong, without the hint.
    #[must_use]
    pub fn message(&self) -> String {
        match self {
            Self::Derivative {
                element,
                kind,
                bond,
                chain,
                ..
            } => format!(
                "derivative causality: {element} ({kind}) would be in derivative causality on bond {bond}; {chain}"
            ),
            Self::Conflict {
                element,
                kind,
                bond,
                chain,
                ..
            } => format!("causal conflict at {element} ({kind}) on bond {bond}; {chain}"),
            Self::AlgebraicLoop {
                elements, bonds, ..
            } => format!(
                "algebraic loop through elements [{}] and bonds [{}]",
                elements.join(", "),
                bonds.join(", ")
            ),
        }
    }

    /// What to do about it.
    #[must_use]
    pub fn hint(&self) -> Option<String> {
        match self {
            Self::Derivative { hint, .. }
            | Self::Conflict { hint, .. }
            | Self::AlgebraicLoop { hint, .. } => Some(hint.clone()),
        }
    }
}

impl std::fmt::Display for CausalityError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        message_and_hint(f, &self.message(), self.hint())
    }
}

/// A simulation stopped early or could not start. `Display` writes `message; hint: hint`
/// ([`message`](Self::message), [`hint`](Self::hint)).
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum SimulationError {
    /// The initial state does not have one value per state.
    InitialState {
        /// Values given.
        given: usize,
        /// States of the model.
        expected: usize,
    },
    /// The solver could not be set up for a segment between events.
    SolverSetup {
        /// The solver's message.
        message: String,
    },
    /// One setting is invalid.
    InvalidSetting {
        /// The setting (`t_end`, `dt_out`, `rtol`, `atol`).
        setting: &'static str,
        /// What is wrong.
        message: String,
        /// What to do, if more than the message says.
        hint: Option<&'static str>,
    },
    /// The solver failed.
    Solver {
        /// Time reached.
        t: f64,
        /// The solver's message.
        message: String,
        /// Where a non-finite value first appeared, if one did.
        culprit: String,
        /// What to do, where it is known.
        hint: Option<&'static str>,
    },
    /// A state became NaN or infinite.
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
        /// The element's advice ([`Limit::hint`](crate::element::Limit::hint)).
        hint: Option<String>,
    },
    /// The run was interrupted ([`Settings::interrupt`](crate::Settings::interrupt): SIGINT,
    /// SIGTERM) after the step that reached `t`.
    Interrupted {
        /// Time reached.
        t: f64,
    },
    /// The sink of the output rows refused one (a full disk, a closed file).
    Output {
        /// Time of the refused row.
        t: f64,
        /// Why.
        message: String,
    },
    /// A scheduled event could not be applied.
    Event {
        /// Event time.
        t: f64,
        /// Why.
        source: GraphError,
    },
}

impl SimulationError {
    /// What is wrong, without the hint.
    #[must_use]
    pub fn message(&self) -> String {
        match self {
            Self::InitialState { given, expected } => format!(
                "invalid simulation settings: initial state has {given} values, the model {expected} states"
            ),
            Self::SolverSetup { message } => format!("invalid simulation settings: {message}"),
            Self::InvalidSetting {
                setting, message, ..
            } => format!("invalid simulation setting `{setting}`: {message}"),
            Self::Solver {
                t,
                message,
                culprit,
                ..
            } => format!("solver failed at t = {t:.9} s: {message}{culprit}"),
            Self::NonFinite {
                t,
                state,
                element,
                value,
                culprit,
            } => format!(
                "state `{state}` of element `{element}` became {value} at t = {t:.9} s{culprit}"
            ),
            Self::LimitReached {
                t,
                state,
                element,
                which,
                limit,
                message,
                ..
            } => format!(
                "state `{state}` of element `{element}` reached its {which} limit {limit} at t = {t:.9} s: {message}"
            ),
            Self::Interrupted { t } => format!("interrupted at t = {t:.9} s"),
            Self::Output { t, message } => {
                format!("the output row at t = {t:.9} s could not be written: {message}")
            }
            Self::Event { t, source } => format!("event at t = {t} s: {}", source.message()),
        }
    }

    /// What to do about it, where it is known.
    #[must_use]
    pub fn hint(&self) -> Option<String> {
        match self {
            Self::InvalidSetting { hint, .. } | Self::Solver { hint, .. } => {
                hint.map(str::to_owned)
            }
            Self::NonFinite { element, .. } => Some(format!(
                "check parameters of `{element}` and the elements feeding it, or tighten tolerances"
            )),
            Self::LimitReached { hint, .. } => hint.clone(),
            Self::Event { source, .. } => source.hint(),
            _ => None,
        }
    }
}

impl std::fmt::Display for SimulationError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        message_and_hint(f, &self.message(), self.hint())
    }
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

impl Error {
    /// What is wrong, without the hint.
    #[must_use]
    pub fn message(&self) -> String {
        match self {
            Self::Param(e) => e.to_string(),
            Self::Graph(e) => e.message(),
            Self::Causality(e) => e.message(),
            Self::Simulation(e) => e.message(),
        }
    }

    /// What to do about it, where the core knows.
    #[must_use]
    pub fn hint(&self) -> Option<String> {
        match self {
            Self::Param(_) => None,
            Self::Graph(e) => e.hint(),
            Self::Causality(e) => e.hint(),
            Self::Simulation(e) => e.hint(),
        }
    }
}
