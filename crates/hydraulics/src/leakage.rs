//! Leakage: laminar `R` elements (paper eq. 82, and the C_in, C_ex terms of eq. 28).
//!
//! * `hydraulics.leakage` — internal, between two lines (across the piston): ports `a`, `b`,
//!   `Q = (P_a − P_b)/R` from `a` to `b`.
//! * `hydraulics.tank_leakage` — external, from one line to the tank: one port,
//!   `Q = (P − P_T)/R` out of the line.
//!
//! `R` is the leakage resistance in Pa·s/m³ (the paper's R_l = 1/C_in). Dissipates
//! (ΔP)²/R ≥ 0. Causality: conductance (the lines set the pressures, the leak its flow); the
//! external leak also accepts resistance causality (P = P_T + R·Q).

use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot,
};

/// Laminar leakage with resistance `r` (Pa·s/m³, > 0): internal (two ports) or to a tank at
/// pressure `p_tank` (one port).
#[derive(Debug)]
pub struct Leakage {
    r: f64,
    /// `Some(P_T)`: external, one port; `None`: internal, two ports.
    tank: Option<f64>,
}

impl Leakage {
    /// Internal leakage between ports `a` and `b`.
    pub fn internal(r: f64) -> Result<Self, ParamError> {
        ParamError::positive("r", r)?;
        Ok(Self { r, tank: None })
    }

    /// External leakage from its port to a tank at `p_tank` (Pa).
    pub fn to_tank(r: f64, p_tank: f64) -> Result<Self, ParamError> {
        ParamError::positive("r", r)?;
        ParamError::finite("p_tank", p_tank)?;
        Ok(Self {
            r,
            tank: Some(p_tank),
        })
    }
}

impl Element for Leakage {
    fn kind(&self) -> &str {
        match self.tank {
            None => "hydraulics.leakage",
            Some(_) => "hydraulics.tank_leakage",
        }
    }
    fn ports(&self) -> Ports {
        match self.tank {
            None => Ports::Fixed(vec![PortSpec::new("a", 1), PortSpec::new("b", 1)]),
            Some(_) => Ports::Fixed(vec![PortSpec::new("1", 1)]),
        }
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        use PortCausality::{EffortOut, FlowOut};
        match self.tank {
            None => CausalRule::Resistive(vec![vec![FlowOut, FlowOut]]),
            Some(_) => CausalRule::Resistive(vec![vec![FlowOut], vec![EffortOut]]),
        }
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        match self.tank {
            None => {
                let q = (io.e(0, 0) - io.e(1, 0)) / self.r;
                io.set_f_in(0, 0, q);
                io.set_f_in(1, 0, -q);
            }
            Some(p_t) => match io.causality(0) {
                PortCausality::FlowOut => io.set_f_in(0, 0, (io.e(0, 0) - p_t) / self.r),
                PortCausality::EffortOut => io.set_e(0, 0, p_t + self.r * io.f_in(0, 0)),
            },
        }
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let g = 1.0 / self.r;
        match (self.tank, io.causality(0)) {
            (None, _) => {
                for (p, s) in [(0, 1.0), (1, -1.0)] {
                    let row = jac.row(Slot::Flow(p), 0);
                    jac.set(row, jac.effort_col(0, 0), s * g);
                    jac.set(row, jac.effort_col(1, 0), -s * g);
                }
            }
            (Some(_), PortCausality::FlowOut) => {
                jac.set(jac.row(Slot::Flow(0), 0), jac.effort_col(0, 0), g);
            }
            (Some(_), PortCausality::EffortOut) => {
                jac.set(jac.row(Slot::Effort(0), 0), jac.flow_col(0, 0), self.r);
            }
        }
        true
    }
}

const R: ParamDecl = ParamDecl::number("r", "Pa·s/m³", "leakage resistance").positive();

/// Kind `hydraulics.leakage`.
pub const INTERNAL: KindDecl = KindDecl::element(
    "hydraulics.leakage",
    "internal leakage between ports a and b: Q = (P_a − P_b)/r",
    &[R],
    |p| Ok(Box::new(Leakage::internal(p.number("r")?)?)),
)
.example("r = 1e12");

/// Kind `hydraulics.tank_leakage`.
pub const TO_TANK: KindDecl = KindDecl::element(
    "hydraulics.tank_leakage",
    "external leakage to tank: Q = (P − p_tank)/r",
    &[
        R,
        ParamDecl::number("p_tank", "Pa", "tank pressure").default(0.0),
    ],
    |p| {
        Ok(Box::new(Leakage::to_tank(
            p.number("r")?,
            p.number("p_tank")?,
        )?))
    },
)
.example("r = 1e12");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        use PortCausality::{EffortOut, FlowOut};
        let i = Leakage::internal(1e13).unwrap();
        let ports = [(1, 1.0, FlowOut), (1, -1.0, FlowOut)];
        assert_eq!(check_partials(&i, &ports, &[11e6, 1e-6, 1e6, 1e-6]), Ok(1));
        let t = Leakage::to_tank(1e12, 1e5).unwrap();
        for c in [FlowOut, EffortOut] {
            assert_eq!(check_partials(&t, &[(1, 1.0, c)], &[3e6, 2e-6]), Ok(1));
        }
    }

    #[test]
    fn rejects_non_positive_resistance() {
        assert!(Leakage::internal(0.0).is_err());
        assert!(Leakage::internal(f64::INFINITY).is_err());
        assert!(Leakage::to_tank(-1.0, 0.0).is_err());
        assert!(Leakage::to_tank(1e12, f64::NAN).is_err());
        assert_eq!(
            Leakage::internal(1e13).unwrap().kind(),
            "hydraulics.leakage"
        );
        assert_eq!(
            Leakage::to_tank(1e13, 0.0).unwrap().kind(),
            "hydraulics.tank_leakage"
        );
    }
}
