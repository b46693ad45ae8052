//! Model files with hydraulic kinds: bad parameters are refused with the key, line and a hint,
//! never a panic.
#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "hydraulics_common/mod.rs"]
mod common;

use bg_model::{ErrorKind, Model};
use common::{model_path, registry};

fn lift_with(from: &str, to: &str) -> Result<Model, bg_model::ModelError> {
    let text = std::fs::read_to_string(model_path("cylinder_lift")).unwrap();
    assert!(text.contains(from), "{from}");
    Model::from_text("lift.toml", &text.replacen(from, to, 1), &registry(), &[])
}

#[test]
fn a_valve_needs_its_orifice_coefficient() {
    let e = lift_with(r#", alpha = "alpha""#, "").unwrap_err();
    assert_eq!(e.kind, ErrorKind::MissingParameter, "{e}");
    assert_eq!(e.element.as_deref(), Some("lift"));
    assert!(e.hint.as_deref().unwrap_or("").contains("cd"), "{e}");
}

#[test]
fn valve_parameters_without_a_valve_are_refused() {
    let e = lift_with(r#"x_v = "spool.out", "#, "").unwrap_err();
    assert_eq!(e.kind, ErrorKind::BadParameter, "{e}");
    assert!(e.message.contains("no valve"), "{e}");
}

#[test]
fn hold_force_and_given_pressures_exclude_each_other() {
    let e = lift_with(r#"p_p0 = "p_pre""#, r#"hold_force = "m*g", p_p0 = "p_pre""#).unwrap_err();
    assert_eq!(e.kind, ErrorKind::BadParameter, "{e}");
    assert!(e.message.contains("hold_force"), "{e}");
}

#[test]
fn geometry_is_checked_with_the_key_named() {
    let e = lift_with(r#"l_r0 = "l_r0""#, "l_r0 = 0.5").unwrap_err();
    assert_eq!(e.kind, ErrorKind::BadParameter, "{e}");
    assert!(e.message.contains("l_r0"), "{e}");
    // starting past the stroke end is allowed only with an end stop
    assert!(lift_with(r#"s0 = "s0""#, "s0 = 1.5").is_ok());
    let e = lift_with(
        r#"s0 = "s0", beta = "beta", p_t = "p_t", p_p0 = "p_pre", p_r0 = "p_pre", x_v = "spool.out", p_s = "p_s", p_tr = "p_tr", alpha = "alpha", r_int = "r_l", k_stop = 1e9, c_stop = 5e6"#,
        r#"s0 = 1.5, beta = "beta", p_t = "p_t", p_p0 = "p_pre", p_r0 = "p_pre", x_v = "spool.out", p_s = "p_s", p_tr = "p_tr", alpha = "alpha", r_int = "r_l""#,
    )
    .unwrap_err();
    assert!(e.message.contains("s0"), "{e}");
    let e = lift_with(r#"beta = "beta""#, "beta = -1.0").unwrap_err();
    assert!(e.message.contains("beta"), "{e}");
    let e = lift_with(r#"r_int = "r_l""#, "r_int = 0.0").unwrap_err();
    assert!(e.message.contains("r_int"), "{e}");
    let e = lift_with("k_stop = 1e9", "k_stop = -1e9").unwrap_err();
    assert!(e.message.contains("k_stop"), "{e}");
    let e = lift_with(r#"p_s = "p_s""#, "p_s = -1.0").unwrap_err();
    assert!(e.message.contains("p_s"), "{e}");
}

#[test]
fn unknown_cylinder_parameter_is_reported() {
    // Unknown keys are reported first, with the declared key they look like.
    let e = lift_with(r#"k_stop = 1e9"#, "k_stopp = 1e9").unwrap_err();
    assert_eq!(e.kind, ErrorKind::ExtraParameter, "{e}");
    assert!(
        e.hint
            .as_deref()
            .is_some_and(|h| h.contains("did you mean `k_stop`")),
        "{e}"
    );
    let e = lift_with(r#"k_stop = 1e9, c_stop = 5e6"#, "c_stopp = 5e6").unwrap_err();
    assert_eq!(e.kind, ErrorKind::ExtraParameter, "{e}");
}

#[test]
fn single_elements_build_from_a_model_file() {
    let text = r#"
[elements]
oil   = { kind = "hydraulics.chamber", side = "rod", area = 0.03, dead_length = 1.0, stroke = "pist.s", beta = 1.5e9, p0 = 1e6 }
oil2  = { kind = "hydraulics.chamber", side = "piston", area = 0.04, dead_length = 0.1, stroke = "pist.s", beta = 1.5e9, p0 = 1e6 }
pist  = { kind = "hydraulics.piston", a_p = 0.04, a_r = 0.03, s_max = 0.9, s0 = 0.5 }
v     = { kind = "1" }
mass  = { kind = "I", m = 100.0 }
stop  = { kind = "hydraulics.end_stop", stroke = "pist.s", s_max = 0.9, k = 1e8, c = 1e5 }
jp    = { kind = "0" }
jr    = { kind = "0" }
leak  = { kind = "hydraulics.leakage", r = 1e12 }
ext   = { kind = "hydraulics.tank_leakage", r = 1e12 }
valve = { kind = "hydraulics.valve", x_v = "0.1*sin(t)", p_s = 2e7, cd = 0.6, w = 1e-5, rho = 880.0 }
[bonds]
b1 = "valve.A -> jp"
b2 = "valve.B -> jr"
b3 = "jp -> oil2"
b4 = "jr -> oil"
b5 = "jp -> pist.p"
b6 = "jr -> pist.r"
b7 = "pist.mech -> v"
b8 = "v -> mass"
b9 = "v -> stop"
b10 = "jp -> leak.a"
b11 = "leak.b -> jr"
b12 = "jr -> ext"
[simulation]
t_end = 1.0
[outputs]
p = "oil.p"
V = "oil.V"
[[check]]
value = "V"
expected = "V"
tol = 0.0
"#;
    let mut m = Model::from_text("parts.toml", text, &registry(), &[]).unwrap();
    let out = m.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    assert_eq!(out.watched.len(), 2);
    let bad = text.replace(r#"side = "rod""#, r#"side = "top""#);
    let e = Model::from_text("parts.toml", &bad, &registry(), &[]).unwrap_err();
    assert!(e.message.contains("side"), "{e}");
    assert_eq!(e.line, Some(3));
}

fn drive_with(from: &str, to: &str) -> Result<Model, bg_model::ModelError> {
    let text = std::fs::read_to_string(model_path("motor_drive")).unwrap();
    assert!(text.contains(from), "{from}");
    Model::from_text("drive.toml", &text.replacen(from, to, 1), &registry(), &[])
}

#[test]
fn machine_parameters_are_checked_with_the_key_named() {
    let motor = r#"displacement = "d_m", c_l = "c_lm", t_c = "t_cm""#;
    for (bad, key) in [
        (
            r#"displacement = 0.0, c_l = "c_lm", t_c = "t_cm""#,
            "displacement",
        ),
        (r#"displacement = "d_m", c_l = -1.0, t_c = "t_cm""#, "c_l"),
        (r#"displacement = "d_m", c_l = "c_lm", t_c = -2.0"#, "t_c"),
        (
            r#"displacement = "d_m", c_l = "c_lm", t_c = "t_cm", omega_tanh = 0.0"#,
            "omega_tanh",
        ),
        (
            r#"displacement = "d_m", c_l = "c_lm", t_c = "t_cm", fraction = 1.5"#,
            "fraction",
        ),
    ] {
        let e = drive_with(motor, bad).unwrap_err();
        assert_eq!(e.kind, ErrorKind::BadParameter, "{e}");
        assert_eq!(e.element.as_deref(), Some("motor"), "{e}");
        assert!(e.message.contains(key), "{key}: {e}");
    }
    // a breakaway torque needs its Stribeck speed
    let e = drive_with(motor, &format!("{motor}, t_s = 3.0")).unwrap_err();
    assert_eq!(e.kind, ErrorKind::MissingParameter, "{e}");
    assert!(e.message.contains("omega_s"), "{e}");
    assert!(drive_with(motor, &format!("{motor}, t_s = 3.0, omega_s = 2.0")).is_ok());
    // a motor has no set speed: the key is refused, not ignored
    let e = drive_with(motor, &format!(r#"{motor}, speed = 100.0"#)).unwrap_err();
    assert!(e.to_string().contains("speed"), "{e}");
}

#[test]
fn a_pump_without_speed_has_a_shaft_to_bond() {
    // Without `speed` the pump has a shaft port, and a shaft left open is reported.
    let e = drive_with(r#"speed = "drive.out", "#, "").unwrap_err();
    assert!(e.to_string().contains("shaft"), "{e}");
}
