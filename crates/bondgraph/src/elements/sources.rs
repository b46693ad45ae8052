//! Sources `Se` and `Sf`: impose an effort or a flow, fixed causality.
//!
//! The value may be constant or modulated by time and signals ([`Param`]). On a multibond
//! every component gets the same value. With power-in positive, a source delivering power
//! has `e·f_in < 0`; draw its bond pointing away from it.

use crate::bond::PortCausality as Pc;
use crate::element::{CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot, Stage};
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

/// Effort source `Se`: e = e_s(t, signals) on every component.
#[derive(Debug)]
pub struct EffortSource {
    value: Param,
}

impl EffortSource {
    /// A source of the given effort.
    pub fn new(value: impl Into<Param>) -> Self {
        Self {
            value: value.into(),
        }
    }
}

impl Element for EffortSource {
    fn kind(&self) -> &str {
        "Se"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::any_dim("1")])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![Pc::EffortOut])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.value.signal_inputs()
    }
    fn stages(&self, causality: &[Pc]) -> Vec<Stage> {
        // A source's output depends on time and signals only, never on its port.
        Stage::from_states(causality, self.value.n_inputs(), 0)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let v = self.value.value(io, 0);
        for k in 0..io.dim(0) {
            io.set_e(0, k, v);
        }
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        for k in 0..io.dim(0) {
            let row = jac.row(Slot::Effort(0), k);
            self.value
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), d));
        }
        true
    }
}

/// Flow source `Sf`: delivers the flow f_s(t, signals), i.e. f_in = −f_s. With its bond drawn
/// pointing away from the source (the usual way), the bond's flow is `f_s`.
#[derive(Debug)]
pub struct FlowSource {
    value: Param,
}

impl FlowSource {
    /// A source delivering the given flow along its outgoing bond.
    pub fn new(value: impl Into<Param>) -> Self {
        Self {
            value: value.into(),
        }
    }
}

impl Element for FlowSource {
    fn kind(&self) -> &str {
        "Sf"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::any_dim("1")])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![Pc::FlowOut])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.value.signal_inputs()
    }
    fn stages(&self, causality: &[Pc]) -> Vec<Stage> {
        // A source's output depends on time and signals only, never on its port.
        Stage::from_states(causality, self.value.n_inputs(), 0)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        // The value is the flow *delivered* along the bond: the flow out of the source.
        let v = self.value.value(io, 0);
        for k in 0..io.dim(0) {
            io.set_f_in(0, k, -v);
        }
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        for k in 0..io.dim(0) {
            let row = jac.row(Slot::Flow(0), k);
            self.value
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), -d));
        }
        true
    }
}

/// Kind `Se`: `e = e(t, signals)`.
pub const SE: KindDecl = KindDecl::element(
    "Se",
    "effort source: e = e(t, signals)",
    &[ParamDecl::modulated(
        "e",
        "",
        "effort imposed (may read signals and t)",
    )],
    |p| Ok(Box::new(EffortSource::new(p.modulated("e")?))),
)
.example("e = 1.0");

/// Kind `Sf`: `f = f(t, signals)`.
pub const SF: KindDecl = KindDecl::element(
    "Sf",
    "flow source: delivers f = f(t, signals)",
    &[ParamDecl::modulated(
        "f",
        "",
        "flow delivered (may read signals and t)",
    )],
    |p| Ok(Box::new(FlowSource::new(p.modulated("f")?))),
)
.example("f = 1.0");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences() {
        let law = || Param::modulated(vec!["a".into(), "b".into()], |t, u| u[0] * u[1].sin() + t);
        let se = EffortSource::new(law());
        let sf = FlowSource::new(law());
        // e, f_in, a, b
        let point = [0.0, 0.0, 1.5, 0.7];
        assert_eq!(
            check_partials(&se, &[(1, -1.0, Pc::EffortOut)], &point),
            Ok(1)
        );
        assert_eq!(
            check_partials(&sf, &[(1, -1.0, Pc::FlowOut)], &point),
            Ok(1)
        );
        assert_eq!(
            check_partials(
                &EffortSource::new(3.0),
                &[(1, 1.0, Pc::EffortOut)],
                &[0.0, 0.0]
            ),
            Ok(1)
        );
    }
}
