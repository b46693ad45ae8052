//! Element state limits stop a run exactly at the crossing, with the rows before kept.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bondgraph::*;

/// A signal block integrating a constant rate, with a bound on its state.
#[derive(Debug)]
struct Ramp {
    rate: f64,
    lower: f64,
    upper: f64,
}

impl Element for Ramp {
    fn kind(&self) -> &str {
        "ramp"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("y", 0.0)]
    }
    fn eval(&self, _: usize, _: &mut Io<'_>) {}
    fn derivatives(&self, _: &Io<'_>, dx: &mut [f64]) {
        dx[0] = self.rate;
    }
    fn limits(&self) -> Vec<Limit> {
        vec![Limit {
            state: 0,
            lower: self.lower,
            upper: self.upper,
            message: "the ramp ran out".into(),
            hint: None,
        }]
    }
}

fn run(rate: f64, lower: f64, upper: f64, method: Method) -> Outcome {
    let mut g = BondGraph::new();
    g.add("ramp", Ramp { rate, lower, upper }).unwrap();
    let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let x0 = eqs.initial_state();
    let settings = Settings {
        t_end: 2.0,
        dt_out: 0.1,
        method,
        ..Settings::default()
    };
    let out = [Output {
        name: "y".into(),
        probe: eqs.probe("ramp.y").unwrap(),
    }];
    simulate(&mut eqs, &x0, &settings, &out, vec![])
}

#[test]
fn upper_limit_stops_the_run_at_the_crossing() {
    for method in Method::ALL {
        let o = run(2.0, -1.0, 1.05, method);
        match &o.error {
            Some(SimulationError::LimitReached {
                t,
                which,
                limit,
                element,
                ..
            }) => {
                assert!((t - 0.525).abs() < 1e-6, "{method:?}: t = {t}");
                assert_eq!((*which, *limit, element.as_str()), ("upper", 1.05, "ramp"));
            }
            other => panic!("{method:?}: expected LimitReached, got {other:?}"),
        }
        assert!((o.t_final - 0.525).abs() < 1e-6);
        assert!((o.x_final[0] - 1.05).abs() < 1e-5, "{}", o.x_final[0]);
        // rows at 0, 0.1, …, 0.5 are kept; none after the crossing
        assert_eq!(o.trajectory.rows.len(), 6, "{method:?}");
        assert!(o.trajectory.rows.iter().all(|r| r[1] <= 1.05));
    }
}

#[test]
fn lower_limit_and_a_start_outside_are_reported() {
    let o = run(-1.0, -0.25, 10.0, Method::Bdf);
    assert!(
        matches!(
            o.error,
            Some(SimulationError::LimitReached { which: "lower", .. })
        ),
        "{:?}",
        o.error
    );
    assert!((o.t_final - 0.25).abs() < 1e-6);
    let o = run(1.0, 0.5, 10.0, Method::Bdf);
    assert!(
        matches!(o.error, Some(SimulationError::LimitReached { t, .. }) if t == 0.0),
        "{:?}",
        o.error
    );
    assert!(o.trajectory.rows.is_empty());
}

#[test]
fn a_run_inside_its_limits_is_unaffected() {
    let o = run(0.1, -1.0, 1.0, Method::Bdf);
    assert!(o.error.is_none());
    assert_eq!(o.trajectory.rows.len(), 21);
    assert!((o.x_final[0] - 0.2).abs() < 1e-9);
}
