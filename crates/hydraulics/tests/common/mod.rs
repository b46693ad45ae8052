//! Shared by the integration tests: columns, probes and a signal integrator for
//! bookkeeping. Each test binary uses a subset.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use bondgraph::{
    CausalRule, Element, Io, Output, Param, Ports, SignalSpec, Stage, StateEquations, StateSpec,
    Trajectory,
};

/// A column of a trajectory, by name.
pub fn col(t: &Trajectory, name: &str) -> Vec<f64> {
    t.column(name)
        .unwrap_or_else(|| panic!("no column `{name}` in {:?}", t.columns))
}

/// An output reading `probe`.
pub fn output(eqs: &StateEquations, column: &str, probe: &str) -> Output {
    Output {
        name: column.to_owned(),
        probe: eqs
            .probe(probe)
            .unwrap_or_else(|| panic!("no probe `{probe}`")),
    }
}

/// Signal block with one state: dz/dt = integrand(t, signals). For exact running integrals
/// (to solver tolerance) of quantities the model computes.
#[derive(Debug)]
pub struct Integrator {
    pub integrand: Param,
    pub nominal: f64,
}

impl Element for Integrator {
    fn kind(&self) -> &str {
        "test.integrator"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("z", 0.0).nominal(self.nominal)]
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.integrand.signal_inputs()
    }
    fn stages(&self, _: &[bondgraph::PortCausality]) -> Vec<Stage> {
        Vec::new()
    }
    fn eval(&self, _: usize, _: &mut Io<'_>) {}
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        dx[0] = self.integrand.value(io, 0);
    }
}

/// An integrator of `law(signals)` with the given nominal magnitude.
pub fn integrator(
    signals: &[&str],
    nominal: f64,
    law: impl Fn(&[f64]) -> f64 + 'static,
) -> Integrator {
    Integrator {
        integrand: Param::modulated(
            signals.iter().map(|s| (*s).to_owned()).collect(),
            move |_, u| law(u),
        ),
        nominal,
    }
}
