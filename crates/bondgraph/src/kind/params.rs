//! What a builder sees ([`Params`]) and what it may answer ([`BuildError`]).

use std::error::Error as StdError;
use std::fmt;

use super::composite::member_name;
use crate::{Param, ParamError};

/// One entry of a [`MatrixParam`] as a function of the inputs' values.
pub type MatrixEntry = Box<dyn Fn(&[f64]) -> f64>;

/// A matrix of expressions sharing one list of signal inputs (an MTF's modulus).
pub struct MatrixParam {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// The signals read, in the order the entries receive them.
    pub inputs: Vec<String>,
    /// Entry `i·cols + j` as a function of the inputs' values.
    pub entries: Vec<MatrixEntry>,
}

impl fmt::Debug for MatrixParam {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MatrixParam")
            .field("rows", &self.rows)
            .field("cols", &self.cols)
            .field("inputs", &self.inputs)
            .finish_non_exhaustive()
    }
}

/// An element's parameters as its builder reads them, by their declared names.
///
/// The reader (the model loader, or a test) knows the kind's declarations: an absent
/// parameter takes its declared default, a value outside the declared range is refused
/// before the builder sees it, and keys the declaration does not list never reach the
/// builder. Asking for a name the kind did not declare is a programming error, answered
/// with a [`BuildErrorKind::Undeclared`] error.
pub trait Params {
    /// The instance's name in the model (`"cyl1"`).
    fn name(&self) -> &str;
    /// The kind's name (`"hydraulics.cylinder"`).
    fn kind(&self) -> &str;
    /// Whether the model gave `key` (defaults do not count).
    fn has(&self, key: &str) -> bool;
    /// A constant number (the declared default when absent).
    fn number(&self, key: &str) -> Result<f64, BuildError>;
    /// A constant number, `None` when absent and declared [`super::Default::Optional`].
    fn optional(&self, key: &str) -> Result<Option<f64>, BuildError>;
    /// A number that may read signals and time.
    fn modulated(&self, key: &str) -> Result<Param, BuildError>;
    /// A whole number.
    fn count(&self, key: &str) -> Result<usize, BuildError>;
    /// A signal name.
    fn signal(&self, key: &str) -> Result<String, BuildError>;
    /// A flag.
    fn flag(&self, key: &str) -> Result<bool, BuildError>;
    /// One of the declared words.
    fn word(&self, key: &str) -> Result<String, BuildError>;
    /// A list of constant numbers (empty when absent and optional).
    fn vector(&self, key: &str) -> Result<Vec<f64>, BuildError>;
    /// A matrix of expressions.
    fn matrix(&self, key: &str) -> Result<MatrixParam, BuildError>;
    /// A prescribed motion: x(t) with exact ẋ, ẍ ([`crate::Motion`]), from an expression of
    /// time (declared as a modulated parameter). The default reads a constant; the model
    /// loader compiles expressions of `t`, parameters and inputs with known derivatives.
    fn motion(&self, key: &str) -> Result<crate::Motion, BuildError> {
        self.number(key).map(crate::Motion::Const)
    }
    /// A nested table, `None` when absent.
    fn table(&self, key: &str) -> Result<Option<Box<dyn Params + '_>>, BuildError>;
    /// A list of nested tables (empty when absent).
    fn tables(&self, key: &str) -> Result<Vec<Box<dyn Params + '_>>, BuildError>;

    /// The global name of a composite member: `<instance>_<local>` ([`member_name`]).
    fn member(&self, local: &str) -> String {
        member_name(self.name(), local)
    }
}

/// What went wrong while building a kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildErrorKind {
    /// A required parameter is absent.
    Missing,
    /// A key the kind does not declare.
    Unknown,
    /// A value outside its range, of the wrong type, or not finite.
    Invalid,
    /// Parameters that exclude each other, or one that needs another.
    Conflict,
    /// A value with a unit of the wrong kind (`"3 m"` for a pressure).
    WrongUnit,
    /// The builder asked for a parameter its kind does not declare (a bug in the kind).
    Undeclared,
}

/// A kind that cannot be built: which parameter, what is wrong, and how to fix it.
#[derive(Debug)]
pub struct BuildError {
    /// What went wrong.
    pub kind: BuildErrorKind,
    /// The parameter, as a path for nested tables (`links[2].length`); `None` for the
    /// element as a whole.
    pub param: Option<String>,
    /// One sentence.
    pub message: String,
    /// How to fix it.
    pub hint: Option<String>,
    source: Option<Box<dyn StdError + Send + Sync>>,
}

impl BuildError {
    /// An error of `kind` about `param`.
    #[must_use]
    pub fn new(kind: BuildErrorKind, param: Option<&str>, message: impl Into<String>) -> Self {
        Self {
            kind,
            param: param.map(str::to_owned),
            message: message.into(),
            hint: None,
            source: None,
        }
    }
    /// A bad value of `param`.
    #[must_use]
    pub fn invalid(param: &str, message: impl Into<String>) -> Self {
        Self::new(BuildErrorKind::Invalid, Some(param), message)
    }
    /// `param` conflicts with the others (or needs one that is absent).
    #[must_use]
    pub fn conflict(param: &str, message: impl Into<String>) -> Self {
        Self::new(BuildErrorKind::Conflict, Some(param), message)
    }
    /// A required `param` is absent.
    #[must_use]
    pub fn missing(param: &str, message: impl Into<String>) -> Self {
        Self::new(BuildErrorKind::Missing, Some(param), message)
    }
    /// With a hint.
    #[must_use]
    pub fn hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }
    /// With the error that caused it.
    #[must_use]
    pub fn caused_by(mut self, source: impl StdError + Send + Sync + 'static) -> Self {
        self.source = Some(Box::new(source));
        self
    }
    /// Prefix the parameter path with `prefix` (a nested table's place: `links[2]`).
    #[must_use]
    pub fn within(mut self, prefix: &str) -> Self {
        self.param = Some(match self.param.take() {
            Some(p) => format!("{prefix}.{p}"),
            None => prefix.to_owned(),
        });
        self
    }
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl StdError for BuildError {
    fn source(&self) -> Option<&(dyn StdError + 'static)> {
        self.source
            .as_deref()
            .map(|e| e as &(dyn StdError + 'static))
    }
}

impl From<ParamError> for BuildError {
    fn from(e: ParamError) -> Self {
        let param = match &e {
            ParamError::OutOfRange { param, .. } | ParamError::Shape { param, .. } => param.clone(),
        };
        Self {
            kind: BuildErrorKind::Invalid,
            param: Some(param),
            message: e.to_string(),
            hint: None,
            source: Some(Box::new(e)),
        }
    }
}

impl From<crate::Error> for BuildError {
    fn from(e: crate::Error) -> Self {
        match e {
            crate::Error::Param(p) => p.into(),
            other => Self {
                kind: BuildErrorKind::Invalid,
                param: None,
                message: other.to_string(),
                hint: None,
                source: Some(Box::new(other)),
            },
        }
    }
}
