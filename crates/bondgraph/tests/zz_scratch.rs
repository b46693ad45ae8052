//! scratch
#![allow(clippy::unwrap_used, clippy::expect_used)]
mod common;
use bondgraph::*;
#[test]
fn scratch() {
    let mut g = BondGraph::new();
    for i in 1..=3 {
        g.add(&format!("Z{i}"), ZeroJunction).unwrap();
        g.add(&format!("J{i}"), OneJunction).unwrap();
        g.add(
            &format!("I{i}"),
            Inertia::new(1.0 + i as f64, 0.1 * i as f64).unwrap(),
        )
        .unwrap();
        g.add(
            &format!("C{i}"),
            Capacitor::new(0.5 * i as f64, 0.2).unwrap(),
        )
        .unwrap();
    }
    for i in 1..=3 {
        g.connect_names(&format!("Z{i}"), &format!("I{i}")).unwrap();
        g.connect_names(&format!("J{i}"), &format!("C{i}")).unwrap();
    }
    for i in 1..=3 {
        for j in 1..=3 {
            g.connect_names(&format!("Z{i}"), &format!("J{j}")).unwrap();
        }
    }
    match assign_causality(g) {
        Ok(c) => {
            for b in 0..c.graph.n_bonds() {
                eprintln!("{}", c.describe_bond(b));
            }
            let r = StateEquations::new(c);
            eprintln!("{:?}", r.err().map(|e| e.to_string()));
        }
        Err(e) => eprintln!("ERR {e}"),
    }
}
