//! [`Motion`]: a prescribed function of time with its exact first and second derivatives
//! (a moving base, a position source). Interface as agreed with the sea-state work
//! (`/work/wt/API-sea.md`); the loader builds it from an expression in Taylor arithmetic.

use std::fmt;
use std::sync::Arc;

/// A prescribed motion `x(t)` with `ẋ`, `ẍ`.
#[derive(Clone)]
pub enum Motion {
    /// A constant (ẋ = ẍ = 0).
    Const(f64),
    /// `[x, ẋ, ẍ]` at t, exact.
    Law(Arc<dyn Fn(f64) -> [f64; 3] + Send + Sync>),
}

impl Motion {
    /// `[x, ẋ, ẍ]` at `t` (no allocation).
    #[must_use]
    #[inline]
    pub fn eval(&self, t: f64) -> [f64; 3] {
        match self {
            Self::Const(c) => [*c, 0.0, 0.0],
            Self::Law(f) => f(t),
        }
    }
    /// The value of a constant.
    #[must_use]
    pub fn constant(&self) -> Option<f64> {
        match self {
            Self::Const(c) => Some(*c),
            Self::Law(_) => None,
        }
    }
    /// Whether it never moves (a constant).
    #[must_use]
    pub fn is_still(&self) -> bool {
        matches!(self, Self::Const(_))
    }
}

impl From<f64> for Motion {
    fn from(v: f64) -> Self {
        Self::Const(v)
    }
}

impl fmt::Debug for Motion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Const(c) => write!(f, "Motion::Const({c})"),
            Self::Law(_) => f.write_str("Motion::Law(..)"),
        }
    }
}
