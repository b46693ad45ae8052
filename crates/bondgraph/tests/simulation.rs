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
        matches!(
            run.error,
            Some(SimulationError::InitialState {
                given: 1,
                expected: _
            })
        ),
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
            assert_eq!(s.jac_assemblies + s.lu_factorisations, 0, "{s}");
        } else {
            assert!(
                s.jac_evals >= 1 && s.jac_assemblies >= 1 && s.lu_factorisations >= 1,
                "{}: {s}",
                method.name()
            );
        }
    }
}

/// Issue "hardening" #9: a model with no states (`Se -> R`) panicked in diffsol ("Matrix
/// slicing out of bounds"). It has nothing to integrate: its rows are its outputs.
#[test]
fn a_model_without_states_gives_its_outputs_at_the_output_times() {
    let mut g = BondGraph::new();
    g.add("src", EffortSource::new(2.0)).unwrap();
    g.add("r", Resistor::new(4.0).unwrap()).unwrap();
    bond_all(&mut g, &[("src", "r")]);
    let mut eqs = assemble(g);
    assert_eq!(eqs.n_states(), 0);
    let outs = [output(&eqs, "r.f"), output(&eqs, "r.P")];
    for method in Method::ALL {
        let run = simulate(
            &mut eqs,
            &[],
            &settings(method, 1.0, 0.25, 1e-6, 1e-8),
            &outs,
            vec![],
        );
        assert!(run.error.is_none(), "{method:?}: {:?}", run.error);
        assert_eq!(col(&run.trajectory, "t"), [0.0, 0.25, 0.5, 0.75, 1.0]);
        assert!(col(&run.trajectory, "r.f")
            .iter()
            .all(|f| (*f - 0.5).abs() < 1e-15));
        assert!(col(&run.trajectory, "r.P")
            .iter()
            .all(|p| (*p - 1.0).abs() < 1e-15));
        assert_eq!(run.rows, 5);
    }
}

/// Issue "hardening" #4: at t ≈ 1e16 f64 times are 2 s apart; a 2 s run gave "steps 0" and
/// 10 001 identical rows with exit 0. Now it is refused, and so is an rtol f64 cannot meet.
#[test]
fn times_and_tolerances_beyond_f64_resolution_are_refused() {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    for s in [
        Settings {
            t_start: 1e16,
            t_end: 1.000_000_000_000_01e16,
            dt_out: 2e-4,
            ..Settings::default()
        },
        Settings {
            t_end: 1e-12,
            dt_out: 1e-13,
            ..Settings::default()
        },
        Settings {
            rtol: 1e-300,
            ..Settings::default()
        },
        Settings {
            t_end: 10.0,
            dt_out: 1e-9,
            ..Settings::default()
        },
    ] {
        let run = simulate(&mut eqs, &x0, &s, &[], vec![]);
        assert!(
            matches!(run.error, Some(SimulationError::InvalidSetting { .. })),
            "{s:?}: {:?}",
            run.error
        );
        assert_eq!(run.trajectory.rows.len(), 0);
    }
    // far from the origin, but resolvable: fine
    let s = Settings {
        t_start: 1e6,
        t_end: 1e6 + 1.0,
        dt_out: 0.5,
        ..Settings::default()
    };
    let run = simulate(&mut eqs, &x0, &s, &[], vec![]);
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_eq!(col(&run.trajectory, "t"), [1e6, 1e6 + 0.5, 1e6 + 1.0]);
}

/// A sink that keeps rows and counts the accepted steps it was shown.
#[derive(Default)]
struct Counting {
    rows: Vec<Vec<f64>>,
    steps: Vec<f64>,
    refuse_after: Option<usize>,
}

impl RowSink for Counting {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        if self.refuse_after.is_some_and(|n| self.rows.len() >= n) {
            return Err("disk full".into());
        }
        self.rows.push(row.to_vec());
        Ok(())
    }
    fn wants_steps(&self) -> bool {
        true
    }
    fn step(&mut self, values: &[f64]) {
        self.steps.push(values[0]);
    }
}

/// Issue "hardening" #5/#7: rows stream to a sink as they are computed (the same rows as in
/// memory), and the sink sees the outputs at every accepted step in between (#6).
#[test]
fn rows_stream_to_a_sink_with_every_accepted_step() {
    let s = settings(Method::Bdf, 1.0, 0.1, 1e-8, 1e-12);
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "spring.q")];
    let kept = simulate(&mut eqs, &x0, &s, &outs, vec![]);
    let mut sink = Counting::default();
    let streamed = simulate_into(&mut eqs, &x0, &s, &outs, vec![], &mut sink);
    assert!(streamed.error.is_none(), "{:?}", streamed.error);
    assert!(streamed.trajectory.rows.is_empty());
    assert_eq!(streamed.rows, 11);
    assert_eq!(sink.rows, kept.trajectory.rows);
    assert_eq!(sink.steps.len(), streamed.stats.steps);
    assert!(sink.steps.windows(2).all(|w| w[0] < w[1]));
}

/// A sink that keeps every step's values and reads the columns `reads` says (all: `None`).
struct Steps {
    reads: Option<usize>,
    steps: Vec<Vec<f64>>,
}

impl RowSink for Steps {
    fn row(&mut self, _row: &[f64]) -> Result<(), String> {
        Ok(())
    }
    fn wants_steps(&self) -> bool {
        true
    }
    fn step(&mut self, values: &[f64]) {
        self.steps.push(values.to_vec());
    }
    fn step_reads(&self, column: usize) -> bool {
        self.reads.is_none_or(|c| c == column)
    }
}

/// At every step only the columns the sink reads are evaluated (only their stages run):
/// they hold what a whole evaluation gives, bit for bit; the others are NaN.
#[test]
fn a_step_evaluates_only_the_columns_the_sink_reads() {
    let s = settings(Method::Bdf, 1.0, 0.1, 1e-8, 1e-12);
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    let outs = [
        output(&eqs, "mass.f"),
        output(&eqs, "spring.e"),
        output(&eqs, "damper.e"),
    ];
    let mut all = Steps {
        reads: None,
        steps: Vec::new(),
    };
    let mut one = Steps {
        reads: Some(1),
        steps: Vec::new(),
    };
    simulate_into(&mut eqs, &x0, &s, &outs, vec![], &mut all);
    simulate_into(&mut eqs, &x0, &s, &outs, vec![], &mut one);
    assert!(all.steps.len() > 10);
    assert_eq!(all.steps.len(), one.steps.len());
    for (a, o) in all.steps.iter().zip(&one.steps) {
        assert!(a.iter().all(|v| v.is_finite()), "{a:?}");
        assert_eq!(o[0].to_bits(), a[0].to_bits());
        assert_eq!(o[2].to_bits(), a[2].to_bits(), "spring.e");
        assert!(o[1].is_nan() && o[3].is_nan(), "{o:?}");
    }
}

/// A refused row (a full disk) stops the run at once, keeping the rows before it.
#[test]
fn a_refused_row_stops_the_run() {
    let s = settings(Method::Bdf, 1.0, 0.01, 1e-8, 1e-12);
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    let mut sink = Counting {
        refuse_after: Some(30),
        ..Counting::default()
    };
    let run = simulate_into(&mut eqs, &x0, &s, &[], vec![], &mut sink);
    assert!(
        matches!(&run.error, Some(SimulationError::Output { message, .. }) if message == "disk full"),
        "{:?}",
        run.error
    );
    assert_eq!(sink.rows.len(), 30);
    assert_eq!(run.rows, 30);
    assert!(run.t_final < 0.35, "stopped soon after: {}", run.t_final);
}

/// Issue "hardening" #5: an interruption (SIGINT/SIGTERM in the CLI) stops the run after the
/// current step and keeps the rows so far.
#[test]
fn the_interrupt_flag_stops_the_run_and_keeps_the_rows() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    struct StopAt(Arc<AtomicBool>, Vec<Vec<f64>>);
    impl RowSink for StopAt {
        fn row(&mut self, row: &[f64]) -> Result<(), String> {
            if row[0] >= 0.5 {
                self.0.store(true, Ordering::Relaxed);
            }
            self.1.push(row.to_vec());
            Ok(())
        }
    }
    let flag = Arc::new(AtomicBool::new(false));
    let s = Settings {
        interrupt: Some(Arc::clone(&flag)),
        ..settings(Method::Bdf, 10.0, 0.01, 1e-8, 1e-12)
    };
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    let mut sink = StopAt(flag, Vec::new());
    let run = simulate_into(&mut eqs, &x0, &s, &[], vec![], &mut sink);
    assert!(
        matches!(run.error, Some(SimulationError::Interrupted { .. })),
        "{:?}",
        run.error
    );
    assert!(sink.1.len() >= 51 && sink.1.len() < 80, "{}", sink.1.len());
    assert_eq!(run.rows, sink.1.len());
}

/// Issue "hardening" #7: the 1e7-row cap ignored the columns. Rows kept in memory are now
/// bounded by rows × columns; streamed rows only by `MAX_OUTPUT_ROWS`.
#[test]
fn rows_kept_in_memory_are_bounded_by_values_not_rows() {
    let mut eqs = mass_spring_damper(1.0, 100.0, 0.4, 0.01);
    let x0 = eqs.initial_state();
    let outs: Vec<Output> = (0..99).map(|_| output(&eqs, "spring.q")).collect();
    // 1e6 rows × 100 columns = 1e8 values: refused in memory, before any step
    let s = settings(Method::Bdf, 1.0, 1e-6, 1e-6, 1e-8);
    let run = simulate(&mut eqs, &x0, &s, &outs, vec![]);
    assert!(
        matches!(&run.error, Some(SimulationError::InvalidSetting { setting: "dt_out", message, .. }) if message.contains("columns")),
        "{:?}",
        run.error
    );
    assert_eq!(run.stats.steps, 0);
    // the same rows into a sink that drops them: fine
    struct Drop(usize);
    impl RowSink for Drop {
        fn row(&mut self, _: &[f64]) -> Result<(), String> {
            self.0 += 1;
            Ok(())
        }
    }
    let s = settings(Method::Bdf, 0.1, 1e-6, 1e-6, 1e-8);
    let mut sink = Drop(0);
    let run = simulate_into(&mut eqs, &x0, &s, &outs, vec![], &mut sink);
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_eq!(sink.0, 100_001);
}
