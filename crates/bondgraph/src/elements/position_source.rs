//! Position source `Sf_position`: a flow source driven by a prescribed position x(t); the
//! flow it delivers is the exact derivative ẋ(t).
//!
//! A crane tip following a vessel, a deck, a test rig's actuator: the motion is known as a
//! position, and differencing it would put noise into the flow. The position is a
//! [`Motion`] (an expression of `t`, parameters and inputs whose derivatives are known: a
//! sea state, data with `interp = "spline"`), so ẋ and ẍ are exact. Fixed flow-out
//! causality, like `Sf`: with its bond drawn away from the source the bond's flow is ẋ.
//! Outputs: `x`, `v` = ẋ and `a` = ẍ (the acceleration, for an inertial load elsewhere).
//! The source's flow starts from the position's own rate; what it drives starts wherever
//! its states start (integrate the flow to get x back only if they start consistently).

use crate::bond::PortCausality as Pc;
use crate::element::{CausalRule, Element, Io, PortSpec, Ports, SignalSpec, Stage};
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;
use crate::Motion;

/// A flow source delivering ẋ of a prescribed position x(t) (see the module documentation).
#[derive(Debug)]
pub struct PositionSource {
    position: Motion,
}

impl PositionSource {
    /// A source following `position`.
    #[must_use]
    pub fn new(position: impl Into<Motion>) -> Self {
        Self {
            position: position.into(),
        }
    }
}

impl Element for PositionSource {
    fn kind(&self) -> &str {
        "Sf_position"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::any_dim("1")])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![Pc::FlowOut])
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![
            SignalSpec::scalar("x"),
            SignalSpec::scalar("v"),
            SignalSpec::scalar("a"),
        ]
    }
    fn stages(&self, causality: &[Pc]) -> Vec<Stage> {
        // time alone: no inputs, no states
        Stage::from_states(causality, 0, 3)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let [x, v, a] = self.position.eval(io.time());
        for k in 0..io.dim(0) {
            io.set_f_in(0, k, -v);
        }
        io.set_y(0, 0, x);
        io.set_y(1, 0, v);
        io.set_y(2, 0, a);
    }
    /// A function of time alone: no partials in the element's variables.
    fn stage_partials(&self, _: usize, _: &Io<'_>, _: &mut LocalJacobian<'_>) -> bool {
        true
    }
}

/// Kind `Sf_position`: delivers f = ẋ of the position `x(t)`.
pub const KIND: KindDecl = KindDecl::element(
    "Sf_position",
    "position source: delivers the flow f = dx/dt of a prescribed position x(t), exactly",
    &[ParamDecl::modulated(
        "x",
        "",
        "position: an expression of t, parameters and inputs with known derivatives (sea, spline data)",
    )],
    |p| Ok(Box::new(PositionSource::new(p.motion("x")?))),
)
.example("x = \"0.5*sin(2*t)\"");

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;
    use crate::{assign_causality, simulate, BondGraph, Settings, StateEquations};

    /// The source feeding a spring (C): the spring's displacement integrates the flow, so
    /// q(t) − q(0) = x(t) − x(0) if the flow is ẋ exactly.
    #[test]
    fn a_spring_fed_by_the_source_integrates_back_the_position() {
        let x = Motion::law(|t| {
            let w = 2.0;
            [0.3 * (w * t).sin() + 0.1 * t * t, 0.3 * w * (w * t).cos() + 0.2 * t, -0.3 * w * w * (w * t).sin() + 0.2]
        });
        let mut g = BondGraph::new();
        g.add("tip", PositionSource::new(x.clone())).unwrap();
        g.add("spring", crate::Capacitor::new(1.0, 0.0).unwrap()).unwrap();
        g.connect_names("tip", "spring").unwrap();
        let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let x0 = eqs.initial_state();
        let settings = Settings {
            t_end: 3.0,
            rtol: 1e-10,
            atol: 1e-12,
            ..Settings::default()
        };
        let run = simulate(&mut eqs, &x0, &settings, &[], vec![]);
        assert!(run.error.is_none(), "{:?}", run.error);
        let want = x.eval(3.0)[0] - x.eval(0.0)[0];
        assert!((run.x_final[0] - want).abs() < 1e-8, "{} vs {want}", run.x_final[0]);
    }

    #[test]
    fn outputs_are_the_motion_and_the_flow_its_rate() {
        let src = PositionSource::new(Motion::law(|t| [t * t, 2.0 * t, 2.0]));
        assert_eq!(src.signal_outputs().len(), 3);
        assert_eq!(src.position.eval(1.5), [2.25, 3.0, 2.0]);
        assert_eq!(PositionSource::new(4.0).position.eval(9.0), [4.0, 0.0, 0.0]);
    }
}
