//! Tank `hydraulics.tank`: a reservoir at constant pressure that counts the oil it receives.
//!
//! ```text
//! e = p_T                 (constant, gauge; default 0)
//! dV/dt = f_in            V(0) = V₀ (default 0)
//! ```
//!
//! An effort source (Se) with one state: V, the net volume returned to the tank since the
//! start (m³; negative when a pump draws more than returns). A circuit's volume balance can
//! then be closed: every m³ the pump takes out and every m³ a valve, leak or line returns is
//! counted, `V(t) = V₀ + ∫f_in dt` exactly (the state *is* the integral). Power p_T·f_in
//! leaves the circuit here (zero at the default p_T = 0). The reservoir is large: its level
//! does not change its pressure.
//!
//! Causality: fixed, the tank sets the pressure of its port (like Se). Several returns share
//! one tank through a 0-junction.

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot,
    Stage, StateSpec,
};

/// A tank at pressure `p` (Pa gauge) whose state `V` (m³) counts the volume returned.
#[derive(Debug, Clone, PartialEq)]
pub struct Tank {
    p: f64,
    v0: f64,
    v_nominal: f64,
}

impl Tank {
    /// A tank at gauge pressure `p` (Pa, finite) that has received `v0` (m³, finite) at the
    /// start. The volume's absolute tolerance scale is 1e-3 m³ (see
    /// [`with_nominal_volume`](Self::with_nominal_volume)).
    pub fn new(p: f64, v0: f64) -> Result<Self, ParamError> {
        ParamError::finite("p", p)?;
        ParamError::finite("v0", v0)?;
        Ok(Self {
            p,
            v0,
            v_nominal: 1e-3,
        })
    }

    /// Set the typical volume (m³, > 0): the absolute tolerance of V is `atol · v_nominal`.
    pub fn with_nominal_volume(mut self, v_nominal: f64) -> Result<Self, ParamError> {
        self.v_nominal = ParamError::positive("v_nominal", v_nominal)?;
        Ok(self)
    }
}

impl Element for Tank {
    fn kind(&self) -> &str {
        "hydraulics.tank"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::EffortOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("V", self.v0).nominal(self.v_nominal)]
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        vec![Stage {
            writes: vec![Slot::Effort(0)],
            reads: Vec::new(),
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        io.set_e(0, 0, self.p);
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        dx[0] = io.f_in(0, 0);
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, _: &mut LocalJacobian<'_>) -> bool {
        true // a constant
    }
    fn derivative_partials(&self, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        jac.set(jac.derivative_row(0), jac.flow_col(0, 0), 1.0);
        true
    }
}

/// Kind `hydraulics.tank`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.tank",
    "tank at constant pressure p that counts the volume it receives: state V = ∫ f_in dt",
    &[
        ParamDecl::number("p", "Pa", "tank pressure (gauge)").default(0.0),
        ParamDecl::number("v0", "m³", "volume counted at the start").default(0.0),
        ParamDecl::number("v_nominal", "m³", "tolerance scale of the volume state")
            .positive()
            .default(1e-3),
    ],
    build,
)
.example("p = 0.0");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let t =
        Tank::new(p.number("p")?, p.number("v0")?)?.with_nominal_volume(p.number("v_nominal")?)?;
    Ok(Box::new(t))
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // a constant and a copied parameter are meant exactly
mod tests {
    use super::*;
    use crate::Chamber;
    use bondgraph::{
        assign_causality, check_partials, simulate, BondGraph, Output, Resistor, Settings,
        StateEquations,
    };

    /// A 1 l chamber at 10 MPa drains through a laminar resistance into the tank: the tank
    /// receives exactly what the chamber loses, (V/β)·(P₀ − P(t)), and
    /// P(t) = p_T + (P₀ − p_T)·e^(−t/τ), τ = R·V/β.
    #[test]
    fn tank_volume_is_the_integral_of_the_inflow() {
        let (v, beta, p0, r, p_t) = (1e-3, 1.5e9, 10e6, 1e12, 2e5);
        let mut g = BondGraph::new();
        g.add("oil", Chamber::fixed(v, beta, p0).unwrap()).unwrap();
        g.add("drain", Resistor::new(r).unwrap()).unwrap();
        g.add(
            "tank",
            Tank::new(p_t, 0.0)
                .unwrap()
                .with_nominal_volume(1e-6)
                .unwrap(),
        )
        .unwrap();
        g.add("j", bondgraph::OneJunction).unwrap();
        for (a, b) in [("oil", "j"), ("j", "drain"), ("j", "tank")] {
            g.connect_names(a, b).unwrap();
        }
        let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let outputs: Vec<Output> = ["oil.p", "tank.V", "tank.e"]
            .iter()
            .map(|p| Output {
                name: (*p).into(),
                probe: eqs.probe(p).unwrap(),
            })
            .collect();
        let tau = r * v / beta;
        let settings = Settings {
            t_end: 3.0 * tau,
            dt_out: tau / 100.0,
            rtol: 1e-10,
            atol: 1e-10,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(run.error.is_none(), "{:?}", run.error);
        let tr = &run.trajectory;
        let (t, p, vt, et) = (
            tr.column("t").unwrap(),
            tr.column("oil.p").unwrap(),
            tr.column("tank.V").unwrap(),
            tr.column("tank.e").unwrap(),
        );
        let total = v / beta * (p0 - p_t);
        for k in 0..t.len() {
            assert_eq!(et[k], p_t);
            // what the chamber lost is what the tank received
            let lost = v / beta * (p0 - p[k]);
            assert!((vt[k] - lost).abs() < 1e-9 * total, "t = {}", t[k]);
            // and both follow the closed form
            let exact = total * (1.0 - (-t[k] / tau).exp());
            assert!((vt[k] - exact).abs() < 1e-7 * total, "t = {}", t[k]);
        }
    }

    #[test]
    fn partials_and_parameters() {
        let tank = Tank::new(0.0, 1.0).unwrap();
        let port = [(1, 1.0, PortCausality::EffortOut)];
        assert_eq!(check_partials(&tank, &port, &[0.0, 2e-3, 1.0]), Ok(2));
        assert_eq!(tank.states()[0].initial, 1.0);
        assert!(Tank::new(f64::NAN, 0.0).is_err());
        assert!(Tank::new(0.0, f64::INFINITY).is_err());
        assert!(tank.with_nominal_volume(0.0).is_err());
    }
}
