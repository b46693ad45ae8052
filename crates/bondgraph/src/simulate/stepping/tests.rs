//! `Simulation`'s tests: many short advances equal one run, inputs and series corners between
//! calls, refusals, events on the way.

#![allow(clippy::unwrap_used, clippy::float_cmp)] // exact values by intent
use super::*;
use crate::{simulate, EffortSource, Output};

/// m = 1, k = 100, c = 2 pushed by 10 N, from rest.
fn msd() -> StateEquations {
    crate::test_models::msd(1.0, 1.0 / 100.0, 2.0, 10.0, None)
}

fn settings() -> Settings {
    Settings {
        t_end: 3.0,
        dt_out: 0.01,
        rtol: 1e-8,
        atol: 1e-10,
        ..Settings::default()
    }
}

/// x(t) of the MSD under a 10 N step: x∞ = 0.1, ω_d = √99, σ = 1.
fn exact(t: f64) -> f64 {
    let wd = 99f64.sqrt();
    0.1 * (1.0 - (-t).exp() * ((wd * t).cos() + (wd * t).sin() / wd))
}

/// 300 calls of 10 ms end where one run ends (to the tolerance), and where the closed
/// form is; the calls cost no Jacobian or LU of their own.
#[test]
fn many_short_advances_equal_one_run() {
    let s = settings();
    let mut eqs = msd();
    let x0 = eqs.initial_state();
    let probe = eqs.probe("spring.q").unwrap();
    let outputs = [Output {
        name: "x".into(),
        probe,
    }];
    let run = simulate(&mut eqs, &x0, &s, &outputs, vec![]);
    assert!(run.error.is_none());
    let x_run = *run.trajectory.column("x").unwrap().last().unwrap();

    let mut sim = Simulation::start(msd(), 0.0, &x0, &s, vec![]).unwrap();
    let mut worst = 0.0f64;
    for k in 1..=300 {
        sim.advance_to(k as f64 * 0.01).unwrap();
        assert!((sim.t() - k as f64 * 0.01).abs() < 1e-15);
        worst = worst.max((sim.read(probe) - exact(sim.t())).abs());
    }
    let x_step = sim.read(probe);
    let st = sim.stats();
    eprintln!(
        "300 advances: x = {x_step:.12} (one run {x_run:.12}, exact {:.12}), worst error {worst:.1e}; stepping {st}; one run {}",
        exact(3.0),
        run.stats
    );
    assert!((x_step - x_run).abs() < 1e-8, "{x_step} vs {x_run}");
    assert!(worst < 1e-8, "{worst}");
    // No restart per call: a restart costs a Jacobian, so 300 calls would cost ≥ 300. The
    // Jacobians are those of a run within a small margin; the LUs at most the run's plus
    // two per call (the landing step's h and the next one's).
    assert!(st.jac_evals <= run.stats.jac_evals + 5, "{st}");
    assert!(
        st.lu_factorisations <= run.stats.lu_factorisations + 2 * 300,
        "{st}"
    );
    assert!(st.steps >= 300);
}

/// A changed source at the current time (as an input set to a new value) costs no
/// Jacobian and no LU, and the solution follows the new force exactly.
#[test]
fn a_changed_force_costs_no_restart() {
    let s = settings();
    let eqs = msd();
    let x0 = eqs.initial_state();
    let force = eqs.graph().find("force").unwrap();
    let probe = eqs.probe("spring.q").unwrap();
    let mut sim = Simulation::start(eqs, 0.0, &x0, &s, vec![]).unwrap();
    sim.advance_to(1.0).unwrap();
    let before = sim.stats();
    sim.equations_mut()
        .replace(force, Box::new(EffortSource::new(20.0)))
        .unwrap();
    sim.equations_changed();
    for k in 1..=100 {
        sim.advance_to(1.0 + k as f64 * 0.01).unwrap();
    }
    let after = sim.stats();
    // x(t) = exact(t) for 10 N plus the response to a 10 N step at t = 1.
    let want = exact(2.0) + exact(1.0);
    let got = sim.read(probe);
    eprintln!(
        "force doubled at t = 1: x(2) = {got:.12}, exact {want:.12}; work over the 100 calls after: {} Jacobians, {} LUs, {} steps",
        after.jac_evals - before.jac_evals,
        after.lu_factorisations - before.lu_factorisations,
        after.steps - before.steps
    );
    assert!((got - want).abs() < 1e-8, "{got} vs {want}");
    assert!(after.jac_evals - before.jac_evals <= 3, "{after}");
    assert!(
        after.lu_factorisations - before.lu_factorisations <= 3 * 100,
        "{after}"
    );
}

/// The same through an external input: set to a new value between calls, the same value
/// again costs nothing; a series' corner inside a call is a stop.
#[test]
fn an_input_set_between_calls_and_a_series_corner() {
    let s = settings();
    let eqs = crate::test_models::msd(1.0, 0.01, 2.0, 0.0, Some(10.0));
    let x0 = eqs.initial_state();
    let probe = eqs.probe("spring.q").unwrap();
    let mut sim = Simulation::start(eqs, 0.0, &x0, &s, vec![]).unwrap();
    for k in 1..=100 {
        sim.set_input(0, 10.0).unwrap(); // unchanged: nothing happens
        sim.advance_to(k as f64 * 0.01).unwrap();
    }
    let rhs_before = sim.stats().rhs_evals;
    sim.set_input(0, 20.0).unwrap();
    for k in 101..=200 {
        sim.advance_to(k as f64 * 0.01).unwrap();
    }
    assert!(sim.stats().rhs_evals > rhs_before);
    let want = exact(2.0) + exact(1.0);
    assert!((sim.read(probe) - want).abs() < 1e-8);
    // a held series stepping back to 10 N at t = 2.505, inside the next call
    let series =
        crate::Series::new(vec![2.0, 2.505], vec![20.0, 10.0], crate::Interp::Hold).unwrap();
    sim.set_input_series(0, series).unwrap();
    sim.advance_to(3.0).unwrap();
    let want = exact(3.0) + exact(2.0) - exact(3.0 - 2.505);
    let got = sim.read(probe);
    assert!((got - want).abs() < 1e-8, "{got} vs {want}");
}

#[test]
fn going_back_is_refused_and_a_failure_sticks() {
    let s = settings();
    let eqs = msd();
    let x0 = eqs.initial_state();
    let mut sim = Simulation::start(eqs, 0.0, &x0, &s, vec![]).unwrap();
    sim.advance(0.5).unwrap();
    sim.advance_to(0.5).unwrap();
    let e = sim.advance_to(0.25).unwrap_err();
    assert!(e.to_string().contains("only goes forward"), "{e}");
    assert!(Simulation::start(msd(), 0.0, &[0.0], &s, vec![]).is_err());
}

/// A scheduled event is applied on the way, as in a run.
#[test]
fn events_on_the_way_as_in_a_run() {
    let s = settings();
    let mut eqs = msd();
    let force = eqs.graph().find("force").unwrap();
    let x0 = eqs.initial_state();
    let probe = eqs.probe("spring.q").unwrap();
    let ev = || {
        vec![Event {
            t: 1.005,
            replacements: vec![(force, Box::new(EffortSource::new(20.0)) as Box<_>)],
        }]
    };
    let outputs = [Output {
        name: "x".into(),
        probe,
    }];
    let run = simulate(&mut eqs, &x0, &s, &outputs, ev());
    let x_run = *run.trajectory.column("x").unwrap().last().unwrap();
    let mut sim = Simulation::start(msd(), 0.0, &x0, &s, ev()).unwrap();
    for k in 1..=300 {
        sim.advance_to(k as f64 * 0.01).unwrap();
    }
    assert_eq!(sim.stats().events, 1);
    let got = sim.read(probe);
    assert!((got - x_run).abs() < 1e-8, "{got} vs {x_run}");
}
