//! Small models the unit tests of several modules share (test builds only).

#![allow(clippy::unwrap_used)] // fixed, valid test models

use crate::{
    assign_causality, BondGraph, Capacitor, EffortSource, Inertia, InputSpec, OneJunction, Param,
    Resistor, StateEquations,
};

/// A mass–spring–damper on one 1-junction (`force → v → mass, spring, damper`), from rest:
/// mass `m`, compliance `c`, resistance `r`. The force is the constant `force`, or, with
/// `input = Some(default)`, the model input `F` (that default) through a modulated source.
pub(crate) fn msd(m: f64, c: f64, r: f64, force: f64, input: Option<f64>) -> StateEquations {
    let mut g = BondGraph::new();
    match input {
        None => {
            g.add("force", EffortSource::new(force)).unwrap();
        }
        Some(default) => {
            let spec = InputSpec {
                name: "F".into(),
                unit: "N".into(),
                default,
                description: "force".into(),
            };
            g.add("F", crate::Input::new(spec).unwrap()).unwrap();
            let law = Param::modulated(vec!["F".into()], |_, u| u[0]);
            g.add("force", EffortSource::new(law)).unwrap();
        }
    }
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(m, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(c, 0.0).unwrap()).unwrap();
    g.add("damper", Resistor::new(r).unwrap()).unwrap();
    for (a, b) in [
        ("force", "v"),
        ("v", "mass"),
        ("v", "spring"),
        ("v", "damper"),
    ] {
        g.connect_names(a, b).unwrap();
    }
    StateEquations::new(assign_causality(g).unwrap()).unwrap()
}
