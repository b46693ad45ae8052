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
