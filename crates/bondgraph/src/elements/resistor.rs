//! Resistor `R`: e = r·f_in (Karnopp, Margolis & Rosenberg, ch. 3). Dissipates r·f² ≥ 0.
//!
//! Causality: free. Resistance causality (flow in, effort out) is preferred; conductance
//! causality (f_in = e/r) is offered when `r` is non-zero (a modulated `r` is assumed
//! non-zero). On a multibond the law applies component-wise.

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot};
use crate::error::ParamError;
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

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
    fn partials_are_constant(&self) -> bool {
        self.r.constant().is_some()
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let r = self.r.value(io, 0);
        for k in 0..io.dim(0) {
            // e = r·f_in, or f_in = e/r; the modulation enters through r.
            let (row, col, v, dv_dr) = match io.causality(0) {
                PortCausality::EffortOut => {
                    let f = io.f_in(0, k);
                    (jac.row(Slot::Effort(0), k), jac.flow_col(0, k), r, f)
                }
                PortCausality::FlowOut => {
                    let e = io.e(0, k);
                    (
                        jac.row(Slot::Flow(0), k),
                        jac.effort_col(0, k),
                        1.0 / r,
                        -e / (r * r),
                    )
                }
            };
            jac.set(row, col, v);
            self.r
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), dv_dr * d));
        }
        true
    }
}

/// Kind `R`: `e = r·f`.
pub const KIND: KindDecl = KindDecl::element(
    "R",
    "resistor: e = r·f",
    &[ParamDecl::modulated("r", "", "resistance e/f (may read signals)").non_negative()],
    |p| Ok(Box::new(Resistor::new(p.modulated("r")?)?)),
)
.example("r = 2.0");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences_in_both_causalities() {
        let r =
            Resistor::new(Param::modulated(vec!["u".into()], |_, u| 2.0 + u[0] * u[0])).unwrap();
        for c in [PortCausality::EffortOut, PortCausality::FlowOut] {
            for sign in [1.0, -1.0] {
                // e, f_in, u
                assert_eq!(
                    check_partials(&r, &[(1, sign, c)], &[3.0, -0.7, 0.4]),
                    Ok(1)
                );
            }
        }
        let r2 = Resistor::new(5.0).unwrap();
        let c = PortCausality::EffortOut;
        assert_eq!(
            check_partials(&r2, &[(2, 1.0, c)], &[0.0, 0.0, 1.5, -2.0]),
            Ok(1)
        );
    }

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
