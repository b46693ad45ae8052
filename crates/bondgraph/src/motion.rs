//! A prescribed motion x(t) with its exact time derivatives ẋ(t), ẍ(t): what a position
//! source or a moving base needs from a position given as a function of time.
//!
//! Signals carry no time derivatives in the plan (expressions carry gradients with respect
//! to their signal inputs, not d/dt), so a [`Motion`] is a function of time alone: a
//! constant, or a law returning [x, ẋ, ẍ] at t. The model loader builds one from an
//! expression of `t`, parameters and inputs whose derivatives are known (a sea state, data
//! with `interp = "spline"`) by second-order Taylor arithmetic ([`Params::motion`]).
//!
//! [`Params::motion`]: crate::kind::Params::motion

use std::fmt;
use std::sync::Arc;

/// The law of a [`Motion`]: [x, ẋ, ẍ] at t.
pub type MotionLaw = Arc<dyn Fn(f64) -> [f64; 3] + Send + Sync>;

/// x(t), ẋ(t), ẍ(t) (see the module documentation).
#[derive(Clone)]
pub enum Motion {
    /// Standing still at a value.
    Const(f64),
    /// [x, ẋ, ẍ] = law(t), exact.
    Law(MotionLaw),
}

impl Motion {
    /// A motion from its law, `law(t) = [x, ẋ, ẍ]`.
    pub fn law(law: impl Fn(f64) -> [f64; 3] + Send + Sync + 'static) -> Self {
        Self::Law(Arc::new(law))
    }
    /// [x, ẋ, ẍ] at `t` (no allocation).
    #[inline]
    #[must_use]
    pub fn eval(&self, t: f64) -> [f64; 3] {
        match self {
            Self::Const(v) => [*v, 0.0, 0.0],
            Self::Law(f) => f(t),
        }
    }
    /// The value, if constant.
    #[must_use]
    pub fn constant(&self) -> Option<f64> {
        match self {
            Self::Const(v) => Some(*v),
            Self::Law(_) => None,
        }
    }
    /// Whether it stands still (a constant: ẋ = ẍ = 0 at every t).
    #[must_use]
    pub fn is_still(&self) -> bool {
        matches!(self, Self::Const(_))
    }
}

impl fmt::Debug for Motion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Const(v) => write!(f, "{v}"),
            Self::Law(_) => write!(f, "motion(t)"),
        }
    }
}

impl From<f64> for Motion {
    fn from(v: f64) -> Self {
        Self::Const(v)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::float_cmp)]
    use super::*;

    #[test]
    fn a_constant_stands_still_and_a_law_is_evaluated() {
        let c = Motion::from(2.0);
        assert_eq!(c.eval(5.0), [2.0, 0.0, 0.0]);
        assert!(c.is_still());
        let m = Motion::law(|t| [t * t, 2.0 * t, 2.0]);
        assert_eq!(m.eval(3.0), [9.0, 6.0, 2.0]);
        assert_eq!(m.constant(), None);
    }
}
