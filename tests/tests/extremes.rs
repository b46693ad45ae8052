//! The extremes matrix (`docs/extremes.md`): the hydraulic and mechanical parameters at the
//! ends of their ranges, the tolerances and every solver, on `cylinder_lift` (10 s, fast) and
//! on short runs of the crane (1 s unless said). Every cell is bounded: at most
//! [`MAX_STEPS`] steps and [`WALL_LIMIT`] of wall time (a watchdog interrupts the run, which
//! keeps its rows). Each cell either completes, with its steps and key figures asserted
//! within bounds, or stops with a reason that names the time, the state and the element, with
//! its rows kept.
//!
//! Run with `--nocapture` to see the matrix rows (cell, outcome, steps, wall time).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use bg_model::{CheckResult, Model};
use bg_tests::root;
use bondgraph::{Method, Outcome, SimulationError};

/// Most accepted steps of a cell.
const MAX_STEPS: usize = 200_000;
/// Longest wall time of a cell (the dev/test profile; cells take at most ~1 s).
const WALL_LIMIT: Duration = Duration::from_secs(30);

/// A cell's run: the outcome and the checks (if the model's were evaluated); its wall time is
/// printed with the matrix row, not asserted.
struct Cell {
    out: Outcome,
    checks: Vec<CheckResult>,
}

impl Cell {
    fn col(&self, name: &str) -> Vec<f64> {
        self.out
            .trajectory
            .column(name)
            .unwrap_or_else(|| panic!("no column {name}"))
    }
    fn last(&self, name: &str) -> f64 {
        *self.col(name).last().unwrap()
    }
    fn max(&self, name: &str) -> f64 {
        self.col(name).into_iter().fold(f64::NEG_INFINITY, f64::max)
    }
    fn min(&self, name: &str) -> f64 {
        self.col(name).into_iter().fold(f64::INFINITY, f64::min)
    }
    fn completed(&self, name: &str) -> &Self {
        assert!(
            self.out.error.is_none(),
            "{name}: stopped: {:?}",
            self.out.error
        );
        self
    }
    fn steps_within(&self, name: &str, lo: usize, hi: usize) -> &Self {
        let s = self.out.stats.steps;
        assert!(
            (lo..=hi).contains(&s),
            "{name}: {s} steps, not in {lo}..={hi}"
        );
        self
    }
    fn checks_pass(&self, name: &str) -> &Self {
        assert!(!self.checks.is_empty(), "{name}: no checks evaluated");
        for c in &self.checks {
            assert!(
                c.passed,
                "{name}: check {} failed: {:e}",
                c.value, c.max_error
            );
        }
        self
    }
}

/// Load `models/<file>.toml` (or `text`, if given) with `sets`, run it bounded, print its
/// matrix row.
fn cell(
    name: &str,
    file: &str,
    text: Option<&str>,
    sets: &[&str],
    tweak: impl FnOnce(&mut Model),
) -> Cell {
    let mut m = match text {
        Some(t) => {
            let set: Vec<String> = sets.iter().map(|s| (*s).to_owned()).collect();
            Model::from_text(&format!("{file}.toml"), t, &bg_sim::registry(), &set)
        }
        None => bg_tests::load(file, sets),
    }
    .unwrap_or_else(|e| panic!("{name}: {e}"));
    tweak(&mut m);
    m.settings.max_steps = MAX_STEPS;
    let flag = Arc::new(AtomicBool::new(false));
    m.settings.interrupt = Some(Arc::clone(&flag));
    let (done, wait) = channel::<()>();
    let watchdog = std::thread::spawn(move || {
        if let Err(RecvTimeoutError::Timeout) = wait.recv_timeout(WALL_LIMIT) {
            flag.store(true, Ordering::Relaxed);
        }
    });
    let start = Instant::now();
    let with_checks = !m.checks.is_empty() && file == "cylinder_lift";
    let (out, checks) = if with_checks {
        m.run_checked().unwrap_or_else(|e| panic!("{name}: {e}"))
    } else {
        (
            m.run().unwrap_or_else(|e| panic!("{name}: {e}")),
            Vec::new(),
        )
    };
    let wall = start.elapsed();
    drop(done);
    watchdog.join().unwrap();
    let outcome = match &out.error {
        None => "completes".to_owned(),
        Some(e) => format!(
            "stops: {}",
            e.to_string().chars().take(90).collect::<String>()
        ),
    };
    eprintln!(
        "| {name} | {} | {outcome} | {} | {:.0} |",
        m.settings.method.name(),
        out.stats.steps,
        wall.as_secs_f64() * 1e3
    );
    assert!(
        !matches!(out.error, Some(SimulationError::Interrupted { .. })),
        "{name}: took longer than {WALL_LIMIT:?}"
    );
    Cell { out, checks }
}

fn lift(name: &str, sets: &[&str]) -> Cell {
    cell(name, "cylinder_lift", None, sets, |_| {})
}

fn crane(name: &str, t_end: f64, sets: &[&str]) -> Cell {
    cell(name, "knuckle_boom", None, sets, |m| {
        m.settings.t_end = t_end
    })
}

/// `cylinder_lift` settles at l_d − offset (1.8923 m) with these chamber pressures.
const LIFT_L_SS: f64 = 1.9 - 7.7e-3;

// ---------------------------------------------------------------------------------------
// Oil: bulk modulus and dead volume

#[test]
fn bulk_modulus_from_soft_to_stiff() {
    // soft oil (1e7 Pa, 150 times softer): the lift still settles, slower and less exactly
    let c = lift("lift β = 1e7 Pa", &["parameters.beta=1e7"]);
    c.completed("β 1e7").steps_within("β 1e7", 100, 2_000);
    assert!((c.last("l") - LIFT_L_SS).abs() < 3e-3, "{}", c.last("l"));
    let c = lift("lift β = 1.5e9 Pa", &["parameters.beta=1.5e9"]);
    c.completed("β 1.5e9")
        .steps_within("β 1.5e9", 100, 2_000)
        .checks_pass("β 1.5e9");
    // stiff oil (1e11): the pressure transients are 8 times faster; the steady state is exact
    let c = lift("lift β = 1e11 Pa", &["parameters.beta=1e11"]);
    c.completed("β 1e11").steps_within("β 1e11", 100, 3_000);
    assert!((c.last("l") - LIFT_L_SS).abs() < 1e-4, "{}", c.last("l"));
    for beta in ["1e7", "1e11"] {
        let c = crane(
            &format!("crane β = {beta} Pa, 1 s"),
            1.0,
            &[&format!("parameters.beta={beta}")],
        );
        c.completed(beta).steps_within(beta, 50, 5_000);
        // the static initialisation holds at any β
        assert!((c.col("F_c1")[0] - 207_073.3).abs() < 1.0);
        assert!(c.min("q1") > -0.05 && c.max("q1") < 0.5, "{beta}: q1");
    }
}

#[test]
fn chamber_dead_length_down_to_1e_4_m() {
    // the piston-side dead volume from 0.05 m down to 0.1 mm: the chamber gets 500 times
    // stiffer at s = 0, the lift starts at s = 0.2 m so its chamber is still 0.2 m long
    let c = lift("lift l_p0 = 1e-4 m", &["parameters.l_p0=1e-4"]);
    c.completed("l_p0")
        .steps_within("l_p0", 100, 2_000)
        .checks_pass("l_p0");
    // the crane's cylinder 1 starts at s = 0.106 m: its chamber is 1.5 times stiffer
    let c = crane("crane l_p0 = 1e-4 m, 1 s", 1.0, &["parameters.l_p0=1e-4"]);
    c.completed("crane l_p0")
        .steps_within("crane l_p0", 50, 5_000);
    assert!(c.min("p_p1") > 1e6, "{}", c.min("p_p1"));
}

// ---------------------------------------------------------------------------------------
// The crane: lumped-mass springs and modes

#[test]
fn lumped_mass_springs_soft_and_stiff() {
    // k_c = 1e5 N/m: the lumped masses hang on soft springs (about 4 Hz for the barrel)
    let c = crane("crane k_c = 1e5 N/m, 1 s", 1.0, &["parameters.k_c=1e5"]);
    c.completed("k_c 1e5").steps_within("k_c 1e5", 50, 2_000);
    // k_c = 1e12 N/m: 100 kHz springs; Radau's L-stability steps over them, but the
    // start-up transient is resolved
    let c = crane("crane k_c = 1e12 N/m, 1 s", 1.0, &["parameters.k_c=1e12"]);
    c.completed("k_c 1e12")
        .steps_within("k_c 1e12", 100, 20_000);
    for k in [1, 2] {
        let f = c.max(&format!("F_c{k}"));
        assert!(f.is_finite() && f.abs() < 2e6, "F_c{k} max {f}");
    }
}

#[test]
fn zero_five_and_ten_modes_per_link() {
    let mut states = Vec::new();
    let mut l1s = Vec::new();
    for modes in [0, 5, 10] {
        let m = format!("{modes}");
        let c = crane(
            &format!("crane {modes} modes per link, 1 s"),
            1.0,
            &[
                &format!("parameters.modes1={m}"),
                &format!("parameters.modes2={m}"),
            ],
        );
        c.completed(&m).steps_within(&m, 20, 5_000);
        states.push(c.out.x_final.len());
        let l1 = c.last("l1");
        assert!((4.2..4.5).contains(&l1), "{modes} modes: l1(1 s) = {l1}");
        l1s.push(l1);
    }
    assert_eq!(states, [26, 46, 66]);
    // the stroke after 1 s (0.77 m) agrees within 1 % whatever the modes
    let spread = l1s.iter().fold(0.0_f64, |w, x| w.max((x - l1s[2]).abs()));
    assert!(spread < 1e-2 * 0.77, "l1(1 s) by modes: {l1s:?}");
}

// ---------------------------------------------------------------------------------------
// Valve law, stroke ends, payload, supply

#[test]
fn the_papers_square_root_orifice() {
    // p_tr = 0: sign(Δp)·√|Δp|, not Lipschitz at Δp = 0
    let c = lift("lift p_tr = 0", &["parameters.p_tr=0"]);
    c.completed("lift p_tr 0")
        .steps_within("lift p_tr 0", 100, 2_000)
        .checks_pass("lift p_tr 0");
    for solver in [Method::Radau5, Method::Bdf] {
        let c = cell(
            &format!("crane p_tr = 0, 1 s ({})", solver.name()),
            "knuckle_boom",
            None,
            &["parameters.p_tr=0"],
            |m| {
                m.settings.t_end = 1.0;
                m.settings.method = solver;
            },
        );
        c.completed(solver.name())
            .steps_within(solver.name(), 50, 5_000);
        assert!((4.2..4.5).contains(&c.last("l1")), "{}", c.last("l1"));
    }
}

/// The lift's file without its end stops.
fn lift_without_end_stops() -> String {
    let text = std::fs::read_to_string(root().join("models/cylinder_lift.toml")).unwrap();
    let cut = text.replace(", k_stop = 1e9, c_stop = 5e6", "");
    assert_ne!(
        cut, text,
        "the lift's end stop is where this test expects it"
    );
    cut
}

#[test]
fn a_desired_length_beyond_the_stroke() {
    // l_d = 2.5 m, the stroke ends at l = 2.2 m
    let c = lift("lift l_d = 2.5 m, end stop", &["parameters.l_d=2.5"]);
    c.completed("with stop")
        .steps_within("with stop", 100, 3_000);
    let l = c.last("l");
    assert!((2.2..2.201).contains(&l), "held at the stop: l = {l}");
    let no_stop = lift_without_end_stops();
    let c = cell(
        "lift l_d = 2.5 m, no end stop",
        "cylinder_lift",
        Some(&no_stop),
        &["parameters.l_d=2.5"],
        |_| {},
    );
    let e = c.out.error.as_ref().expect("the piston leaves its stroke");
    let SimulationError::LimitReached {
        t,
        state,
        element,
        which,
        limit,
        ..
    } = e
    else {
        panic!("{e}")
    };
    assert_eq!(
        (state.as_str(), element.as_str(), *which),
        ("lift_piston.s", "lift_piston", "upper")
    );
    assert!((limit - 1.0).abs() < 1e-12 && *t > 0.5 && *t < 10.0, "{e}");
    let text = e.to_string();
    assert!(
        text.contains("lift_piston") && text.contains("t = ") && text.contains("end stop"),
        "{text}"
    );
    // the rows up to the crossing are kept
    assert!(c.out.trajectory.rows.len() > 10);
    assert!(c.last("t") <= *t + 1e-12 && c.last("t") > t - 0.011);
    assert!(c.max("l") <= 2.2 + 1e-9);

    // the crane has no end stops: cylinder 2 leaves its stroke at l = 6.2 m
    let c = crane(
        "crane l_d = 6.5 m, no end stop",
        10.0,
        &["parameters.l_d=6.5"],
    );
    let e = c.out.error.as_ref().expect("cylinder 2 leaves its stroke");
    let SimulationError::LimitReached { t, element, .. } = e else {
        panic!("{e}")
    };
    assert_eq!(element, "cyl2_piston");
    assert!((5.0..7.0).contains(t), "{e}");
    assert!(c.out.trajectory.rows.len() > 500, "rows kept");
    // with end stops added it holds both cylinders at the end of their stroke
    let c = crane(
        "crane l_d = 6.5 m, end stops, 10 s",
        10.0,
        &[
            "parameters.l_d=6.5",
            "elements.cyl1.k_stop=1e9",
            "elements.cyl1.c_stop=5e6",
            "elements.cyl2.k_stop=1e9",
            "elements.cyl2.c_stop=5e6",
        ],
    );
    c.completed("crane stops")
        .steps_within("crane stops", 100, 20_000);
    for k in ["l1", "l2"] {
        let l = c.last(k);
        assert!((6.19..6.21).contains(&l), "{k} = {l}");
    }
}

#[test]
fn zero_payload() {
    // an empty hook: the pendulum coordinate has no inertia, refused at load with its name
    let e = bg_tests::load("knuckle_boom", &["parameters.m3=0"]).unwrap_err();
    let text = e.to_string();
    eprintln!(
        "| crane m3 = 0 | – | refused at load: {} | 0 | 0 |",
        text.lines().next().unwrap_or("")
    );
    assert_eq!(e.element.as_deref(), Some("crane"));
    assert!(e.line.is_some());
    assert!(
        text.contains("q3 has none") && text.contains("hook"),
        "{text}"
    );
    // a 1 kg hook: the crane lifts its own weight
    let c = crane("crane m3 = 1 kg, 1 s", 1.0, &["parameters.m3=1"]);
    c.completed("m3 1").steps_within("m3 1", 20, 5_000);
    // the hold force without the 5 t payload: 207 kN less its share
    let f1 = c.col("F_c1")[0];
    assert!((50e3..150e3).contains(&f1), "F_c1(0) = {f1}");
    assert!(c.last("rho5").abs() < 100.0, "rho5 = {}", c.last("rho5"));
}

#[test]
fn a_supply_too_weak_to_lift() {
    // 5 MPa supply, 12.5 MPa needed: the valve opens, the load sinks to the bottom stop
    let c = lift("lift P_s = 5 MPa (stall)", &["parameters.p_s=5e6"]);
    c.completed("stall").steps_within("stall", 100, 3_000);
    assert!(c.max("l") <= 1.4 + 1e-6, "never rises: {}", c.max("l"));
    let l = c.last("l");
    assert!((1.199..1.21).contains(&l), "on the bottom stop: {l}");
    assert!(
        c.out.watched.iter().any(|w| w.warning.is_some()),
        "the rod side cavitates, and says so"
    );
    // the crane has no end stop: cylinder 1 sinks out of its stroke
    let c = crane("crane P_s = 5 MPa (stall)", 5.0, &["parameters.P_s=5e6"]);
    let e = c
        .out
        .error
        .as_ref()
        .expect("cylinder 1 sinks out of its stroke");
    let SimulationError::LimitReached {
        t, element, which, ..
    } = e
    else {
        panic!("{e}")
    };
    assert_eq!((element.as_str(), *which), ("cyl1_piston", "lower"));
    assert!((1.0..4.0).contains(t), "{e}");
    assert!(c.out.trajectory.rows.len() > 100, "rows kept");
    // it first rises 3 cm (the booms drop into their deflection and the rod-side oil
    // expands), then sinks
    assert!(c.max("l1") < 3.65, "hardly rises: {}", c.max("l1"));
    assert!(c.last("l1") < 3.55, "sinks: {}", c.last("l1"));
}

// ---------------------------------------------------------------------------------------
// Tolerances and solvers

#[test]
fn loose_and_tight_tolerances() {
    for rtol in [1e-2, 1e-10] {
        let name = format!("lift rtol {rtol:e}");
        let c = cell(&name, "cylinder_lift", None, &[], |m| {
            m.settings.rtol = rtol
        });
        c.completed(&name)
            .steps_within(&name, 20, 3_000)
            .checks_pass(&name);
    }
    let loose = cell("crane rtol 1e-2, 1 s", "knuckle_boom", None, &[], |m| {
        m.settings.t_end = 1.0;
        m.settings.rtol = 1e-2;
    });
    loose
        .completed("crane 1e-2")
        .steps_within("crane 1e-2", 20, 1_000);
    let tight = cell("crane rtol 1e-10, 1 s", "knuckle_boom", None, &[], |m| {
        m.settings.t_end = 1.0;
        m.settings.rtol = 1e-10;
    });
    tight
        .completed("crane 1e-10")
        .steps_within("crane 1e-10", 1_000, 50_000);
    // the loose run is still within 1 % of the tight one on the cylinder lengths
    let (a, b) = (loose.col("l1"), tight.col("l1"));
    let worst = a
        .iter()
        .zip(&b)
        .fold(0.0_f64, |w, (x, y)| w.max((x - y).abs()));
    assert!(worst < 1e-2 * 0.4, "l1 differs by {worst} m");
    // more work for the tighter tolerance (counted, not timed: timing belongs to benchmarks)
    assert!(tight.out.stats.steps > loose.out.stats.steps);
}

#[test]
fn every_solver() {
    let mut finals = Vec::new();
    for method in [
        Method::Radau5,
        Method::Bdf,
        Method::Esdirk34,
        Method::TrBdf2,
        Method::Tsit45,
    ] {
        let name = format!("lift {}", method.name());
        let c = cell(&name, "cylinder_lift", None, &[], |m| {
            m.settings.method = method
        });
        c.completed(&name)
            .steps_within(&name, 100, 5_000)
            .checks_pass(&name);
        let name = format!("crane {}, 1 s", method.name());
        let c = cell(&name, "knuckle_boom", None, &[], |m| {
            m.settings.t_end = 1.0;
            m.settings.method = method;
        });
        c.completed(&name).steps_within(&name, 50, 5_000);
        finals.push(c.last("l1"));
    }
    let spread = finals
        .iter()
        .fold(0.0_f64, |w, x| w.max((x - finals[0]).abs()));
    assert!(spread < 1e-3, "l1(1 s) by solver: {finals:?}");
}
