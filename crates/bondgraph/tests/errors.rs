//! Structural errors, each a specific `GraphError` variant naming the culprit: unconnected
//! ports, duplicate names, dimension mismatches, unknown signals, port misuse, bad
//! replacements.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use bondgraph::*;
use common::*;

fn graph_error(err: Error) -> GraphError {
    match err {
        Error::Graph(g) => g,
        other => panic!("expected a graph error, got {other:?}"),
    }
}

#[test]
fn unconnected_port_is_reported_with_element_kind_and_port() {
    let mut g = BondGraph::new();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(0.01, 0.0).unwrap()).unwrap();
    g.add("damper", Resistor::new(0.4).unwrap()).unwrap(); // never bonded
    bond_all(&mut g, &[("v", "mass"), ("v", "spring")]);
    let err = graph_error(assign_causality(g).unwrap_err());
    assert_eq!(
        err,
        GraphError::Unconnected {
            element: "damper".into(),
            kind: "R".into(),
            port: "1".into()
        }
    );
    assert!(err.to_string().contains("`damper`"), "{err}");
}

#[test]
fn junction_without_bonds_is_reported() {
    let mut g = BondGraph::new();
    g.add("lonely", ZeroJunction).unwrap();
    let err = graph_error(assign_causality(g).unwrap_err());
    assert_eq!(
        err,
        GraphError::EmptyJunction {
            element: "lonely".into()
        }
    );
}

#[test]
fn duplicate_name_is_refused_and_the_graph_is_unchanged() {
    let mut g = BondGraph::new();
    g.add("spring", Capacitor::new(0.01, 0.0).unwrap()).unwrap();
    let err = g.add("spring", Resistor::new(1.0).unwrap()).unwrap_err();
    assert_eq!(
        err,
        GraphError::DuplicateName {
            name: "spring".into()
        }
    );
    assert_eq!(g.n_elements(), 1);
    assert_eq!(g.node(0).element.kind(), "C");
}

/// A planar inertia (2-bond) bonded straight to a scalar capacitor.
#[test]
fn multibond_inertia_on_scalar_capacitor_is_a_dimension_mismatch() {
    let mut g = BondGraph::new();
    g.add("puck", Inertia::multi(1.0, vec![0.0, 0.0]).unwrap())
        .unwrap();
    g.add("spring", Capacitor::new(0.01, 0.0).unwrap()).unwrap();
    g.connect_names("puck", "spring").unwrap();
    match graph_error(assign_causality(g).unwrap_err()) {
        GraphError::DimensionMismatch { element, message } => {
            assert!(element == "spring" || element == "puck", "{element}");
            assert!(
                message.contains("puck") && message.contains("spring"),
                "{message}"
            );
            assert!(message.contains('2') && message.contains('1'), "{message}");
        }
        other => panic!("expected a dimension mismatch, got {other:?}"),
    }
}

/// The same mismatch through a junction: its bonds must share one dimension.
#[test]
fn junction_joining_two_and_one_dimensional_bonds_is_a_dimension_mismatch() {
    let mut g = BondGraph::new();
    g.add("v", OneJunction).unwrap();
    g.add("puck", Inertia::multi(1.0, vec![0.0, 0.0]).unwrap())
        .unwrap();
    g.add("spring", Capacitor::new(0.01, 0.0).unwrap()).unwrap();
    bond_all(&mut g, &[("v", "puck"), ("v", "spring")]);
    match graph_error(assign_causality(g).unwrap_err()) {
        GraphError::DimensionMismatch { element, message } => {
            assert_eq!(element, "v");
            assert!(
                message.contains("b1") && message.contains("b2"),
                "{message}"
            );
        }
        other => panic!("expected a dimension mismatch, got {other:?}"),
    }
}

/// A matching planar model builds: the dimension spreads through the junction to the
/// adaptive resistor port, and every state is a component.
#[test]
fn matching_multibond_dimensions_are_inferred() {
    let mut g = BondGraph::new();
    g.add("v", OneJunction).unwrap();
    g.add("puck", Inertia::multi(1.0, vec![1.0, -2.0]).unwrap())
        .unwrap();
    g.add("spring", Capacitor::multi(0.01, vec![0.0, 0.0]).unwrap())
        .unwrap();
    g.add("drag", Resistor::new(0.5).unwrap()).unwrap();
    bond_all(&mut g, &[("v", "puck"), ("v", "spring"), ("v", "drag")]);
    let eqs = assemble(g);
    assert!(eqs.graph().bonds().all(|b| b.dim == 2));
    let names: Vec<&str> = eqs.states().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        ["puck.p[0]", "puck.p[1]", "spring.q[0]", "spring.q[1]"]
    );
    // Component-wise law: drag force = 0.5·v per component.
    let x = [1.0, -2.0, 0.0, 0.0];
    eqs.evaluate(0.0, &x);
    for (k, v) in [1.0, -2.0].into_iter().enumerate() {
        let e = eqs.read(eqs.probe(&format!("drag.e[{k}]")).unwrap(), 0.0, &x);
        assert!((e - 0.5 * v).abs() <= 1e-15, "drag.e[{k}] = {e}");
    }
}

/// An MTF whose ratio reads a signal that does not exist.
#[test]
fn unknown_signal_is_reported_with_reader_and_name() {
    let mut g = BondGraph::new();
    g.add("force", EffortSource::new(1.0)).unwrap();
    g.add("j1", OneJunction).unwrap();
    g.add(
        "lever",
        Transformer::new(Param::modulated(vec!["nope.q".into()], |_, u| 1.0 + u[0])).unwrap(),
    )
    .unwrap();
    g.add("j2", OneJunction).unwrap();
    g.add("mass", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[
            ("force", "j1"),
            ("j1", "lever"),
            ("lever", "j2"),
            ("j2", "mass"),
        ],
    );
    let causal = assign_causality(g).unwrap();
    match graph_error(StateEquations::new(causal).unwrap_err()) {
        GraphError::UnknownSignal {
            element,
            signal,
            hint,
        } => {
            assert_eq!(element, "lever");
            assert_eq!(signal, "nope.q");
            assert!(hint.contains("nope"), "{hint}");
        }
        other => panic!("expected an unknown signal, got {other:?}"),
    }
}

/// A near miss suggests what the element offers.
#[test]
fn unknown_signal_of_existing_element_lists_its_signals() {
    let mut g = BondGraph::new();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(0.01, 0.0).unwrap()).unwrap();
    g.add(
        "damper",
        Resistor::new(Param::modulated(vec!["spring.x".into()], |_, u| {
            1.0 + u[0] * u[0]
        }))
        .unwrap(),
    )
    .unwrap();
    bond_all(&mut g, &[("v", "mass"), ("v", "spring"), ("v", "damper")]);
    let err = graph_error(StateEquations::new(assign_causality(g).unwrap()).unwrap_err());
    match &err {
        GraphError::UnknownSignal {
            element,
            signal,
            hint,
        } => {
            assert_eq!((element.as_str(), signal.as_str()), ("damper", "spring.x"));
            assert!(
                hint.contains("spring.q"),
                "hint should offer spring.q: {hint}"
            );
        }
        other => panic!("expected an unknown signal, got {other:?}"),
    }
}

#[test]
fn port_misuse_is_reported() {
    let mut g = BondGraph::new();
    let tf = g.add("lever", Transformer::new(2.0).unwrap()).unwrap();
    let a = g.add("a", OneJunction).unwrap();
    let b = g.add("b", OneJunction).unwrap();
    let c = g.add("c", OneJunction).unwrap();
    // Port 1 twice.
    g.connect((a, None), (tf, Some(0))).unwrap();
    assert_eq!(
        g.connect((b, None), (tf, Some(0))).unwrap_err(),
        GraphError::PortInUse {
            element: "lever".into(),
            kind: "TF".into(),
            port: "1".into()
        }
    );
    // A port that does not exist.
    assert!(
        matches!(g.connect((tf, Some(5)), (b, None)).unwrap_err(), GraphError::NoSuchPort { element, .. } if element == "lever")
    );
    assert!(
        matches!(g.port_index(tf, "3").unwrap_err(), GraphError::NoSuchPort { available, .. } if available == "1, 2")
    );
    // Fill port 2, then a third bond has no free port; the failed attempts left no half-bonds.
    g.connect((tf, None), (b, None)).unwrap();
    assert_eq!(
        g.connect((c, None), (tf, None)).unwrap_err(),
        GraphError::NoFreePort {
            element: "lever".into(),
            kind: "TF".into(),
            n_ports: 2
        }
    );
    assert_eq!(g.n_bonds(), 2);
    assert_eq!(
        g.ports_of(c).len(),
        0,
        "the failed connection must not leave a port on `c`"
    );
    assert_eq!(
        g.connect_names("a", "nowhere").unwrap_err(),
        GraphError::UnknownElement {
            name: "nowhere".into()
        }
    );
}

#[test]
fn replacement_of_different_kind_is_refused() {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let damper = eqs.graph().find("damper").unwrap();
    let err = eqs
        .replace(damper, Box::new(Capacitor::new(1.0, 0.0).unwrap()))
        .unwrap_err();
    assert!(
        matches!(&err, GraphError::Replacement { element, .. } if element == "damper"),
        "{err:?}"
    );
    // Same kind is accepted and returns the old element.
    let old = eqs
        .replace(damper, Box::new(Resistor::new(2.0).unwrap()))
        .unwrap();
    assert_eq!(old.kind(), "R");
}

#[test]
fn invalid_parameters_are_param_errors() {
    assert!(
        matches!(Capacitor::new(-1.0, 0.0).unwrap_err(), ParamError::OutOfRange { param, .. } if param == "c")
    );
    assert!(
        matches!(Inertia::new(0.0, 0.0).unwrap_err(), ParamError::OutOfRange { param, .. } if param == "m")
    );
    assert!(
        matches!(Resistor::new(f64::NAN).unwrap_err(), ParamError::OutOfRange { param, .. } if param == "r")
    );
    assert!(
        matches!(Transformer::new(0.0).unwrap_err(), ParamError::OutOfRange { param, .. } if param == "m")
    );
    assert!(
        matches!(Gyrator::new(0.0).unwrap_err(), ParamError::OutOfRange { param, .. } if param == "r")
    );
    assert!(matches!(
        Inertia::multi(1.0, vec![]).unwrap_err(),
        ParamError::Shape { .. }
    ));
}
