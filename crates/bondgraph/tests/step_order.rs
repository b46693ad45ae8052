//! What a sink that asks for every accepted step sees: the rows and the steps in time order
//! (a step's outputs follow the rows up to it), every step once, and the same rows as a run
//! kept in memory.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use bondgraph::*;
use common::*;

/// Every call a sink receives, in order: (is a step, t, first output).
#[derive(Default)]
struct Calls {
    calls: Vec<(bool, f64, f64)>,
}

impl RowSink for Calls {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        self.calls.push((false, row[0], row[1]));
        Ok(())
    }
    fn wants_steps(&self) -> bool {
        true
    }
    fn step(&mut self, values: &[f64]) {
        self.calls.push((true, values[0], values[1]));
    }
}

/// Rows (every 0.01 s, several between two steps) and steps reach the sink in time order,
/// with an event inside the run, for Radau and a diffsol method; the rows are bit for bit
/// those of a run kept in memory, and every step is shown once.
#[test]
fn rows_and_steps_reach_the_sink_in_time_order() {
    for method in [Method::Radau5, Method::Bdf] {
        let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
        let damper = eqs.graph().find("damper").unwrap();
        let x0 = eqs.initial_state();
        let outs = [output(&eqs, "spring.q"), output(&eqs, "damper.e")];
        let s = settings(method, 1.0, 0.01, 1e-6, 1e-10);
        let event = || Event {
            t: 0.437,
            replacements: vec![(damper, Box::new(Resistor::new(2.0).unwrap()))],
        };
        let kept = simulate(&mut eqs, &x0, &s, &outs, vec![event()]);
        let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
        let mut sink = Calls::default();
        let run = simulate_into(&mut eqs, &x0, &s, &outs, vec![event()], &mut sink);
        assert!(run.error.is_none(), "{method:?}: {:?}", run.error);
        let steps: Vec<f64> = sink.calls.iter().filter(|c| c.0).map(|c| c.1).collect();
        assert_eq!(steps.len(), run.stats.steps, "{method:?}");
        // rows inside steps, not only on their ends: what the order is about
        let inside = sink.calls.iter().filter(|c| !c.0).any(|c| {
            steps
                .windows(2)
                .any(|w| w[0] < c.1 && c.1 < w[1] && c.1 - w[0] > 1e-9 && w[1] - c.1 > 1e-9)
        });
        assert!(inside, "{method:?}: no row between two steps");
        for w in sink.calls.windows(2) {
            assert!(w[0].1 <= w[1].1, "{method:?}: {:?} before {:?}", w[0], w[1]);
        }
        let rows: Vec<(f64, f64)> = sink
            .calls
            .iter()
            .filter(|c| !c.0)
            .map(|c| (c.1, c.2))
            .collect();
        assert_eq!(rows.len(), kept.trajectory.rows.len());
        for (r, k) in rows.iter().zip(&kept.trajectory.rows) {
            assert_eq!(r.0.to_bits(), k[0].to_bits());
            assert_eq!(r.1.to_bits(), k[1].to_bits(), "{method:?} at t = {}", r.0);
        }
    }
}
