//! Pins: attachment points of actuators and lumped masses (design page, Fig. 3).
//!
//! A pin is fixed in frame 0 (the crane base) or sits on the *deformed* axis of a link at
//! distance x along its chord, i.e. at `(x, w(x))` in the link's frame.

use nalgebra::Vector2;

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
