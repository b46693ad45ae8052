//! scratch
#![allow(clippy::unwrap_used, clippy::expect_used)]
mod common;
use bondgraph::*;
use common::*;
#[test]
fn scratch() {
    for m in [Method::Esdirk34, Method::TrBdf2] {
        for (rtol, dt, atol) in [
            (1e-9, 0.01, 1e-14),
            (1e-10, 0.01, 1e-15),
            (1e-10, 0.01, 1e-14),
            (1e-10, 0.01, 1e-13),
        ] {
            let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
            let x0 = eqs.initial_state();
            let outs = [output(&eqs, "spring.q")];
            let run = simulate(
                &mut eqs,
                &x0,
                &settings(m, 10.0, dt, rtol, atol),
                &outs,
                vec![],
            );
            let t = col(&run.trajectory, "t");
            let q = col(&run.trajectory, "spring.q");
            let e = t
                .iter()
                .zip(&q)
                .map(|(t, q)| (q - underdamped(0.01, 0.0, 0.2, 10.0, *t).0).abs())
                .fold(0.0, f64::max);
            let ef = (run.x_final[1] - underdamped(0.01, 0.0, 0.2, 10.0, 10.0).0).abs();
            eprintln!("{:?} {:?}", run.error, &run.trajectory.rows[..3]);
            eprintln!("{:9} rtol {rtol:e} atol {atol:e} dt {dt}: rows max err {e:.3e}, final err {ef:.3e}, steps {} rhs {} wall {:?}", m.name(), run.stats.steps, run.stats.rhs_evals, run.stats.wall_time);
        }
    }
}
