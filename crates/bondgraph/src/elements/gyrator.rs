//! Gyrator `GY` / modulated gyrator `MGY`: e₁ = −r·f_in₂, e₂ = r·f_in₁.
//!
//! With the usual drawing (bond 1 in, bond 2 out) this is the textbook e₁ = r·f₂, e₂ = r·f₁
//! (a DC motor: torque = k·current, voltage = k·speed). Power is conserved:
//! e₁·f_in₁ + e₂·f_in₂ = −r·f_in₂·f_in₁ + r·f_in₁·f_in₂ = 0.
//! Causality: both ports set their efforts (flows in), or both set their flows (needs r ≠ 0).

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot, Stage};
use crate::error::ParamError;

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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_zero_modulus() {
        assert!(Gyrator::new(0.0).is_err());
        assert!(Gyrator::new(f64::INFINITY).is_err());
        assert!(Gyrator::new(0.1).is_ok());
    }
}
