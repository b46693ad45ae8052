//! Signal blocks in closed loops: a first-order lag, a saturated P-controller driving a
//! mass, and modulated parameters reading many signals.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use approx::assert_abs_diff_eq;
use bondgraph::*;
use common::*;

/// A lag (τ = 0.1) reading a constant signal u = 2: y = u·(1 − e^{−t/τ}).
#[test]
fn lag_follows_a_step_with_its_time_constant() {
    let (u, tau) = (2.0, 0.1);
    let mut g = BondGraph::new();
    g.add("u", SignalFunction::new(u)).unwrap();
    g.add("filter", Lag::new("u.out", tau, 0.0).unwrap())
        .unwrap();
    let mut eqs = assemble(g);
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "filter.out"), output(&eqs, "filter.y.dot")];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.0, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let tr = &run.trajectory;
    for ((t, y), dy) in col(tr, "t")
        .into_iter()
        .zip(col(tr, "filter.out"))
        .zip(col(tr, "filter.y.dot"))
    {
        assert_abs_diff_eq!(y, u * (1.0 - (-t / tau).exp()), epsilon = 1e-7 * u);
        assert_abs_diff_eq!(dy, (u - y) / tau, epsilon = 1e-12 * u / tau);
    }
}

/// A saturated P-controller sets the force on a mass with viscous friction b, regulating its
/// velocity to r: F = clamp(K·(r − v), −F_max, F_max), m·v' = F − b·v.
/// With K = 10, r = 1, F_max = 5, b = 1, m = 1, from rest:
/// * saturated while K·(1 − v) > 5, i.e. v < 0.5: v = 5·(1 − e^{−t}), until t1 = ln(10/9);
/// * then m·v' = 10 − 11·v: v = 10/11 + (0.5 − 10/11)·e^{−11·(t − t1)}.
#[test]
fn saturated_p_controller_regulates_a_mass() {
    let (k, r, f_max, b, m) = (10.0, 1.0, 5.0, 1.0, 1.0);
    let mut g = BondGraph::new();
    g.add(
        "ctrl",
        PController::new("mass.f", k, r, -f_max, f_max).unwrap(),
    )
    .unwrap();
    g.add(
        "force",
        EffortSource::new(Param::modulated(vec!["ctrl.out".into()], |_, u| u[0])),
    )
    .unwrap();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(m, 0.0).unwrap()).unwrap();
    g.add("friction", Resistor::new(b).unwrap()).unwrap();
    bond_all(&mut g, &[("force", "v"), ("v", "mass"), ("v", "friction")]);
    let mut eqs = assemble(g);
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "mass.f"), output(&eqs, "ctrl.out")];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.0, 0.005, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let t1 = (10.0f64 / 9.0).ln();
    let exact = |t: f64| {
        if t <= t1 {
            5.0 * (1.0 - (-t).exp())
        } else {
            10.0 / 11.0 + (0.5 - 10.0 / 11.0) * (-11.0 * (t - t1)).exp()
        }
    };
    let tr = &run.trajectory;
    for ((t, v), f) in col(tr, "t")
        .into_iter()
        .zip(col(tr, "mass.f"))
        .zip(col(tr, "ctrl.out"))
    {
        assert_abs_diff_eq!(v, exact(t), epsilon = 1e-6);
        assert_abs_diff_eq!(f, (k * (r - v)).clamp(-f_max, f_max), epsilon = 1e-12);
    }
    assert_abs_diff_eq!(
        *col(tr, "mass.f").last().unwrap(),
        k * r / (k + b),
        epsilon = 1e-4
    );
}

/// A modulated parameter reading MAX_PARAM_INPUTS + 1 = 17 signals: the law must see all 17
/// values (or the model must be refused); it must not silently receive fewer.
#[test]
fn modulated_parameter_with_many_inputs_sees_all_of_them() {
    let n = bondgraph::element::MAX_PARAM_INPUTS + 1;
    let mut g = BondGraph::new();
    for i in 0..n {
        g.add(&format!("s{i}"), SignalFunction::new(i as f64 + 1.0))
            .unwrap();
    }
    let inputs: Vec<String> = (0..n).map(|i| format!("s{i}.out")).collect();
    // Output: number of values received · 1000 + their sum (1 + 2 + … + n).
    g.add(
        "sum",
        SignalFunction::new(Param::modulated(inputs, |_, u| {
            u.len() as f64 * 1000.0 + u.iter().sum::<f64>()
        })),
    )
    .unwrap();
    match StateEquations::new(assign_causality(g).unwrap()) {
        Ok(eqs) => {
            let probe = eqs.probe("sum.out").unwrap();
            eqs.evaluate(0.0, &[]);
            let got = eqs.read(probe, 0.0, &[]);
            let want = n as f64 * 1000.0 + (n * (n + 1) / 2) as f64;
            assert_abs_diff_eq!(got, want, epsilon = 1e-12);
        }
        Err(e) => {
            // Refusing is acceptable if the message says why.
            assert!(e.to_string().contains("sum"), "{e}");
        }
    }
}
