//! Transformer `TF` / modulated transformer `MTF`: e₁ = m·e₂, f_in₂ = −m·f_in₁.
//!
//! With the usual drawing (bond 1 into the TF, bond 2 out of it) this is the textbook
//! e₁ = m·e₂, f₂ = m·f₁. Power is conserved: e₁·f_in₁ + e₂·f_in₂ = 0. The modulus may depend
//! on time and signals (MTF). Causality: exactly one port sets its effort; the inverse
//! orientation (e₂ = e₁/m, f_in₁ = −f_in₂/m) needs m ≠ 0. Multibonds: component-wise.

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot, Stage};
use crate::error::ParamError;
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

/// Transformer with (possibly modulated) modulus `m` (dimensionless or with units e₁/e₂).
#[derive(Debug)]
pub struct Transformer {
    m: Param,
}

impl Transformer {
    /// A transformer; a constant `m` must be finite and non-zero.
    pub fn new(m: impl Into<Param>) -> Result<Self, ParamError> {
        let m = m.into();
        if let Some(v) = m.constant() {
            ParamError::non_zero("m", v)?;
        }
        Ok(Self { m })
    }
}

impl Element for Transformer {
    fn kind(&self) -> &str {
        match self.m {
            Param::Const(_) => "TF",
            Param::Modulated { .. } => "MTF",
        }
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::any_dim("1"), PortSpec::any_dim("2")])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::ExactlyOne(PortCausality::EffortOut)
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.m.signal_inputs()
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        // Effort travels from the FlowOut side to the EffortOut side, flow the other way.
        let (out, inp) = if causality[0] == PortCausality::EffortOut {
            (0, 1)
        } else {
            (1, 0)
        };
        let mut modulation: Vec<Slot> = (0..self.m.n_inputs()).map(Slot::Input).collect();
        let mut effort = vec![Slot::Effort(inp)];
        effort.append(&mut modulation.clone());
        let mut flow = vec![Slot::Flow(out)];
        flow.append(&mut modulation);
        vec![
            Stage {
                writes: vec![Slot::Effort(out)],
                reads: effort,
            },
            Stage {
                writes: vec![Slot::Flow(inp)],
                reads: flow,
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let m = self.m.value(io, 0);
        let forward = io.causality(0) == PortCausality::EffortOut;
        for k in 0..io.dim(0) {
            match (stage, forward) {
                (0, true) => io.set_e(0, k, m * io.e(1, k)),
                (1, true) => io.set_f_in(1, k, -m * io.f_in(0, k)),
                (0, false) => io.set_e(1, k, io.e(0, k) / m),
                _ => io.set_f_in(0, k, -io.f_in(1, k) / m),
            }
        }
    }
    fn partials_are_constant(&self) -> bool {
        self.m.constant().is_some()
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let m = self.m.value(io, 0);
        let forward = io.causality(0) == PortCausality::EffortOut;
        for k in 0..io.dim(0) {
            // (row, column, ∂row/∂column, ∂row/∂m)
            let (row, col, v, dm) = match (stage, forward) {
                (0, true) => (
                    jac.row(Slot::Effort(0), k),
                    jac.effort_col(1, k),
                    m,
                    io.e(1, k),
                ),
                (1, true) => (
                    jac.row(Slot::Flow(1), k),
                    jac.flow_col(0, k),
                    -m,
                    -io.f_in(0, k),
                ),
                (0, false) => (
                    jac.row(Slot::Effort(1), k),
                    jac.effort_col(0, k),
                    1.0 / m,
                    -io.e(0, k) / (m * m),
                ),
                _ => (
                    jac.row(Slot::Flow(0), k),
                    jac.flow_col(1, k),
                    -1.0 / m,
                    io.f_in(1, k) / (m * m),
                ),
            };
            jac.set(row, col, v);
            self.m
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), dm * d));
        }
        true
    }
}

/// Kind `TF`: `e₁ = m·e₂`, `f₂ = m·f₁`.
pub const KIND: KindDecl = KindDecl::element(
    "TF",
    "transformer: e1 = m·e2, f2 = m·f1",
    &[ParamDecl::number("m", "", "modulus e1/e2 = f2/f1")],
    |p| Ok(Box::new(Transformer::new(p.number("m")?)?)),
)
.example("m = 0.5");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences_in_both_orientations() {
        use PortCausality::{EffortOut as E, FlowOut as F};
        let tf =
            Transformer::new(Param::modulated(vec!["u".into()], |_, u| 1.5 + u[0].sin())).unwrap();
        // e1, f1, e2, f2, u
        let point = [2.0, -0.5, 1.1, 0.8, 0.3];
        for c in [[E, F], [F, E]] {
            let ports = [(1, 1.0, c[0]), (1, -1.0, c[1])];
            assert_eq!(check_partials(&tf, &ports, &point), Ok(2));
        }
    }

    #[test]
    fn rejects_zero_modulus() {
        assert!(Transformer::new(0.0).is_err());
        assert!(Transformer::new(f64::NAN).is_err());
        assert_eq!(Transformer::new(2.0).unwrap().kind(), "TF");
        assert_eq!(
            Transformer::new(Param::modulated(vec!["t".into()], |t, _| t))
                .unwrap()
                .kind(),
            "MTF"
        );
    }
}
