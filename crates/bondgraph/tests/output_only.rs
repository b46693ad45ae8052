//! Stages whose signals only outputs read — directly or through other such stages — are
//! skipped by `rhs` and run for output rows.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::cell::Cell;
use std::rc::Rc;

use bondgraph::*;

#[derive(Debug)]
struct Counter(Rc<Cell<usize>>, &'static str);

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
        vec![SignalSpec::scalar(self.1)]
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
    oscillator_reading(counter, read_by_source.then_some("probe.twice"), None)
}

/// The oscillator with a probe of the spring, an optional second probe of the first, and a
/// source that reads `source_reads`.
fn oscillator_reading(
    counter: Rc<Cell<usize>>,
    source_reads: Option<&str>,
    second: Option<Rc<Cell<usize>>>,
) -> StateEquations {
    let mut g = BondGraph::new();
    let force = if let Some(name) = source_reads {
        Param::modulated(vec![name.into()], |_, u| -0.0 * u[0])
    } else {
        Param::Const(0.0)
    };
    g.add("f", EffortSource::new(force)).unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(0.1, 0.01).unwrap()).unwrap();
    g.add("probe", Counter(counter, "spring.q")).unwrap();
    if let Some(c) = second {
        g.add("probe2", Counter(c, "probe.twice")).unwrap();
    }
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

#[test]
fn a_signal_read_only_by_skipped_stages_is_skipped_too() {
    let (n, n2) = (Rc::new(Cell::new(0)), Rc::new(Cell::new(0)));
    let eqs = oscillator_reading(n.clone(), None, Some(n2.clone()));
    let x = eqs.initial_state();
    let mut dx = vec![0.0; 2];
    eqs.rhs(0.0, &x, &mut dx);
    assert_eq!((n.get(), n2.get()), (0, 0));
    eqs.evaluate(0.0, &x);
    assert_eq!((n.get(), n2.get()), (1, 1));
    let p = eqs.probe("probe2.twice").unwrap();
    assert!((eqs.read(p, 0.0, &x) - 0.04).abs() < 1e-15);
    // once the source reads the second probe, both run in rhs
    let (n, n2) = (Rc::new(Cell::new(0)), Rc::new(Cell::new(0)));
    let eqs = oscillator_reading(n.clone(), Some("probe2.twice"), Some(n2.clone()));
    eqs.rhs(0.0, &x, &mut dx);
    assert_eq!((n.get(), n2.get()), (1, 1));
}
