//! scratch
#![allow(clippy::unwrap_used, clippy::expect_used)]
mod common;
use bondgraph::*;
use common::*;
#[test]
fn scratch() {
    for m in Method::ALL {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "spring.q")];
    let run = simulate(&mut eqs, &x0, &settings(m, 1.0, 0.1, 1e-8, 1e-12), &outs, vec![]);
    eprintln!("{:?} {:?}", run.error, run.trajectory.rows.iter().map(|r| r[0]).collect::<Vec<_>>());
    let mut eqs = planar_matrix_mtf();
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "spring.q")];
    let run = simulate(&mut eqs, &x0, &settings(m, 1.0, 0.1, 1e-8, 1e-10), &outs, vec![]);
    eprintln!("{:?} {:?}", run.error, run.trajectory.rows.iter().map(|r| r[0]).collect::<Vec<_>>());
    }
}
