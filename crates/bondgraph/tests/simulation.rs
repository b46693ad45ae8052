//! Simulation behaviour: output rows on the grid, scheduled events landing exactly on their
//! times, NaN detection keeping the rows computed before the failure, settings validation.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use approx::assert_abs_diff_eq;
use bondgraph::*;
use common::*;

/// Output rows land at k·dt_out for k = 0, 1, …, and the last row at t_end, also when t_end
/// is not a multiple of dt_out — for every method.
#[test]
fn output_rows_land_on_the_grid_and_end_at_t_end() {
    for (t_end, dt_out) in [(1.0, 0.1), (1.05, 0.1), (0.5, 0.01)] {
        for method in Method::ALL {
            let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
            let x0 = eqs.initial_state();
            let outs = [output(&eqs, "spring.q")];
            let run = simulate(
                &mut eqs,
                &x0,
                &settings(method, t_end, dt_out, 1e-9, 1e-14),
                &outs,
                vec![],
            );
            assert!(run.error.is_none(), "{:?}", run.error);
            let t = col(&run.trajectory, "t");
            let n_grid = (t_end / dt_out + 1e-9).floor() as usize;
            let mut expected: Vec<f64> = (0..=n_grid).map(|k| k as f64 * dt_out).collect();
            if (expected[n_grid] - t_end).abs() > 1e-12 {
                expected.push(t_end);
            }
            assert_eq!(
                t.len(),
                expected.len(),
                "{} t_end = {t_end}, dt_out = {dt_out}: rows at {t:?}",
                method.name()
            );
            for (got, want) in t.iter().zip(&expected) {
                assert_abs_diff_eq!(*got, *want, epsilon = 1e-12);
            }
            assert_abs_diff_eq!(run.t_final, t_end, epsilon = 1e-12);
            // Rows hold the solution at their own time.
            let q = col(&run.trajectory, "spring.q");
            for (&ti, &qi) in t.iter().zip(&q) {
                assert_abs_diff_eq!(
                    qi,
                    underdamped(0.01, 0.0, 0.2, 10.0, ti).0,
                    epsilon = 1e-6 * 0.01
                );
            }
        }
    }
}

/// Undamped oscillator (damper r = 0) until t = 0.5, when an event replaces the damper by
/// r = 2: the output row at 0.5 exists, one event is counted, and after 0.5 the solution is
/// the damped free response restarted from the undamped state at exactly 0.5.
#[test]
fn event_replacing_a_resistor_lands_exactly_on_its_time() {
    let (m, k, q0, r_after, t_ev): (f64, f64, f64, f64, f64) = (1.0, 100.0, 0.01, 2.0, 0.5);
    let omega0 = (k / m).sqrt();
    for method in [Method::Bdf, Method::Esdirk34] {
        let mut eqs = mass_spring_damper(m, k, 0.0, q0);
        let damper = eqs.graph().find("damper").unwrap();
        let x0 = eqs.initial_state();
        let outs = [
            output(&eqs, "spring.q"),
            output(&eqs, "damper.e"),
            output(&eqs, "mass.f"),
        ];
        let event = Event {
            t: t_ev,
            replacements: vec![(damper, Box::new(Resistor::new(r_after).unwrap()))],
        };
        let run = simulate(
            &mut eqs,
            &x0,
            &settings(method, 1.5, 0.01, 1e-10, 1e-13),
            &outs,
            vec![event],
        );
        assert!(run.error.is_none(), "{:?}", run.error);
        assert_eq!(run.stats.events, 1);
        let tr = &run.trajectory;
        let t = col(tr, "t");
        let at_event: Vec<usize> = (0..t.len())
            .filter(|&i| (t[i] - t_ev).abs() <= 1e-12)
            .collect();
        assert_eq!(
            at_event.len(),
            1,
            "exactly one row at the event time, rows {t:?}"
        );
        assert_eq!(t.len(), 151, "rows at 0, 0.01, …, 1.5");
        // The state at the switch, from the undamped solution.
        let (x_ev, v_ev) = underdamped(q0, 0.0, 0.0, omega0, t_ev);
        let alpha = r_after / (2.0 * m);
        let q = col(tr, "spring.q");
        let (e_damper, v) = (col(tr, "damper.e"), col(tr, "mass.f"));
        for i in 0..t.len() {
            let exact = if t[i] <= t_ev {
                underdamped(q0, 0.0, 0.0, omega0, t[i]).0
            } else {
                underdamped(x_ev, v_ev, alpha, omega0, t[i] - t_ev).0
            };
            assert_abs_diff_eq!(q[i], exact, epsilon = 1e-6 * q0);
            // Before the event the damper carries no force; from the event row on, r_after·v.
            let r_now = if i < at_event[0] { 0.0 } else { r_after };
            assert_abs_diff_eq!(e_damper[i], r_now * v[i], epsilon = 1e-14);
        }
        // The damped tail decays: energy at 1.5 s is below e^{−2α·1}·E(0.5).
        let e_ev = 0.5 * k * x_ev * x_ev + 0.5 * m * v_ev * v_ev;
        let e_end = eqs.stored_energy(&run.x_final);
        assert!(
            e_end < 1.5 * (-2.0 * alpha).exp() * e_ev,
            "E(1.5) = {e_end}, E(0.5) = {e_ev}"
        );
    }
}

/// An event between output times: no extra row, and the switch still takes effect there.
#[test]
fn event_between_output_times_adds_no_row() {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.0, 0.01);
    let damper = eqs.graph().find("damper").unwrap();
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "spring.q")];
    let t_ev = 0.123;
    let event = Event {
        t: t_ev,
        replacements: vec![(damper, Box::new(Resistor::new(2.0).unwrap()))],
    };
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 0.5, 0.1, 1e-10, 1e-13),
        &outs,
        vec![event],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_eq!(run.stats.events, 1);
    let t = col(&run.trajectory, "t");
    assert_eq!(t.len(), 6, "rows {t:?}");
    let (x_ev, v_ev) = underdamped(0.01, 0.0, 0.0, 10.0, t_ev);
    let q_end = *col(&run.trajectory, "spring.q").last().unwrap();
    assert_abs_diff_eq!(
        q_end,
        underdamped(x_ev, v_ev, 1.0, 10.0, 0.5 - t_ev).0,
        epsilon = 1e-8
    );
}

/// A replacement of another shape stops the run at the event with `SimulationError::Event`,
/// keeping the rows before it.
#[test]
fn event_with_wrong_replacement_stops_the_run() {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let damper = eqs.graph().find("damper").unwrap();
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "spring.q")];
    let event = Event {
        t: 0.3,
        replacements: vec![(damper, Box::new(Inertia::new(1.0, 0.0).unwrap()))],
    };
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.0, 0.1, 1e-8, 1e-12),
        &outs,
        vec![event],
    );
    match &run.error {
        Some(SimulationError::Event {
            t,
            source: GraphError::Replacement { element, .. },
        }) => {
            assert_abs_diff_eq!(*t, 0.3, epsilon = 1e-15);
            assert_eq!(element, "damper");
        }
        other => panic!("expected an event error, got {other:?}"),
    }
    assert_abs_diff_eq!(run.t_final, 0.3, epsilon = 1e-12);
    let t = col(&run.trajectory, "t");
    assert_eq!(t.len(), 3, "rows before the event: {t:?}");
    assert_eq!(eqs.graph().node(damper).element.kind(), "R");
}

/// An event is applied whole or not at all: when one of its replacements is refused, the
/// others are not applied either and the event is not counted ("scheduled events applied").
#[test]
fn refused_event_is_neither_applied_nor_counted() {
    let (r0, r_new) = (0.4, 3.0);
    let mut eqs = mass_spring_damper(1.0, 100.0, r0, 0.01);
    let damper = eqs.graph().find("damper").unwrap();
    let spring = eqs.graph().find("spring").unwrap();
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "spring.q")];
    let event = Event {
        t: 0.3,
        replacements: vec![
            (damper, Box::new(Resistor::new(r_new).unwrap())), // acceptable on its own
            (spring, Box::new(Inertia::new(1.0, 0.0).unwrap())), // refused: a different kind
        ],
    };
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.0, 0.1, 1e-8, 1e-12),
        &outs,
        vec![event],
    );
    assert!(
        matches!(&run.error, Some(SimulationError::Event { source: GraphError::Replacement { element, .. }, .. }) if element == "spring"),
        "{:?}",
        run.error
    );
    assert_eq!(
        run.stats.events, 0,
        "a refused event was counted as applied"
    );
    // The damper still has r0: its force at unit velocity is r0.
    let x = vec![1.0, 0.0]; // mass.p = 1 (v = 1), spring.q = 0
    assert_eq!(eqs.states()[0].name, "mass.p");
    eqs.evaluate(0.0, &x);
    let e = eqs.read(eqs.probe("damper.e").unwrap(), 0.0, &x);
    assert_abs_diff_eq!(e, r0, epsilon = 1e-15);
}

/// A resistor in conductance causality (f = e/r: C discharging through R on a 0-junction)
/// must not be switched to r = 0 by an event: its causality no longer fits. The switch must be
/// refused when the event is applied (`SimulationError::Event` naming the resistor), keeping
/// the rows before it, rather than running on with an infinite flow.
#[test]
fn event_switching_conductance_resistor_to_zero_is_refused() {
    let mut g = BondGraph::new();
    g.add("z", ZeroJunction).unwrap();
    g.add("C", Capacitor::new(1.0, 1.0).unwrap()).unwrap();
    let r = g.add("R", Resistor::new(1.0).unwrap()).unwrap();
    bond_all(&mut g, &[("z", "C"), ("z", "R")]);
    let mut eqs = assemble(g);
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "C.q")];
    let event = Event {
        t: 0.5,
        replacements: vec![(r, Box::new(Resistor::new(0.0).unwrap()))],
    };
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.0, 0.1, 1e-10, 1e-13),
        &outs,
        vec![event],
    );
    match &run.error {
        Some(SimulationError::Event { t, source }) => {
            assert_abs_diff_eq!(*t, 0.5, epsilon = 1e-15);
            assert!(source.to_string().contains("`R`"), "{source}");
        }
        other => panic!(
            "expected the event to be refused, got {:?}",
            other.as_ref().map(ToString::to_string)
        ),
    }
    let q = col(&run.trajectory, "C.q");
    let t = col(&run.trajectory, "t");
    assert_eq!(t.len(), 5, "rows before the event: {t:?}");
    for (ti, qi) in t.iter().zip(&q) {
        assert_abs_diff_eq!(*qi, (-ti).exp(), epsilon = 1e-8);
    }
}

/// Se driven by a signal that turns NaN at t = 1 drives a current through R and L
/// (τ = L/R = 0.1 s, a sine keeping the steps short). The run stops with `NonFinite` or
/// `Solver` naming the signal block, and keeps the rows before the failure, which match the
/// analytic current.
#[test]
fn nan_from_a_signal_stops_the_run_and_keeps_earlier_rows() {
    let (r, l) = (1.0, 0.1);
    let tau = l / r;
    let w = 20.0;
    for method in Method::ALL {
        let mut g = BondGraph::new();
        g.add(
            "sig",
            SignalFunction::new(Param::modulated(vec![], move |t, _| {
                if t < 1.0 {
                    (w * t).sin()
                } else {
                    f64::NAN
                }
            })),
        )
        .unwrap();
        g.add(
            "src",
            EffortSource::new(Param::modulated(vec!["sig.out".into()], |_, u| u[0])),
        )
        .unwrap();
        g.add("j", OneJunction).unwrap();
        g.add("R", Resistor::new(r).unwrap()).unwrap();
        g.add("L", Inertia::new(l, 0.0).unwrap()).unwrap();
        bond_all(&mut g, &[("src", "j"), ("j", "R"), ("j", "L")]);
        let mut eqs = assemble(g);
        let x0 = eqs.initial_state();
        let outs = [output(&eqs, "L.f"), output(&eqs, "sig.out")];
        let run = simulate(
            &mut eqs,
            &x0,
            &settings(method, 2.0, 0.01, 1e-8, 1e-12),
            &outs,
            vec![],
        );
        let err = run
            .error
            .clone()
            .unwrap_or_else(|| panic!("{}: the run must fail", method.name()));
        let text = err.to_string();
        eprintln!("{}: {text}", method.name());
        let t_fail = match &err {
            SimulationError::NonFinite {
                t,
                element,
                culprit,
                ..
            } => {
                assert_eq!(element, "L");
                assert!(culprit.contains("`sig`"), "{}: {text}", method.name());
                *t
            }
            SimulationError::Solver { t, culprit, .. } => {
                assert!(culprit.contains("`sig`"), "{}: {text}", method.name());
                *t
            }
            other => panic!("{}: unexpected error {other:?}", method.name()),
        };
        assert!(
            (0.9..=1.05).contains(&t_fail),
            "{}: failed at {t_fail}",
            method.name()
        );
        let t = col(&run.trajectory, "t");
        let i = col(&run.trajectory, "L.f");
        let last = *t
            .last()
            .unwrap_or_else(|| panic!("{}: no rows kept", method.name()));
        assert!(
            last <= t_fail + 1e-12 && last < 1.0,
            "{}: last row at {last}",
            method.name()
        );
        assert!(
            t.len() >= 90,
            "{}: only {} rows kept before t = {t_fail}",
            method.name(),
            t.len()
        );
        for (k, (tk, ik)) in t.iter().zip(&i).enumerate() {
            assert_abs_diff_eq!(*tk, k as f64 * 0.01, epsilon = 1e-12);
            // τ·i' + i = sin(ωt)/R: i = (sin ωt − ωτ·cos ωt + ωτ·e^{−t/τ}) / (R·(1 + ω²τ²)).
            let exact = ((w * tk).sin() - w * tau * (w * tk).cos() + w * tau * (-tk / tau).exp())
                / (r * (1.0 + (w * tau).powi(2)));
            assert_abs_diff_eq!(*ik, exact, epsilon = 1e-6 / r);
        }
        assert!(run.x_final.len() == 1 && run.t_final >= last);
    }
}

/// A NaN initial state is refused before any step, naming the state and its element.
#[test]
fn non_finite_initial_state_is_refused() {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let mut x0 = eqs.initial_state();
    x0[0] = f64::NAN;
    let run = simulate(&mut eqs, &x0, &Settings::default(), &[], vec![]);
    match run.error {
        Some(SimulationError::NonFinite {
            element, state, t, ..
        }) => {
            assert_eq!((element.as_str(), state.as_str()), ("mass", "mass.p"));
            assert_abs_diff_eq!(t, 0.0);
        }
        other => panic!("{other:?}"),
    }
    assert!(run.trajectory.rows.is_empty());
}

#[test]
fn invalid_settings_are_refused() {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    let bad = [
        Settings {
            t_end: 0.0,
            ..Settings::default()
        },
        Settings {
            dt_out: 0.0,
            ..Settings::default()
        },
        Settings {
            rtol: 1.0,
            ..Settings::default()
        },
        Settings {
            atol: -1.0,
            ..Settings::default()
        },
        Settings {
            t_end: f64::NAN,
            ..Settings::default()
        },
    ];
    for s in bad {
        let run = simulate(&mut eqs, &x0, &s, &[], vec![]);
        assert!(
            matches!(run.error, Some(SimulationError::InvalidSetting { .. })),
            "{s:?}: {:?}",
            run.error
        );
        assert_eq!(run.stats.steps, 0);
    }
    let run = simulate(&mut eqs, &[0.0], &Settings::default(), &[], vec![]);
    assert!(
        matches!(run.error, Some(SimulationError::Settings(_))),
        "wrong state length: {:?}",
        run.error
    );
}

/// The statistics add up: the Jacobian work of the implicit methods is counted, Tsit45 needs
/// none, and every accepted step cost at least one right-hand-side evaluation.
#[test]
fn statistics_are_consistent() {
    for method in Method::ALL {
        let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
        let x0 = eqs.initial_state();
        let run = simulate(
            &mut eqs,
            &x0,
            &settings(method, 1.0, 0.1, 1e-6, 1e-10),
            &[],
            vec![],
        );
        assert!(run.error.is_none());
        let s = &run.stats;
        assert!(
            s.steps > 10 && s.rhs_evals >= s.steps,
            "{}: {s}",
            method.name()
        );
        assert_eq!(s.events, 0);
        if method == Method::Tsit45 {
            assert_eq!(s.jac_rhs_evals, 0, "{s}");
        } else {
            assert!(
                s.jac_evals >= 1 && s.jac_assemblies >= 1 && s.lu_factorisations >= 1,
                "{}: {s}",
                method.name()
            );
        }
    }
}
