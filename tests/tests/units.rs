//! Units on parameters of the hydraulic kinds (issue 37, items 1, 2 and 8): a value whose
//! unit differs from the declared one only by an angle (cc vs cc/rev, 1/min vs rpm) is
//! refused with a hint instead of being read 2π off; common spellings are accepted or
//! named; `[parameters]` take units.
#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "hydraulics_common/mod.rs"]
mod common;

use bg_model::{ErrorKind, Model, ModelError};
use common::{model_path, registry};

/// `models/motor_drive.toml` with the pump's displacement and speed (and optionally one more
/// `[parameters]` line) replaced.
fn drive(displacement: &str, speed: &str, extra: &str) -> Result<Model, ModelError> {
    let text = std::fs::read_to_string(model_path("motor_drive")).unwrap();
    let from = r#"displacement = "d_p", speed = "drive.out""#;
    assert!(text.contains(from));
    let text = text
        .replacen(
            from,
            &format!(r#"displacement = {displacement}, speed = {speed}"#),
            1,
        )
        .replacen("[parameters]\n", &format!("[parameters]\n{extra}\n"), 1);
    Model::from_text("drive.toml", &text, &registry(), &[])
}

fn refused(displacement: &str, speed: &str) -> ModelError {
    match drive(displacement, speed, "") {
        Ok(_) => panic!("{displacement} / {speed} loaded"),
        Err(e) => e,
    }
}

/// The SI value a model computes for a `[parameters]` entry.
fn parameter(extra: &str, name: &str) -> f64 {
    let m = drive(r#""d_p""#, r#""drive.out""#, extra).unwrap_or_else(|e| panic!("{e}"));
    m.parameters[name]
}

#[test]
fn a_bare_volume_for_a_displacement_per_radian_is_refused_with_the_per_rev_hint() {
    let e = refused(r#""250 cc""#, r#""drive.out""#);
    assert_eq!(e.kind, ErrorKind::BadParameter, "{e}");
    assert_eq!(e.element.as_deref(), Some("pump"), "{e}");
    assert!(e.line.is_some(), "{e}");
    assert!(e.message.contains("m³/rad"), "{e}");
    let hint = e.hint.clone().unwrap_or_default();
    assert!(hint.contains("250 cc/rev"), "{e}");
    // the right spellings load
    drive(r#""40 cc/rev""#, r#""drive.out""#, "").unwrap();
    drive(r#""40 cm³/rev""#, r#""drive.out""#, "").unwrap();
    drive(r#""6.366e-6 m³/rad""#, r#""drive.out""#, "").unwrap();
    drive("6.366e-6", r#""drive.out""#, "").unwrap();
}

#[test]
fn a_speed_per_minute_without_revolutions_is_refused_and_hz_counts_cycles() {
    for bad in ["1500 1/min", "1500 min^-1", "1500 1/s"] {
        let e = refused(r#""d_p""#, &format!("\"{bad}\""));
        assert_eq!(e.kind, ErrorKind::BadParameter, "{bad}: {e}");
        let hint = e.hint.clone().unwrap_or_default();
        assert!(hint.contains("rev"), "{bad}: {e}");
    }
    for good in ["1500 rpm", "1500 RPM", "25 rev/s", "25 Hz", "157.08 rad/s"] {
        drive(r#""d_p""#, &format!("\"{good}\""), "").unwrap_or_else(|e| panic!("{good}: {e}"));
    }
}

#[test]
fn parameters_take_units_converted_to_si() {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    assert!(close(parameter(r#"p_x = "300 bar""#, "p_x"), 3e7));
    assert!(close(parameter(r#"p_x = "200 Bar""#, "p_x"), 2e7));
    assert!(close(
        parameter(r#"p_x = "40 cc/rev""#, "p_x"),
        40e-6 / std::f64::consts::TAU
    ));
    assert!(close(
        parameter(r#"p_x = "1500 rpm""#, "p_x"),
        50.0 * std::f64::consts::PI
    ));
    assert!(close(parameter(r#"p_x = "1.5 ml""#, "p_x"), 1.5e-6));
    assert!(close(parameter(r#"p_x = "2*3 mm2""#, "p_x"), 6e-6));
    assert!(close(parameter(r#"p_x = "36 m3/h""#, "p_x"), 0.01));
    assert!(close(parameter(r#"p_x = "60 lpm""#, "p_x"), 1e-3));
    assert!(close(parameter(r#"p_x = "2 µs""#, "p_x"), 2e-6));
    assert!(close(parameter(r#"p_x = "1 atm""#, "p_x"), 101_325.0));
    assert!(close(
        parameter(r#"p_x = "1 psig""#, "p_x"),
        6_894.757_293_168
    ));
    assert!(close(
        parameter(r#"p_x = "1 in^2""#, "p_x"),
        0.0254 * 0.0254
    ));
    assert!(close(parameter(r#"p_x = "5 cm3""#, "p_x"), 5e-6));
    // a parameter with a unit used where that kind of unit is declared loads ...
    drive(r#""d_x""#, r#""drive.out""#, r#"d_x = "40 cc/rev""#).unwrap();
    // ... and where another is declared, is refused: the unit is remembered
    let e = drive(r#""d_x""#, r#""drive.out""#, r#"d_x = "40 cc""#).unwrap_err();
    assert!(e.hint.clone().unwrap_or_default().contains("cc/rev"), "{e}");
}

#[test]
fn an_unknown_unit_is_named_with_a_suggestion() {
    let e = drive(r#""d_p""#, r#""drive.out""#, r#"p_x = "200 barr""#).unwrap_err();
    assert!(e.message.contains("unknown unit `barr`"), "{e}");
    assert!(e.hint.clone().unwrap_or_default().contains("`bar`"), "{e}");
    assert!(!e.message.contains("unexpected"), "{e}");
    let e = drive(r#""d_p""#, r#""drive.out""#, r#"p_x = "3 bara""#).unwrap_err();
    assert!(e.hint.clone().unwrap_or_default().contains("gauge"), "{e}");
    let e = drive(r#""d_p""#, r#""drive.out""#, r#"p_x = "3 gpm""#).unwrap_err();
    assert!(e.message.contains("unknown unit `gpm`"), "{e}");
    let e = refused(r#""d_p""#, r#""1500 RMP""#);
    assert!(e.message.contains("unknown unit `RMP`"), "{e}");
}
