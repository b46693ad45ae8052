//! Signal function `signal`: y = g(t, signals), stateless (a set-point profile, a sensor
//! combination, a gain).

use crate::element::{CausalRule, Element, Io, Param, Ports, SignalSpec};

/// A signal block computing one scalar output from time and scalar signals.
#[derive(Debug)]
pub struct SignalFunction {
    law: Param,
}

impl SignalFunction {
    /// A block whose output `out` is `law`.
    pub fn new(law: impl Into<Param>) -> Self {
        Self { law: law.into() }
    }
}

impl Element for SignalFunction {
    fn kind(&self) -> &str {
        "signal"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.law.signal_inputs()
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("out")]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let y = self.law.value(io, 0);
        io.set_y(0, 0, y);
    }
}
