//! Resistor `R`: e = r·f_in (Karnopp, Margolis & Rosenberg, ch. 3). Dissipates r·f² ≥ 0.
//!
//! Causality: free. Resistance causality (flow in, effort out) is preferred; conductance
//! causality (f_in = e/r) is offered when `r` is non-zero (a modulated `r` is assumed
//! non-zero). On a multibond the law applies component-wise.

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec};
use crate::error::ParamError;

/// Linear (or modulated) resistor. Resistance `r` in effort/flow units (Ω, N·s/m, Pa·s/m³).
#[derive(Debug)]
pub struct Resistor {
    r: Param,
}

impl Resistor {
    /// A resistor; a constant `r` must be finite and ≥ 0.
    pub fn new(r: impl Into<Param>) -> Result<Self, ParamError> {
        let r = r.into();
        if let Some(v) = r.constant() {
            ParamError::non_negative("r", v)?;
        }
        Ok(Self { r })
    }
}

impl Element for Resistor {
    fn kind(&self) -> &str {
        "R"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::any_dim("1")])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        let resistance = vec![PortCausality::EffortOut];
        if self.r.constant() == Some(0.0) {
            CausalRule::Resistive(vec![resistance])
        } else {
            CausalRule::Resistive(vec![resistance, vec![PortCausality::FlowOut]])
        }
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.r.signal_inputs()
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let r = self.r.value(io, 0);
        for k in 0..io.dim(0) {
            match io.causality(0) {
                PortCausality::EffortOut => io.set_e(0, k, r * io.f_in(0, k)),
                PortCausality::FlowOut => io.set_f_in(0, k, io.e(0, k) / r),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_negative_and_nan() {
        assert!(Resistor::new(-1.0).is_err());
        assert!(Resistor::new(f64::NAN).is_err());
        assert!(Resistor::new(0.0).is_ok());
    }

    #[test]
    fn zero_resistance_offers_only_resistance_causality() {
        let r = Resistor::new(0.0).unwrap();
        assert_eq!(
            r.causal_rule(1),
            CausalRule::Resistive(vec![vec![PortCausality::EffortOut]])
        );
    }
}
