//! Power conservation: at random states, every junction, TF/MTF, matrix MTF and GY of every
//! reference model takes in zero net power (relative to the largest port power), and the
//! modulated lever's ratio really varies with the state.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use bondgraph::*;
use common::*;
use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestRunner};

/// Kinds that must conserve power exactly (up to rounding).
const CONSERVATIVE: [&str; 6] = ["0", "1", "TF", "MTF", "GY", "MGY"];

/// Relative tolerance on Σ e·f_in against the largest |e·f| on one port.
const REL_TOL: f64 = 1e-12;

/// The reference model called `name` and the kinds it must contain.
fn model(name: &str) -> (StateEquations, &'static [&'static str]) {
    match name {
        "mass-spring-damper" => (mass_spring_damper(1.0, 100.0, 0.4, 0.01), &["1"]),
        "series RLC" => (series_rlc(2.0, 1.0, 1.0, 0.25), &["1"]),
        "lever" => (
            lever(
                Transformer::new(2.0).unwrap(),
                3.0,
                0.5,
                40.0,
                0.02,
                Some(0.3),
            ),
            &["1", "0", "TF"],
        ),
        "lever, negative ratio" => (
            lever(Transformer::new(-0.7).unwrap(), 3.0, 0.5, 40.0, 0.02, None),
            &["1", "0", "TF"],
        ),
        "DC motor" => (dc_motor(12.0, 2.0, None, 0.5, 0.01, 0.1), &["1", "GY"]),
        "DC motor with inductance" => (
            dc_motor(12.0, 2.0, Some(0.01), 0.5, 0.01, 0.1),
            &["1", "GY"],
        ),
        "DC motor, modulated gyrator" => (
            dc_motor(
                12.0,
                2.0,
                Some(0.01),
                Param::modulated(vec!["J.p".into()], |t, u| 0.5 + 0.1 * (t + u[0]).sin()),
                0.01,
                0.1,
            ),
            &["1", "MGY"],
        ),
        "modulated lever" => (modulated_lever(Some(0.2)), &["1", "0", "MTF"]),
        "planar mass, matrix MTF" => (planar_matrix_mtf(), &["1", "0", "MTF"]),
        "planar mass, constant matrix MTF" => (
            planar_constant_mtf(2.0, 50.0, [0.3, -0.2], 0.02),
            &["1", "0", "MTF"],
        ),
        "lever, inverse orientation" => (reversed_lever(0.5, 2.0, 30.0, 0.03), &["1", "TF"]),
        "gyrator, admittance causality" => (
            gyrator_between_capacitors(2.0, 0.5, 0.125, 0.1),
            &["0", "GY"],
        ),
        _ => panic!("no model {name}"),
    }
}

/// Evaluate at (t, x) and check every conservative element. Returns how many elements were
/// checked with a non-zero power scale.
fn check_power(
    name: &str,
    eqs: &StateEquations,
    t: f64,
    x: &[f64],
) -> Result<usize, TestCaseError> {
    eqs.evaluate(t, x);
    let g = eqs.graph();
    let mut nontrivial = 0;
    for id in 0..g.n_elements() {
        let node = g.node(id);
        if !CONSERVATIVE.contains(&node.element.kind()) {
            continue;
        }
        let (p, scale) = (eqs.power_into(id), eqs.power_scale(id));
        prop_assert!(
            p.is_finite() && scale.is_finite(),
            "{name}: `{}` power {p}, scale {scale}",
            node.name
        );
        if scale == 0.0 {
            // Nothing flows: the balance must be exactly zero.
            prop_assert!(
                p == 0.0,
                "{name}: `{}` takes in {p} with every port power zero",
                node.name
            );
        } else {
            prop_assert!(p.abs() <= REL_TOL * scale, "{name}: `{}` ({}) takes in {p:e}, scale {scale:e}, relative {:e} at t = {t}, x = {x:?}", node.name, node.element.kind(), p / scale);
            nontrivial += 1;
        }
    }
    Ok(nontrivial)
}

/// A state vector for `eqs` from random unit numbers, each scaled by `magnitude`.
fn state_from(eqs: &StateEquations, unit: &[f64], magnitude: f64) -> Vec<f64> {
    (0..eqs.n_states())
        .map(|i| magnitude * unit[i % unit.len()])
        .collect()
}

/// Task 6 for one model: the kinds it is meant to exercise are there, something carries
/// power at a generic state (so the property is not vacuous), and at random states and times
/// every conservative element's balance is zero to `REL_TOL`.
fn power_property(name: &str) {
    let (eqs, kinds) = model(name);
    let g = eqs.graph();
    for kind in kinds {
        assert!(
            (0..g.n_elements()).any(|id| g.node(id).element.kind() == *kind),
            "{name} has no {kind}"
        );
    }
    let generic: Vec<f64> = (0..eqs.n_states()).map(|i| 0.3 + 0.1 * i as f64).collect();
    let checked = check_power(name, &eqs, 0.1, &generic).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        checked >= 1,
        "{name}: no element carries power at {generic:?}"
    );

    let mut runner = TestRunner::new(ProptestConfig {
        cases: 256,
        ..ProptestConfig::default()
    });
    let strategy = (
        prop::collection::vec(-1.0f64..1.0, 7),
        prop_oneof![Just(1e-6f64), Just(0.5), Just(1.0), Just(1e3)],
        0.0f64..10.0,
    );
    let result = runner.run(&strategy, |(unit, magnitude, t)| {
        // The modulated lever's ratio 1 + q must stay away from 0: keep q within ±0.5.
        let magnitude = if name == "modulated lever" {
            magnitude.min(0.5)
        } else {
            magnitude
        };
        let x = state_from(&eqs, &unit, magnitude);
        check_power(name, &eqs, t, &x).map(|_| ())
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
}

#[test]
fn power_mass_spring_damper() {
    power_property("mass-spring-damper");
}

#[test]
fn power_series_rlc() {
    power_property("series RLC");
}

#[test]
fn power_lever() {
    power_property("lever");
}

#[test]
fn power_lever_negative_ratio() {
    power_property("lever, negative ratio");
}

#[test]
fn power_dc_motor() {
    power_property("DC motor");
}

#[test]
fn power_dc_motor_with_inductance() {
    power_property("DC motor with inductance");
}

#[test]
fn power_dc_motor_modulated_gyrator() {
    power_property("DC motor, modulated gyrator");
}

#[test]
fn power_modulated_lever() {
    power_property("modulated lever");
}

#[test]
fn power_planar_matrix_mtf() {
    power_property("planar mass, matrix MTF");
}

#[test]
fn power_planar_constant_matrix_mtf() {
    power_property("planar mass, constant matrix MTF");
}

#[test]
fn power_lever_inverse_orientation() {
    power_property("lever, inverse orientation");
}

#[test]
fn power_gyrator_admittance_causality() {
    power_property("gyrator, admittance causality");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Task 5: the modulated TF conserves power at random states, and its ratio follows
    /// 1 + spring.q: e1 = (1 + q)·e2 on the lever's two bonds.
    #[test]
    fn modulated_transformer_conserves_power_and_follows_the_displacement(
        p1 in -2.0f64..2.0,
        q in -0.5f64..0.5,
        p2 in -2.0f64..2.0,
        t in 0.0f64..5.0,
    ) {
        let eqs = modulated_lever(Some(0.2));
        let mut x = vec![0.0; eqs.n_states()];
        for (name, v) in [("m1.p", p1), ("spring.q", q), ("m2.p", p2)] {
            let i = eqs.states().iter().position(|s| s.name == name).unwrap();
            x[i] = v;
        }
        check_power("modulated lever", &eqs, t, &x)?;
        let tf = eqs.graph().find("tf").unwrap();
        let (p, scale) = (eqs.power_into(tf), eqs.power_scale(tf));
        prop_assert!(p.abs() <= REL_TOL * scale.max(f64::MIN_POSITIVE) || (scale == 0.0 && p == 0.0));
        let e1 = eqs.read(eqs.probe("tf.1.e").unwrap(), t, &x);
        let e2 = eqs.read(eqs.probe("tf.2.e").unwrap(), t, &x);
        let f1 = eqs.read(eqs.probe("tf.1.f").unwrap(), t, &x);
        let f2 = eqs.read(eqs.probe("tf.2.f").unwrap(), t, &x);
        let n = 1.0 + q;
        prop_assert!((e1 - n * e2).abs() <= 1e-12 * e1.abs().max(1e-300), "e1 = {e1}, n·e2 = {}", n * e2);
        prop_assert!((f2 - n * f1).abs() <= 1e-12 * f2.abs().max(1e-300), "f2 = {f2}, n·f1 = {}", n * f1);
        // Moving masses and a deflected spring: the power through the lever is not zero.
        if q.abs() > 1e-3 && p1.abs() > 1e-3 {
            prop_assert!(scale > 0.0);
        }
    }
}
