//! Typed errors of the manipulator crate: a bad parameter names itself and what it must be.

use thiserror::Error;

/// A manipulator description that cannot be built.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum ManipulatorError {
    /// A value outside its valid range.
    #[error("parameter `{param}` = {value} is invalid: it must be {requirement}")]
    Invalid {
        /// Parameter name (`links[1].length`).
        param: String,
        /// The value given.
        value: f64,
        /// What it must be.
        requirement: &'static str,
    },
    /// Lengths, indices or shapes that do not fit together.
    #[error("parameter `{param}`: {message}")]
    Shape {
        /// Parameter name.
        param: String,
        /// What is wrong.
        message: String,
    },
}

impl ManipulatorError {
    /// An out-of-range value.
    #[must_use]
    pub fn invalid(param: &str, value: f64, requirement: &'static str) -> Self {
        Self::Invalid {
            param: param.to_owned(),
            value,
            requirement,
        }
    }
    /// A shape or index problem.
    #[must_use]
    pub fn shape(param: &str, message: impl Into<String>) -> Self {
        Self::Shape {
            param: param.to_owned(),
            message: message.into(),
        }
    }
    /// Check `value` is finite and > 0.
    pub fn positive(param: &str, value: f64) -> Result<f64, Self> {
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(Self::invalid(param, value, "finite and > 0"))
        }
    }
    /// Check `value` is finite and ≥ 0.
    pub fn non_negative(param: &str, value: f64) -> Result<f64, Self> {
        if value.is_finite() && value >= 0.0 {
            Ok(value)
        } else {
            Err(Self::invalid(param, value, "finite and >= 0"))
        }
    }
    /// Check `value` is finite.
    pub fn finite(param: &str, value: f64) -> Result<f64, Self> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(Self::invalid(param, value, "finite"))
        }
    }
}

impl From<ManipulatorError> for bondgraph::ParamError {
    fn from(e: ManipulatorError) -> Self {
        match e {
            ManipulatorError::Invalid {
                param,
                value,
                requirement,
            } => Self::OutOfRange {
                param,
                value,
                requirement,
            },
            ManipulatorError::Shape { param, message } => Self::Shape { param, message },
        }
    }
}
