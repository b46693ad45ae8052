//! External inputs ([`Input`]) through the library API: listed, set by index and name,
//! following a series whose corners the run stops on, read as a column.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use bondgraph::*;
use common::*;

/// m ẍ + c ẋ + k x = F: mass, spring, damper on a 1-junction, the force an effort source
/// modulated by the input `F`.
fn msd() -> StateEquations {
    let mut g = BondGraph::new();
    let spec = InputSpec {
        name: "F".into(),
        unit: "N".into(),
        default: 0.0,
        description: "force on the mass".into(),
    };
    g.add("F", Input::new(spec).unwrap()).unwrap();
    g.add(
        "force",
        EffortSource::new(Param::modulated(vec!["F".into()], |_, u| u[0])),
    )
    .unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(1.0 / 100.0, 0.0).unwrap())
        .unwrap();
    g.add("damper", Resistor::new(2.0).unwrap()).unwrap();
    for (from, to) in [
        ("force", "v"),
        ("v", "mass"),
        ("v", "spring"),
        ("v", "damper"),
    ] {
        g.connect_names(from, to).unwrap();
    }
    assemble(g)
}

/// x(t) of the system above for a step F at t_s (ζ = 0.1, ω = 10).
fn step_response(f: f64, t_s: f64, t: f64) -> f64 {
    if t < t_s {
        return 0.0;
    }
    let (wn, zeta) = (10.0_f64, 0.1_f64);
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let s = t - t_s;
    f / 100.0 * (1.0 - (-zeta * wn * s).exp() * ((wd * s).cos() + zeta * wn / wd * (wd * s).sin()))
}

#[test]
fn inputs_are_listed_and_set_by_index_or_name() {
    let eqs = msd();
    assert_eq!(eqs.n_inputs(), 1);
    let list = eqs.inputs();
    assert_eq!(list[0].name, "F");
    assert_eq!(list[0].unit, "N");
    assert_eq!(eqs.input_index("F").unwrap(), 0);
    let e = eqs.input_index("f").unwrap_err();
    assert!(e.to_string().contains("did you mean `F`"), "{e}");
    assert!(eqs.set_input(3, 1.0).is_err());
    eqs.set_input_by_name("F", 10.0).unwrap();
    assert_eq!(eqs.input_value(0, 0.0).unwrap(), 10.0);
    // the force reaches the mass: dp/dt = F at rest
    let mut dx = vec![0.0; eqs.n_states()];
    eqs.rhs(0.0, &eqs.initial_state(), &mut dx);
    assert!(dx.contains(&10.0), "{dx:?}");
    // the input is a probe (a column) and a signal of the plan
    let p = eqs.probe("F").unwrap();
    assert_eq!(p, eqs.input_probe(0).unwrap());
    eqs.reset_input(0).unwrap();
    assert_eq!(eqs.input_value(0, 0.0).unwrap(), 0.0);
}

/// A held step at t = 0.5 from a series: the run stops on the corner and matches the
/// analytic response; the held value is right-continuous in the output column.
#[test]
fn a_series_step_is_a_breakpoint_and_the_response_is_exact() {
    for stop in [true, false] {
        let mut eqs = msd();
        eqs.set_stop_at_breakpoints(stop);
        let s = Series::new(vec![0.0, 0.5, 3.0], vec![0.0, 10.0, 10.0], Interp::Hold).unwrap();
        eqs.set_input_series(0, s).unwrap();
        assert_eq!(eqs.input_breakpoints(0).unwrap(), [0.0, 0.5, 3.0]);
        assert_eq!(eqs.next_breakpoint(0.0), stop.then_some(0.5));
        let outs = [output(&eqs, "spring.q"), output(&eqs, "F")];
        let x0 = eqs.initial_state();
        let run = simulate(
            &mut eqs,
            &x0,
            &settings(Method::Radau5, 3.0, 0.01, 1e-10, 1e-12),
            &outs,
            vec![],
        );
        assert!(run.error.is_none(), "{:?}", run.error);
        let tr = &run.trajectory;
        let worst = col(tr, "t")
            .iter()
            .zip(col(tr, "spring.q"))
            .map(|(&t, x)| (x - step_response(10.0, 0.5, t)).abs())
            .fold(0.0, f64::max);
        let f = col(tr, "F");
        assert_eq!(f[50], 10.0, "the row at the corner holds the new value");
        assert_eq!(f[49], 0.0);
        if stop {
            assert!(worst < 1e-8, "worst error {worst:e} with stops");
        } else {
            // stepping over the corner: the error control copes, less exactly
            assert!(worst < 1e-4, "worst error {worst:e} without stops");
        }
    }
}
