#![allow(clippy::unwrap_used)]
use super::*;
use crate::Resistor;
use crate::{assign_causality, BondGraph, Capacitor, EffortSource, Inertia, OneJunction};

/// A mass on a spring under a constant force F: at rest the spring holds F, q = F/k.
fn hanging(force: f64, k: f64) -> StateEquations {
    let mut g = BondGraph::new();
    g.add("force", EffortSource::new(force)).unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(2.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(1.0 / k, 0.0).unwrap())
        .unwrap();
    g.add("damper", Resistor::new(3.0).unwrap()).unwrap();
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

fn index(eqs: &StateEquations, name: &str) -> usize {
    eqs.states().iter().position(|s| s.name == name).unwrap()
}

#[test]
fn spring_preload_is_force_over_stiffness() {
    let eqs = hanging(-98.1, 5e4);
    let (q, p) = (index(&eqs, "spring.q"), index(&eqs, "mass.p"));
    let req = SteadyRequest::new(
        vec![q],
        vec![Condition::Derivative {
            state: p,
            value: 0.0,
        }],
    );
    let eq = solve_steady(&eqs, 0.0, &eqs.initial_state(), &req).unwrap();
    let exact = -98.1 / 5e4;
    assert!(
        (eq.x[q] - exact).abs() <= 1e-12 * exact.abs(),
        "{}",
        eq.x[q]
    );
    assert!(eq.iterations <= 2, "linear: {}", eq.iterations);
    assert_eq!(eq.residuals[0].0, "mass.p.dot = 0");
}

#[test]
fn a_state_condition_and_a_count_mismatch() {
    let eqs = hanging(-10.0, 100.0);
    let (q, p) = (index(&eqs, "spring.q"), index(&eqs, "mass.p"));
    let req = SteadyRequest::new(
        vec![q, p],
        vec![
            Condition::Derivative {
                state: p,
                value: 0.0,
            },
            Condition::State {
                state: p,
                value: 0.5,
            },
        ],
    );
    // mass.p = 0.5 moves at v = 0.25: the damper adds 0.75 N, the spring holds the rest
    let eq = solve_steady(&eqs, 0.0, &eqs.initial_state(), &req).unwrap();
    assert!((eq.x[p] - 0.5).abs() < 1e-14);
    assert!((eq.x[q] - (-10.0 - 0.75) / 100.0).abs() < 1e-14);
    let bad = SteadyRequest::new(vec![q, p], req.conditions[..1].to_vec());
    let e = solve_steady(&eqs, 0.0, &eqs.initial_state(), &bad).unwrap_err();
    assert!(matches!(e, EquilibriumError::CountMismatch { .. }), "{e}");
    assert!(e
        .to_string()
        .contains("2 unknowns (spring.q, mass.p) but 1 conditions"));
}

#[test]
fn a_jacobian_that_turns_non_finite_ends_the_solve_instead_of_panicking() {
    // Two masses on springs; the first force F(q) = 1 − 3q − q² has a gradient that is NaN
    // once q leaves the start: the first Newton step lands at q = 0.25 with finite
    // residuals and a NaN in the Jacobian. Before, nalgebra's SVD of that Jacobian panicked
    // (sorting NaN singular values) or, on the loader fuzzer's mutated lift circuit, never
    // returned; now the solve stops with "no equilibrium found".
    let mut g = BondGraph::new();
    let law = crate::Param::modulated_exact(
        vec!["spring.q".into()],
        |_, u| 1.0 - 3.0 * u[0] - u[0] * u[0],
        |_, u, grad| {
            grad[0] = if u[0].abs() < 0.1 {
                -3.0 - 2.0 * u[0]
            } else {
                f64::NAN
            };
            1.0 - 3.0 * u[0] - u[0] * u[0]
        },
    );
    g.add("force", EffortSource::new(law)).unwrap();
    g.add("force2", EffortSource::new(2.0)).unwrap();
    for (j, m, k) in [("v", "mass", "spring"), ("v2", "mass2", "spring2")] {
        g.add(j, OneJunction).unwrap();
        g.add(m, Inertia::new(1.0, 0.0).unwrap()).unwrap();
        g.add(k, Capacitor::new(1.0, 0.0).unwrap()).unwrap();
    }
    for (a, b) in [
        ("force", "v"),
        ("v", "mass"),
        ("v", "spring"),
        ("force2", "v2"),
        ("v2", "mass2"),
        ("v2", "spring2"),
    ] {
        g.connect_names(a, b).unwrap();
    }
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let (q, p) = (index(&eqs, "spring.q"), index(&eqs, "mass.p"));
    let (q2, p2) = (index(&eqs, "spring2.q"), index(&eqs, "mass2.p"));
    let req = SteadyRequest::new(
        vec![q, q2],
        vec![
            Condition::Derivative {
                state: p,
                value: 0.0,
            },
            Condition::Derivative {
                state: p2,
                value: 0.0,
            },
        ],
    );
    let e = solve_steady(&eqs, 0.0, &eqs.initial_state(), &req).unwrap_err();
    assert!(matches!(e, EquilibriumError::NoEquilibrium { .. }), "{e}");
}

#[test]
fn a_force_nothing_can_balance_is_refused_naming_residuals() {
    // F(q) = −(1 + q²) against a unit spring: ṗ = −(q² + q + 1) < 0 for every q.
    let mut g = BondGraph::new();
    let law = crate::Param::modulated(vec!["spring.q".into()], |_, u| -(1.0 + u[0] * u[0]));
    g.add("force", EffortSource::new(law)).unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(1.0, 0.0).unwrap()).unwrap();
    for (a, b) in [("force", "v"), ("v", "mass"), ("v", "spring")] {
        g.connect_names(a, b).unwrap();
    }
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let (q, p) = (index(&eqs, "spring.q"), index(&eqs, "mass.p"));
    let req = SteadyRequest::new(
        vec![q],
        vec![Condition::Derivative {
            state: p,
            value: 0.0,
        }],
    );
    let e = solve_steady(&eqs, 0.0, &eqs.initial_state(), &req).unwrap_err();
    assert!(
        matches!(
            e,
            EquilibriumError::NoEquilibrium { .. } | EquilibriumError::Singular { .. }
        ),
        "{e}"
    );
    let text = e.to_string();
    assert!(
        text.contains("spring.q") && text.contains("mass.p.dot = 0"),
        "{text}"
    );
}

#[test]
fn an_unknown_no_condition_depends_on_is_singular() {
    let eqs = hanging(-1.0, 1.0);
    let (q, p) = (index(&eqs, "spring.q"), index(&eqs, "mass.p"));
    // two conditions on ṗ only: rank 1
    let req = SteadyRequest::new(
        vec![q, p],
        vec![
            Condition::Derivative {
                state: p,
                value: 0.0,
            },
            Condition::Derivative {
                state: p,
                value: 0.0,
            },
        ],
    );
    let e = solve_steady(&eqs, 0.0, &eqs.initial_state(), &req).unwrap_err();
    let EquilibriumError::Singular { unknowns, .. } = &e else {
        panic!("{e}")
    };
    assert!(!unknowns.is_empty(), "{e}");
    assert!(e.to_string().contains("mass.p.dot = 0"), "{e}");
}

/// Each condition's own scale (issue 24, item 1): a rate by the state's error weight
/// per span, a state by its weight, a variable by atol + rtol·max(|v|, |value|), each
/// times OWN_SCALE_FRACTION; a pressure rate (Pa/s, p = 2e7) and a momentum rate (N,
/// p = 0) get tolerances eleven orders apart, each in its own units.
#[test]
fn each_condition_has_its_own_scale() {
    let settle = Settle {
        atol: 1e-8,
        rtol: 1e-6,
        span: 20.0,
    };
    let x = [2e7, 0.0];
    let rate = |state| Condition::Derivative { state, value: 0.0 };
    let pressure = settle.tolerance(&rate(0), &x, x[0]);
    let momentum = settle.tolerance(&rate(1), &x, x[1]);
    let f = OWN_SCALE_FRACTION;
    assert!(
        (pressure - f * (1e-8 + 20.0) / 20.0).abs() < 1e-12 * pressure,
        "{pressure}"
    );
    assert!(
        (momentum - f * 1e-8 / 20.0).abs() < 1e-12 * momentum,
        "{momentum}"
    );
    let state = settle.tolerance(
        &Condition::State {
            state: 0,
            value: 2e7,
        },
        &x,
        x[0],
    );
    assert!((state - f * (1e-8 + 20.0)).abs() < 1e-12 * state, "{state}");
}

/// A solve that cannot reach `tol` (here: 1e-30, below any rounding floor) is refused
/// without [`Settle`], and accepted with it when every residual is within its own
/// scale, the conditions so judged listed; tolerances below the floor still refuse it.
#[test]
fn a_stalled_solve_is_judged_in_each_conditions_own_scale() {
    let eqs = hanging(-98.1, 5e4);
    let (q, p) = (index(&eqs, "spring.q"), index(&eqs, "mass.p"));
    let mut req = SteadyRequest::new(
        vec![q],
        vec![Condition::Derivative {
            state: p,
            value: 0.0,
        }],
    );
    req.tol = 1e-30;
    req.max_iterations = 3;
    let x0 = eqs.initial_state();
    // a non-zero residual: start off the solution so rounding is left
    let mut start = x0.clone();
    start[q] = 1e-3;
    match solve_steady(&eqs, 0.0, &start, &req) {
        Err(e) => assert!(e.to_string().contains("mass.p.dot = 0"), "{e}"),
        Ok(eq) => assert!(eq.residuals[0].1 == 0.0, "{:?}", eq.residuals),
    }
    req.settle = Some(Settle {
        atol: 1e-8,
        rtol: 1e-6,
        span: 10.0,
    });
    let eq = solve_steady(&eqs, 0.0, &start, &req).unwrap();
    assert!((eq.x[q] + 98.1 / 5e4).abs() < 1e-12, "{}", eq.x[q]);
    for (name, r, tol) in &eq.own_scale {
        assert_eq!(name, "mass.p.dot = 0");
        let want = OWN_SCALE_FRACTION * 1e-8 / 10.0;
        assert!(
            r.abs() <= *tol && (*tol - want).abs() <= 1e-12 * want,
            "{r} {tol}"
        );
    }
}
