//! Signal function `signal`: y = g(t, signals), stateless (a set-point profile, a sensor
//! combination, a gain).

use crate::element::{CausalRule, Element, Io, Param, Ports, SignalSpec, Slot};
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

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
    /// The law is a closure: its partials are central differences of the law alone
    /// ([`Param::partials`]), cheaper than re-running the stage.
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let row = jac.row(Slot::Output(0), 0);
        self.law
            .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), d));
        true
    }
}

/// Kind `signal`: `out = value(t, parameters, signals)`.
pub const KIND: KindDecl = KindDecl::element(
    "signal",
    "signal block: out = value(t, parameters, signals)",
    &[ParamDecl::modulated(
        "value",
        "",
        "expression of t, parameters and signals",
    )],
    |p| Ok(Box::new(SignalFunction::new(p.modulated("value")?))),
)
.example("value = \"sin(t)\"");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences() {
        let f = SignalFunction::new(Param::modulated(vec!["a".into(), "b".into()], |_, u| {
            u[0].atan2(u[1])
        }));
        // a, b
        assert_eq!(check_partials(&f, &[], &[0.4, -1.3]), Ok(1));
    }
}
