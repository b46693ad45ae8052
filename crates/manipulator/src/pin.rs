//! Pins: attachment points of actuators and lumped masses (docs/knuckle-boom.md; the paper's Fig. 3).
//!
//! A pin is fixed in frame 0 (the crane base) or sits on the *deformed* axis of a link at
//! distance x along its chord, i.e. at `(x, w(x))` in the link's frame. Resolved on an arm
//! once ([`PinPoint`]), its position and generalized forces need no allocation.

use nalgebra::Vector2;

use crate::arm::{PlanarArm, Pose, Station};
use bondgraph::ParamError;

/// An attachment point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pin {
    /// Fixed in frame 0 at this position (m).
    Ground(Vector2<f64>),
    /// On link `link` (0-based) at distance `x` along its chord (m).
    Link {
        /// Link index, 0-based.
        link: usize,
        /// Distance along the chord (m).
        x: f64,
    },
}

impl Pin {
    /// A pin fixed in frame 0 at (x, y).
    #[must_use]
    pub fn ground(x: f64, y: f64) -> Self {
        Self::Ground(Vector2::new(x, y))
    }
    /// A pin on link `link` (0-based) at distance `x` along its chord.
    #[must_use]
    pub fn on_link(link: usize, x: f64) -> Self {
        Self::Link { link, x }
    }
}

/// A pin resolved on an arm ([`PlanarArm::resolve_pin`]): a ground point, or a station with
/// its mode values.
#[derive(Clone, Debug, PartialEq)]
pub enum PinPoint {
    /// Fixed in frame 0.
    Ground(Vector2<f64>),
    /// On a link's deformed axis.
    Station(Station),
}

impl PinPoint {
    /// The station, for a pin on a link.
    #[must_use]
    pub fn station(&self) -> Option<&Station> {
        match self {
            Self::Ground(_) => None,
            Self::Station(s) => Some(s),
        }
    }
}

impl PlanarArm {
    /// Check a pin lies on the arm (or is a finite ground point).
    pub fn check_pin(&self, pin: &Pin) -> Result<(), ParamError> {
        match *pin {
            Pin::Ground(p) => {
                ParamError::finite("pin.x", p.x)?;
                ParamError::finite("pin.y", p.y)?;
                Ok(())
            }
            Pin::Link { link, x } => self.station(link, x).map(|_| ()),
        }
    }

    /// Resolve `pin` on this arm (checks it lies on the arm).
    pub fn resolve_pin(&self, pin: &Pin) -> Result<PinPoint, ParamError> {
        self.check_pin(pin)?;
        match *pin {
            Pin::Ground(p) => Ok(PinPoint::Ground(p)),
            Pin::Link { link, x } => Ok(PinPoint::Station(self.station(link, x)?)),
        }
    }
}

impl Pose<'_> {
    /// Position of a pin in frame 0 (a pin on a link sits on its deformed axis).
    ///
    /// # Panics
    /// If the pin names a link the arm does not have ([`PlanarArm::check_pin`] first).
    #[must_use]
    pub fn pin_position(&self, pin: &Pin) -> Vector2<f64> {
        match *pin {
            Pin::Ground(p) => p,
            Pin::Link { link, x } => self.position(&self.arm().station_unchecked(link, x)),
        }
    }
    /// Position of a resolved pin in frame 0.
    #[must_use]
    pub fn pin_point_position(&self, pin: &PinPoint) -> Vector2<f64> {
        match pin {
            PinPoint::Ground(p) => *p,
            PinPoint::Station(s) => self.position(s),
        }
    }
    /// `out += (∂r/∂q)ᵀ f` for a force `f` (frame 0) at a resolved pin (zero on the ground).
    pub fn add_pin_force(&self, pin: &PinPoint, f: &Vector2<f64>, out: &mut [f64]) {
        if let PinPoint::Station(s) = pin {
            self.add_point_force(s, f, out);
        }
    }
}
