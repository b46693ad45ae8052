//! First-order lag `lag`: τ·dy/dt = u − y (a spool's dynamics, a low-pass filter).
//!
//! A signal block: no ports, one state `y`, one input `u`, one output `y` (the state, so
//! readers never wait for the input). Energy-free bookkeeping, not a storage element.

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Ports, SignalSpec, Slot, Stage, StateSpec};
use crate::error::ParamError;
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

/// First-order lag with time constant `tau` (s, > 0) reading the signal `input`.
#[derive(Debug)]
pub struct Lag {
    input: String,
    tau: f64,
    y0: f64,
}

impl Lag {
    /// A lag reading signal `input` with time constant `tau` and initial output `y0`.
    pub fn new(input: &str, tau: f64, y0: f64) -> Result<Self, ParamError> {
        ParamError::positive("tau", tau)?;
        ParamError::finite("y0", y0)?;
        Ok(Self {
            input: input.to_owned(),
            tau,
            y0,
        })
    }
}

impl Element for Lag {
    fn kind(&self) -> &str {
        "lag"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("y", self.y0)]
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar(&self.input)]
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("out")]
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, 0, 1)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let y = io.states()[0];
        io.set_y(0, 0, y);
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        dx[0] = (io.u(0) - io.states()[0]) / self.tau;
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        jac.set(jac.row(Slot::Output(0), 0), jac.state_col(0), 1.0);
        true
    }
    fn derivative_partials(&self, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let row = jac.derivative_row(0);
        jac.set(row, jac.input_col(0, 0), 1.0 / self.tau);
        jac.set(row, jac.state_col(0), -1.0 / self.tau);
        true
    }
}

/// Kind `lag`: `τ·dy/dt = u − y`.
pub const KIND: KindDecl = KindDecl::element(
    "lag",
    "first-order lag: tau·dy/dt = input − y",
    &[
        ParamDecl::signal("input", "", "signal to follow, e.g. \"ctrl.out\""),
        ParamDecl::number("tau", "s", "time constant").positive(),
        ParamDecl::number("y0", "", "initial output").default(0.0),
    ],
    |p| {
        Ok(Box::new(Lag::new(
            &p.signal("input")?,
            p.number("tau")?,
            p.number("y0")?,
        )?))
    },
)
.example("input = \"t\", tau = 0.1");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences() {
        let lag = Lag::new("u", 0.1, 0.0).unwrap();
        // u, y
        assert_eq!(check_partials(&lag, &[], &[0.7, -0.2]), Ok(2));
    }

    #[test]
    fn rejects_non_positive_time_constant() {
        assert!(Lag::new("u", 0.0, 0.0).is_err());
        assert!(Lag::new("u", -0.1, 0.0).is_err());
        assert!(Lag::new("u", 0.1, f64::NAN).is_err());
    }
}
