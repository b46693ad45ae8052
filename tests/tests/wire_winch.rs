//! The arm's wire payload on a `mechanical.winch` (docs/offshore.md): a drum held by a
//! constant motor torque lowers a hanging payload; the pay-out reaches the closed-form
//! steady speed, and the wire carries exactly the weight.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::Model;

const MODEL: &str = r#"
title = "A winch lowering a payload from a mast"
[parameters]
m = 100.0
g = 9.81
r = 0.2
J = 1.0
b = 50.0
T_m = "-0.5*r*m*g"          # the motor holds half the weight
[elements]
torque = { kind = "Se", e = "T_m" }
winch = { kind = "mechanical.winch", r = "r", J = "J", b = "b", length = 2.0 }
[elements.mast]
kind = "manipulator.planar_arm"
gravity = "g"
links = [{ type = "rigid", length = 2.0, mass_per_length = 5e11 }]
q0 = ["pi/2"]
payload = { type = "wire", mass = "m", EA = 1e6, damping = 0.01, length = 2.0, winch = true }
[bonds]
b1 = "torque -> winch.shaft"
b2 = "mast.wire -> winch.wire"
[simulation]
t_end = 3.0
dt_out = 0.01
rtol = 1e-9
atol = 1e-10
[outputs]
speed = "winch.speed"
tension = "mast_payload.T"
paid_out = "mast_payload.L"
drum_length = "winch.length"
"#;

#[test]
fn wire_on_a_winch_at_constant_torque_pays_out_at_the_closed_form_speed() {
    let mut model = Model::from_text("winch.toml", MODEL, &bg_sim::registry(), &[])
        .unwrap_or_else(|e| panic!("{e}"));
    let out = model.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    let col = |n: &str| out.trajectory.column(n).unwrap();
    let (speed, tension, paid, drum) = (
        col("speed"),
        col("tension"),
        col("paid_out"),
        col("drum_length"),
    );
    // J ω̇ = n T + r F − b ω with F = m g at steady speed: ω = (T + r m g)/b, v = r ω
    let (m, g, r, b) = (100.0, 9.81, 0.2, 50.0);
    let t_m = -0.5 * r * m * g;
    let v = r * (t_m + r * m * g) / b;
    let (v_end, f_end) = (*speed.last().unwrap(), *tension.last().unwrap());
    eprintln!(
        "steady pay-out {v_end:.6} m/s (closed form {v:.6}), tension {f_end:.3} N (m g = {:.3})",
        m * g
    );
    assert!((v_end / v - 1.0).abs() < 1e-6, "pay-out {v_end} vs {v}");
    assert!((f_end / (m * g) - 1.0).abs() < 1e-6, "tension {f_end}");
    // the payload's paid-out length and the drum's are the same integral of the pay-out speed
    let worst = paid
        .iter()
        .zip(&drum)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "paid-out lengths differ by {worst} m");
}
