//! Gyrator `GY` / modulated gyrator `MGY`: e₁ = −r·f_in₂, e₂ = r·f_in₁.
//!
//! With the usual drawing (bond 1 in, bond 2 out) this is the textbook e₁ = r·f₂, e₂ = r·f₁
//! (a DC motor: torque = k·current, voltage = k·speed). Power is conserved:
//! e₁·f_in₁ + e₂·f_in₂ = −r·f_in₂·f_in₁ + r·f_in₁·f_in₂ = 0.
//! Causality: both ports set their efforts (flows in), or both set their flows (needs r ≠ 0).

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot, Stage};
use crate::error::ParamError;
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

/// Gyrator with (possibly modulated) modulus `r` (units e₁/f₂, e.g. N·m/A).
#[derive(Debug)]
pub struct Gyrator {
    r: Param,
}

impl Gyrator {
    /// A gyrator; a constant `r` must be finite and non-zero.
    pub fn new(r: impl Into<Param>) -> Result<Self, ParamError> {
        let r = r.into();
        if let Some(v) = r.constant() {
            ParamError::non_zero("r", v)?;
        }
        Ok(Self { r })
    }
}

impl Element for Gyrator {
    fn kind(&self) -> &str {
        match self.r {
            Param::Const(_) => "GY",
            Param::Modulated { .. } => "MGY",
        }
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::any_dim("1"), PortSpec::any_dim("2")])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::AllEqual
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.r.signal_inputs()
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        let n = self.r.n_inputs();
        let stage = |write: Slot, read: Slot| Stage {
            writes: vec![write],
            reads: std::iter::once(read)
                .chain((0..n).map(Slot::Input))
                .collect(),
        };
        if causality[0] == PortCausality::EffortOut {
            vec![
                stage(Slot::Effort(0), Slot::Flow(1)),
                stage(Slot::Effort(1), Slot::Flow(0)),
            ]
        } else {
            vec![
                stage(Slot::Flow(1), Slot::Effort(0)),
                stage(Slot::Flow(0), Slot::Effort(1)),
            ]
        }
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let r = self.r.value(io, 0);
        let impedance = io.causality(0) == PortCausality::EffortOut;
        for k in 0..io.dim(0) {
            match (stage, impedance) {
                (0, true) => io.set_e(0, k, -r * io.f_in(1, k)),
                (1, true) => io.set_e(1, k, r * io.f_in(0, k)),
                (0, false) => io.set_f_in(1, k, -io.e(0, k) / r),
                _ => io.set_f_in(0, k, io.e(1, k) / r),
            }
        }
    }
    fn partials_are_constant(&self) -> bool {
        self.r.constant().is_some()
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let r = self.r.value(io, 0);
        let impedance = io.causality(0) == PortCausality::EffortOut;
        for k in 0..io.dim(0) {
            // (row, column, ∂row/∂column, ∂row/∂r)
            let (row, col, v, dr) = match (stage, impedance) {
                (0, true) => (
                    jac.row(Slot::Effort(0), k),
                    jac.flow_col(1, k),
                    -r,
                    -io.f_in(1, k),
                ),
                (1, true) => (
                    jac.row(Slot::Effort(1), k),
                    jac.flow_col(0, k),
                    r,
                    io.f_in(0, k),
                ),
                (0, false) => (
                    jac.row(Slot::Flow(1), k),
                    jac.effort_col(0, k),
                    -1.0 / r,
                    io.e(0, k) / (r * r),
                ),
                _ => (
                    jac.row(Slot::Flow(0), k),
                    jac.effort_col(1, k),
                    1.0 / r,
                    -io.e(1, k) / (r * r),
                ),
            };
            jac.set(row, col, v);
            self.r
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), dr * d));
        }
        true
    }
}

/// Kind `GY`: `e₁ = r·f₂`, `e₂ = r·f₁`, constant modulus.
pub const GY: KindDecl = KindDecl::element(
    "GY",
    "gyrator: e1 = r·f2, e2 = r·f1",
    &[ParamDecl::number("r", "", "modulus")],
    |p| Ok(Box::new(Gyrator::new(p.number("r")?)?)),
)
.example("r = 0.1");

/// Kind `MGY`: a gyrator whose modulus reads signals.
pub const MGY: KindDecl = KindDecl::element(
    "MGY",
    "modulated gyrator: r = r(signals)",
    &[ParamDecl::modulated("r", "", "modulus (may read signals)")],
    |p| Ok(Box::new(Gyrator::new(p.modulated("r")?)?)),
)
.example("r = 0.1");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences_in_both_causalities() {
        use PortCausality::{EffortOut as E, FlowOut as F};
        let gy =
            Gyrator::new(Param::modulated(vec!["u".into()], |_, u| 0.5 + u[0] * u[0])).unwrap();
        // e1, f1, e2, f2, u
        let point = [2.0, -0.5, 1.1, 0.8, 0.3];
        for c in [E, F] {
            let ports = [(1, 1.0, c), (1, -1.0, c)];
            assert_eq!(check_partials(&gy, &ports, &point), Ok(2));
        }
    }

    #[test]
    fn rejects_zero_modulus() {
        assert!(Gyrator::new(0.0).is_err());
        assert!(Gyrator::new(f64::INFINITY).is_err());
        assert!(Gyrator::new(0.1).is_ok());
    }
}
