//! Stages whose signals only outputs read are skipped by `rhs` and run for output rows.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::cell::Cell;
use std::rc::Rc;

use bondgraph::*;

#[derive(Debug)]
struct Counter(Rc<Cell<usize>>);

impl Element for Counter {
    fn kind(&self) -> &str {
        "counter"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("spring.q")]
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("twice")]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        self.0.set(self.0.get() + 1);
        let v = 2.0 * io.u(0);
        io.set_y(0, 0, v);
    }
}

fn oscillator(counter: Rc<Cell<usize>>, read_by_source: bool) -> StateEquations {
    let mut g = BondGraph::new();
    let force = if read_by_source {
        Param::modulated(vec!["probe.twice".into()], |_, u| -0.0 * u[0])
    } else {
        Param::Const(0.0)
    };
    g.add("f", EffortSource::new(force)).unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(0.1, 0.01).unwrap()).unwrap();
    g.add("probe", Counter(counter)).unwrap();
    for (a, b) in [("f", "v"), ("v", "mass"), ("v", "spring")] {
        g.connect_names(a, b).unwrap();
    }
    StateEquations::new(assign_causality(g).unwrap()).unwrap()
}

#[test]
fn output_only_stages_run_for_outputs_not_for_rhs() {
    let n = Rc::new(Cell::new(0));
    let eqs = oscillator(n.clone(), false);
    let x = eqs.initial_state();
    let mut dx = vec![0.0; 2];
    eqs.rhs(0.0, &x, &mut dx);
    assert_eq!(n.get(), 0, "rhs must skip a signal nobody reads");
    eqs.evaluate(0.0, &x);
    assert_eq!(n.get(), 1);
    let p = eqs.probe("probe.twice").unwrap();
    assert!((eqs.read(p, 0.0, &x) - 0.02).abs() < 1e-15);
}

#[test]
fn a_signal_read_by_an_element_is_computed_by_rhs() {
    let n = Rc::new(Cell::new(0));
    let eqs = oscillator(n.clone(), true);
    let x = eqs.initial_state();
    let mut dx = vec![0.0; 2];
    eqs.rhs(0.0, &x, &mut dx);
    assert_eq!(n.get(), 1);
}
