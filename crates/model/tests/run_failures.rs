//! A run that fails says where it failed (issue 37, item 8): "the step size collapsed" names
//! the state with the largest weighted rate (the one whose error bounds the step).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::{Model, Registry};

/// dq/dt = q² from q = 1: q = 1/(1 − t) blows up at t = 1, and the step size collapses
/// there; `quiet` is a slow state beside it that must not be named.
#[test]
fn a_collapsed_step_names_the_state_that_drives_it() {
    let text = r#"
[elements]
feed  = { kind = "Sf", f = "tank.q^2" }
tank  = { kind = "C", c = 1.0, q0 = 1.0 }
slow  = { kind = "Sf", f = 1e-3 }
quiet = { kind = "C", c = 1.0, q0 = 1.0 }
[bonds]
b1 = "feed -> tank"
b2 = "slow -> quiet"
[simulation]
t_end = 2.0
dt_out = 0.1
"#;
    let mut m = Model::from_text("blowup.toml", text, &Registry::with_core(), &[]).unwrap();
    let (outcome, _) = m.run_checked().unwrap();
    let e = outcome
        .error
        .expect("the run must fail before t = 1")
        .to_string();
    assert!(e.contains("step size collapsed"), "{e}");
    assert!(e.contains("`tank.q`"), "{e}");
    assert!(!e.contains("quiet"), "{e}");
}

/// A run whose equations are not finite at t = 0 stops there: no row of NaN is written
/// (the partial file of `bg-sim run` held `0,1,NaN`).
#[test]
fn a_run_that_cannot_start_writes_no_row_of_non_finite_values() {
    let text = r#"
[elements]
feed  = { kind = "Sf", f = "sqrt(tank.q - 1.5)" }
tank  = { kind = "C", c = 1.0, q0 = 1.0 }
[bonds]
b1 = "feed -> tank"
[simulation]
t_end = 1.0
dt_out = 0.1
[outputs]
q = "tank.q"
f = "b1.f"
"#;
    let mut m = Model::from_text("nan.toml", text, &Registry::with_core(), &[]).unwrap();
    let (outcome, _) = m.run_checked().unwrap();
    let e = outcome
        .error
        .expect("the run must fail at t = 0")
        .to_string();
    assert!(e.contains("not finite at the start"), "{e}");
    assert_eq!(outcome.rows, 0, "{:?}", outcome.trajectory.rows);
    assert!(outcome
        .trajectory
        .rows
        .iter()
        .all(|r| r.iter().all(|v| v.is_finite())));
}

/// Numbers in messages are short: `rtol = 1e-300` was echoed with 300 zeros.
#[test]
fn numbers_in_refusals_are_printed_short() {
    let text = r#"
[elements]
feed  = { kind = "Sf", f = 1.0 }
tank  = { kind = "C", c = 1.0 }
[bonds]
b1 = "feed -> tank"
[simulation]
t_end = 1.0
rtol = 1e-300
"#;
    let e = Model::from_text("short.toml", text, &Registry::with_core(), &[]).unwrap_err();
    let shown = e.to_string();
    assert!(shown.contains("1e-300"), "{shown}");
    assert!(!shown.contains("00000000"), "{shown}");
    let e = Model::from_text(
        "short.toml",
        &text
            .replace("rtol = 1e-300", "")
            .replace("c = 1.0 }", "c = -1e-300 }"),
        &Registry::with_core(),
        &[],
    );
    if let Err(e) = e {
        assert!(!e.to_string().contains("00000000"), "{e}");
    }
}
