//! The moving base as a signal source: the base's position, roll and their exact
//! derivatives at the current time, and the apparent gravity in its axes
//! ([`base`](crate::base)). Reads nothing; the arm's members read its signals.

use bondgraph::{CausalRule, Element, Io, LocalJacobian, Ports, SignalSpec, Stage};

use crate::base::Base;

/// Outputs, in order.
pub const BASE_OUTPUTS: [&str; 11] = [
    "x", "y", "roll", "vx", "vy", "omega", "ax", "ay", "alpha", "field_x", "field_y",
];
/// Index of θ̇ among [`BASE_OUTPUTS`].
pub const OUT_OMEGA: usize = 5;
/// Index of θ̈.
pub const OUT_ALPHA: usize = 8;
/// Index of the apparent gravity's x component (y follows).
pub const OUT_FIELD: usize = 9;

/// The base's motion at time t (signals `x, y, roll, vx, vy, omega, ax, ay, alpha`, SI) and
/// the apparent gravity `field_x, field_y` (m/s², base axes).
#[derive(Debug)]
pub struct BaseMotion {
    base: Base,
    gravity: f64,
}

impl BaseMotion {
    /// The base `base` under gravity `gravity` (m/s², along −y inertial).
    #[must_use]
    pub fn new(base: Base, gravity: f64) -> Self {
        Self { base, gravity }
    }
}

impl Element for BaseMotion {
    fn kind(&self) -> &str {
        "manipulator.base"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        BASE_OUTPUTS.iter().map(|n| SignalSpec::scalar(n)).collect()
    }
    fn stages(&self, _: &[bondgraph::PortCausality]) -> Vec<Stage> {
        Stage::from_states(&[], 0, BASE_OUTPUTS.len())
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let b = self.base.at(io.time());
        let f = b.field(self.gravity);
        let v = [
            b.x[0], b.y[0], b.roll[0], b.x[1], b.y[1], b.roll[1], b.x[2], b.y[2], b.roll[2], f.x,
            f.y,
        ];
        for (k, x) in v.into_iter().enumerate() {
            io.set_y(k, 0, x);
        }
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, _: &mut LocalJacobian<'_>) -> bool {
        true // functions of time alone
    }
}
