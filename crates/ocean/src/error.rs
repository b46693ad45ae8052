//! What can go wrong reading sea-state inputs: a bad number or a bad RAO table.

use std::fmt;

/// A problem with a sea state's parameters or an RAO file, with the line (1-based) where
/// it is, if it is in a file, and a hint.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OceanError {
    /// 1-based line of the RAO file, if the problem is in one.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
    /// How to fix it (may be empty).
    pub hint: String,
}

impl OceanError {
    /// A problem not tied to a line.
    #[must_use]
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            line: None,
            message: message.into(),
            hint: String::new(),
        }
    }
    /// A problem at line `line` (1-based) of a file.
    #[must_use]
    pub fn at(line: usize, message: impl Into<String>) -> Self {
        Self {
            line: Some(line),
            ..Self::new(message)
        }
    }
    /// With a hint.
    #[must_use]
    pub fn hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = hint.into();
        self
    }
}

impl fmt::Display for OceanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(l) = self.line {
            write!(f, "line {l}: ")?;
        }
        write!(f, "{}", self.message)?;
        if !self.hint.is_empty() {
            write!(f, " (hint: {})", self.hint)?;
        }
        Ok(())
    }
}

impl std::error::Error for OceanError {}
