//! Causality assignment and equation ordering: derivative causality, causal conflicts and
//! algebraic loops are refused with errors naming the elements; sources next to resistors in
//! conductance causality are not mistaken for algebraic loops.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use approx::assert_abs_diff_eq;
use bondgraph::*;
use common::*;

/// Two inertias rigidly on one 1-junction, pushed by a force: the second inertia's velocity
/// is imposed by the first, so one of them is in derivative causality.
#[test]
fn rigidly_coupled_inertias_are_derivative_causality() {
    let mut g = BondGraph::new();
    g.add("force", EffortSource::new(1.0)).unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("wheel", Inertia::new(2.0, 0.0).unwrap()).unwrap();
    g.add("axle", Inertia::new(0.5, 0.0).unwrap()).unwrap();
    bond_all(&mut g, &[("force", "v"), ("v", "wheel"), ("v", "axle")]);
    let err = assign_causality(g).unwrap_err();
    let text = err.to_string();
    match &err {
        Error::Causality(CausalityError::Derivative {
            element,
            kind,
            bond,
            ..
        }) => {
            assert!(element == "wheel" || element == "axle", "element {element}");
            assert_eq!(kind, "I");
            assert!(bond == "b2" || bond == "b3", "bond {bond}");
        }
        other => panic!("expected derivative causality, got {other:?}"),
    }
    assert!(
        text.contains("wheel") && text.contains("axle"),
        "message must name both inertias: {text}"
    );
    assert!(text.contains("rigidly coupled inertias"), "hint: {text}");
}

/// Two capacitors on one 0-junction (compliances in parallel): derivative causality on a C.
#[test]
fn parallel_capacitors_are_derivative_causality() {
    let mut g = BondGraph::new();
    g.add("flow", FlowSource::new(1.0)).unwrap();
    g.add("p", ZeroJunction).unwrap();
    g.add("tank_a", Capacitor::new(1.0, 0.0).unwrap()).unwrap();
    g.add("tank_b", Capacitor::new(2.0, 0.0).unwrap()).unwrap();
    bond_all(&mut g, &[("flow", "p"), ("p", "tank_a"), ("p", "tank_b")]);
    let err = assign_causality(g).unwrap_err();
    let text = err.to_string();
    assert!(
        matches!(&err, Error::Causality(CausalityError::Derivative { kind, .. }) if kind == "C"),
        "{err:?}"
    );
    assert!(text.contains("tank_a") && text.contains("tank_b"), "{text}");
}

/// Two inertias on both sides of a lever without compliance between them: derivative
/// causality propagated through a TF.
#[test]
fn inertias_rigidly_coupled_through_a_transformer_are_derivative_causality() {
    let mut g = BondGraph::new();
    let j1 = g.add("j1", OneJunction).unwrap();
    let m1 = g.add("m1", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    let tf = g.add("lever", Transformer::new(2.0).unwrap()).unwrap();
    let j2 = g.add("j2", OneJunction).unwrap();
    let m2 = g.add("m2", Inertia::new(1.0, 0.0).unwrap()).unwrap();
    let k = g.add("spring", Capacitor::new(0.01, 0.0).unwrap()).unwrap();
    g.connect((j1, None), (m1, Some(0))).unwrap();
    g.connect((j1, None), (k, Some(0))).unwrap();
    g.connect((j1, None), (tf, Some(0))).unwrap();
    g.connect((tf, Some(1)), (j2, None)).unwrap();
    g.connect((j2, None), (m2, Some(0))).unwrap();
    let err = assign_causality(g).unwrap_err();
    let text = err.to_string();
    assert!(
        matches!(&err, Error::Causality(CausalityError::Derivative { kind, .. }) if kind == "I"),
        "{err:?}"
    );
    assert!(
        text.contains("m1") && text.contains("m2") && text.contains("lever"),
        "{text}"
    );
}

/// Two effort sources on one 0-junction impose the same effort: a causal conflict.
#[test]
fn two_effort_sources_on_a_zero_junction_conflict() {
    let mut g = BondGraph::new();
    g.add("supply", EffortSource::new(10.0)).unwrap();
    g.add("battery", EffortSource::new(12.0)).unwrap();
    g.add("node", ZeroJunction).unwrap();
    g.add("load", Resistor::new(5.0).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[("supply", "node"), ("battery", "node"), ("node", "load")],
    );
    let err = assign_causality(g).unwrap_err();
    let text = err.to_string();
    match &err {
        Error::Causality(CausalityError::Conflict { element, kind, .. }) => {
            assert!(element == "supply" || element == "battery", "{element}");
            assert_eq!(kind, "Se");
        }
        other => panic!("expected a conflict, got {other:?}"),
    }
    assert!(
        text.contains("supply") && text.contains("battery") && text.contains("node"),
        "{text}"
    );
}

/// Two flow sources on one 1-junction impose the same flow: a causal conflict.
#[test]
fn two_flow_sources_on_a_one_junction_conflict() {
    let mut g = BondGraph::new();
    g.add("pump_a", FlowSource::new(1.0)).unwrap();
    g.add("pump_b", FlowSource::new(2.0)).unwrap();
    g.add("line", OneJunction).unwrap();
    g.add("orifice", Resistor::new(5.0).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[("pump_a", "line"), ("pump_b", "line"), ("line", "orifice")],
    );
    let err = assign_causality(g).unwrap_err();
    assert!(
        matches!(&err, Error::Causality(CausalityError::Conflict { kind, .. }) if kind == "Sf"),
        "{err:?}"
    );
}

/// Se → 1a (R1) → 0 (R2) → 1b (R3, C). With one state (q of C), the node effort e0 and the
/// source current i1 depend on each other whatever causality the resistors get:
/// e0 = V − R1·i1 and i1 = e0/R2 + (e0 − q/C)/R3. SCAP leaves R1 in resistance causality and
/// forces R2 and R3 into conductance; the plan's cycle runs ja → R1 → ja → node → R2, jb, R3
/// → node. The source (its effort depends on nothing) and C (a state) are not in it.
#[test]
fn resistive_loop_is_an_algebraic_loop_naming_its_elements() {
    let mut g = BondGraph::new();
    g.add("src", EffortSource::new(1.0)).unwrap();
    g.add("ja", OneJunction).unwrap();
    g.add("R1", Resistor::new(1.0).unwrap()).unwrap();
    g.add("node", ZeroJunction).unwrap();
    g.add("R2", Resistor::new(2.0).unwrap()).unwrap();
    g.add("jb", OneJunction).unwrap();
    g.add("R3", Resistor::new(3.0).unwrap()).unwrap();
    g.add("C", Capacitor::new(1.0, 0.0).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[
            ("src", "ja"),
            ("ja", "R1"),
            ("ja", "node"),
            ("node", "R2"),
            ("node", "jb"),
            ("jb", "R3"),
            ("jb", "C"),
        ],
    );
    let causal =
        assign_causality(g).expect("causality is assignable; the loop is in the equations");
    let err = StateEquations::new(causal).unwrap_err();
    let text = err.to_string();
    match &err {
        Error::Causality(CausalityError::AlgebraicLoop {
            elements, bonds, ..
        }) => {
            for name in ["ja", "R1", "node", "R2", "jb", "R3"] {
                assert!(
                    elements.iter().any(|e| e == name),
                    "loop {elements:?} lacks {name}"
                );
            }
            // A source's effort depends on nothing: it cannot be part of an algebraic loop.
            assert!(
                !elements.iter().any(|e| e == "src"),
                "the source is not in the loop: {elements:?}"
            );
            // Nor is the capacitor: its effort comes from its state.
            assert!(!elements.iter().any(|e| e == "C"), "{elements:?}");
            assert_eq!(elements.len(), 6, "{elements:?}");
            // Bonds: ja–R1 (b2), ja–node (b3), node–R2 (b4), node–jb (b5), jb–R3 (b6).
            for b in ["b2", "b3", "b4", "b5", "b6"] {
                assert!(
                    bonds.iter().any(|x| x == b),
                    "loop bonds {bonds:?} lack {b}"
                );
            }
        }
        other => panic!("expected an algebraic loop, got {other:?}"),
    }
    assert!(text.contains("R1") && text.contains("R2"), "{text}");
}

/// RC charging: Se → 1 (R, C). C sets the effort, so R takes conductance causality and the
/// junction's flow comes from R: i = (V − q/C)/R. Nothing here is an algebraic loop (the
/// source's effort depends on nothing); the plan must build and the charge follow
/// q = C·V·(1 − e^{−t/RC}).
#[test]
fn effort_source_beside_conductance_resistor_is_not_an_algebraic_loop() {
    let (v, r, c) = (5.0, 2.0, 0.1);
    let mut g = BondGraph::new();
    g.add("src", EffortSource::new(v)).unwrap();
    g.add("j", OneJunction).unwrap();
    g.add("R", Resistor::new(r).unwrap()).unwrap();
    g.add("C", Capacitor::new(c, 0.0).unwrap()).unwrap();
    bond_all(&mut g, &[("src", "j"), ("j", "R"), ("j", "C")]);
    let causal = assign_causality(g).unwrap();
    let r_id = causal.graph.find("R").unwrap();
    assert_eq!(
        causal.element_causality(r_id),
        vec![PortCausality::FlowOut],
        "R in conductance causality"
    );
    let mut eqs =
        StateEquations::new(causal).unwrap_or_else(|e| panic!("false algebraic loop: {e}"));
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "C.q")];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.0, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let q_end = *col(&run.trajectory, "C.q").last().unwrap();
    assert_abs_diff_eq!(
        q_end,
        c * v * (1.0 - (-1.0 / (r * c)).exp()),
        epsilon = 1e-7 * c * v
    );
}

/// The dual: Sf → 0 (R, I). The source and the inertia both set their flows, so the
/// 0-junction's effort comes from R in resistance causality, e = r·(f − i_L); the source's
/// flow must not be made to depend on that effort.
#[test]
fn flow_source_beside_resistor_is_not_an_algebraic_loop() {
    let (f, r, l) = (3.0, 2.0, 0.5);
    let mut g = BondGraph::new();
    g.add("src", FlowSource::new(f)).unwrap();
    g.add("z", ZeroJunction).unwrap();
    g.add("R", Resistor::new(r).unwrap()).unwrap();
    g.add("L", Inertia::new(l, 0.0).unwrap()).unwrap();
    bond_all(&mut g, &[("src", "z"), ("z", "R"), ("z", "L")]);
    let mut eqs = StateEquations::new(assign_causality(g).unwrap())
        .unwrap_or_else(|e| panic!("false algebraic loop: {e}"));
    // Current divider with an inductor: i_L' = (r/l)·(f − i_L), i_L(t) = f·(1 − e^{−rt/l}).
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "L.f")];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 0.5, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let i_end = *col(&run.trajectory, "L.f").last().unwrap();
    assert_abs_diff_eq!(i_end, f * (1.0 - (-r * 0.5 / l).exp()), epsilon = 1e-7 * f);
}

/// A junction structure with a cycle that sources and storages leave undecided, so SCAP's
/// last step orients bonds arbitrarily: three 0-junctions Z1..Z3 (each with an inertia) and
/// three 1-junctions J1..J3 (each with a compliance), every Zi bonded to every Jj (K₃,₃).
/// Integral causality exists: each Zi takes its effort from one Jσ(i) for a permutation σ.
/// The arbitrary choices must respect the rules of both ends; the equations then hold a real
/// algebraic loop (each Z's effort is a sum over the other Z's efforts), which
/// `StateEquations::new` reports.
#[test]
fn arbitrary_orientation_of_a_junction_cycle_respects_both_ends() {
    let mut g = BondGraph::new();
    for i in 1..=3 {
        g.add(&format!("Z{i}"), ZeroJunction).unwrap();
        g.add(&format!("J{i}"), OneJunction).unwrap();
        g.add(&format!("I{i}"), Inertia::new(1.0, 0.0).unwrap())
            .unwrap();
        g.add(&format!("C{i}"), Capacitor::new(1.0, 0.0).unwrap())
            .unwrap();
    }
    for i in 1..=3 {
        bond_all(
            &mut g,
            &[
                (&format!("Z{i}"), &format!("I{i}")),
                (&format!("J{i}"), &format!("C{i}")),
            ],
        );
    }
    for i in 1..=3 {
        for j in 1..=3 {
            bond_all(&mut g, &[(&format!("Z{i}"), &format!("J{j}"))]);
        }
    }
    let causal = assign_causality(g)
        .unwrap_or_else(|e| panic!("a valid integral causality exists, but: {e}"));
    for i in 1..=3 {
        for (name, dominant) in [
            (format!("Z{i}"), PortCausality::FlowOut),
            (format!("J{i}"), PortCausality::EffortOut),
        ] {
            let c = causal.element_causality(causal.graph.find(&name).unwrap());
            assert_eq!(
                c.iter().filter(|&&x| x == dominant).count(),
                1,
                "{name}: {c:?}"
            );
        }
        assert_eq!(
            causal.element_causality(causal.graph.find(&format!("I{i}")).unwrap()),
            vec![PortCausality::FlowOut]
        );
        assert_eq!(
            causal.element_causality(causal.graph.find(&format!("C{i}")).unwrap()),
            vec![PortCausality::EffortOut]
        );
    }
    match StateEquations::new(causal).unwrap_err() {
        Error::Causality(CausalityError::AlgebraicLoop { elements, .. }) => {
            assert!(
                elements
                    .iter()
                    .all(|e| e.starts_with('Z') || e.starts_with('J')),
                "{elements:?}"
            );
            assert_eq!(elements.len(), 6, "{elements:?}");
        }
        other => panic!("expected an algebraic loop, got {other:?}"),
    }
}

/// SCAP on the mass–spring–damper: mass flow out, spring effort out, damper in resistance
/// causality; the 1-junction's dominant bond is the mass's.
#[test]
fn mass_spring_damper_gets_integral_causality() {
    let mut g = BondGraph::new();
    g.add("force", EffortSource::new(1.0)).unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(2.0, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(0.02, 0.0).unwrap()).unwrap();
    g.add("damper", Resistor::new(3.0).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[
            ("force", "v"),
            ("v", "mass"),
            ("v", "spring"),
            ("v", "damper"),
        ],
    );
    let causal = assign_causality(g).unwrap();
    let id = |n: &str| causal.graph.find(n).unwrap();
    assert_eq!(
        causal.element_causality(id("force")),
        vec![PortCausality::EffortOut]
    );
    assert_eq!(
        causal.element_causality(id("mass")),
        vec![PortCausality::FlowOut]
    );
    assert_eq!(
        causal.element_causality(id("spring")),
        vec![PortCausality::EffortOut]
    );
    assert_eq!(
        causal.element_causality(id("damper")),
        vec![PortCausality::EffortOut]
    );
    use PortCausality::{EffortOut, FlowOut};
    assert_eq!(
        causal.element_causality(id("v")),
        vec![FlowOut, EffortOut, FlowOut, FlowOut]
    );
}
