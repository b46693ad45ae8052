//! scratch
#![allow(clippy::unwrap_used, clippy::expect_used)]
mod common;
use bondgraph::*;
use common::*;
#[test]
fn scratch() {
    let mut g = BondGraph::new();
    g.add("src", EffortSource::new(1.0)).unwrap();
    g.add("j", OneJunction).unwrap();
    g.add("R", Resistor::new(1.0).unwrap()).unwrap();
    g.add("C", Capacitor::new(0.1, 0.0).unwrap()).unwrap();
    bond_all(&mut g, &[("src", "j"), ("j", "R"), ("j", "C")]);
    let r = StateEquations::new(assign_causality(g).unwrap());
    eprintln!("{:?}", r.err().map(|e| e.to_string()));
    let mut g = BondGraph::new();
    g.add("src", FlowSource::new(1.0)).unwrap();
    g.add("j", ZeroJunction).unwrap();
    g.add("R", Resistor::new(1.0).unwrap()).unwrap();
    g.add("C", Inertia::new(0.1, 0.0).unwrap()).unwrap();
    bond_all(&mut g, &[("src", "j"), ("j", "R"), ("j", "C")]);
    let r = StateEquations::new(assign_causality(g).unwrap());
    eprintln!("{:?}", r.err().map(|e| e.to_string()));
    let eqs = dc_motor(12.0, 2.0, None, 0.5, 0.01, 0.1);
    eprintln!("{:?}", eqs.order());
}
