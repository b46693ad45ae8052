//! Power and volume bookkeeping of the dissipative hydraulics kinds at random states, loaded
//! from model text as a user would write them: the pump and the motor (shaft and set-speed
//! forms), the load-sensing pump and the friction element. For each, the power into the element equals its
//! dissipation `C_l·Δ² + T_f(ω)·ω` (≥ 0; zero without losses), to 1e-12 of the power
//! through it, and the machine passes the oil through (flow in at `a` = flow out at `b`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::Model;
use proptest::prelude::*;

/// The friction torque T_f(ω) = T_c·tanh(ω/ω_tanh) + b·ω (no Stribeck peak).
fn t_f(t_c: f64, w_tanh: f64, b: f64, w: f64) -> f64 {
    t_c * (w / w_tanh).tanh() + b * w
}

fn load(text: &str) -> Model {
    Model::from_text("machine.toml", text, &bg_sim::registry(), &[])
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Value of output `name` after evaluating at t = 0 (the test graphs have no states).
fn read(model: &Model, name: &str) -> f64 {
    let eqs = &model.equations;
    let p = eqs.probe(name).unwrap_or_else(|| panic!("no probe {name}"));
    eqs.read(p, 0.0, &[])
}

fn machine_model(kind: &str, shaft_bond: &str, params: &str) -> String {
    format!(
        r#"
[elements]
sa    = {{ kind = "Se", e = "pa" }}
sb    = {{ kind = "Se", e = "pb" }}
drive = {{ kind = "Sf", f = "w" }}
m     = {{ kind = "{kind}", displacement = "d", fraction = "eps", c_l = "cl", t_c = "tc", omega_tanh = "wt", b = "bv" }}

[bonds]
b1 = "sa -> m.a"
b2 = "m.b -> sb"
b3 = "{shaft_bond}"

[parameters]
{params}
"#
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Pump (`drive -> m.shaft`) and motor (`m.shaft -> drive`) in all four quadrants.
    #[test]
    fn machines_dissipate_exactly_their_losses(
        eps in -1.0f64..1.0, pa in -1e5f64..3e7, pb in -1e5f64..3e7, w in -300.0f64..300.0,
        lossless in any::<bool>(), cl in 0.0f64..5e-12, tc in 0.0f64..5.0, wt in 0.01f64..1.0,
        bv in 0.0f64..0.01, motor in any::<bool>(),
    ) {
        let (cl, tc, bv) = if lossless { (0.0, 0.0, 0.0) } else { (cl, tc, bv) };
        let d = 8e-6;
        let params = format!(
            "pa = {pa:e}\npb = {pb:e}\nw = {w:e}\nd = {d:e}\neps = {eps:e}\ncl = {cl:e}\ntc = {tc:e}\nwt = {wt:e}\nbv = {bv:e}"
        );
        let (kind, bond) = if motor {
            ("hydraulics.motor", "m.shaft -> drive")
        } else {
            ("hydraulics.pump", "drive -> m.shaft")
        };
        let model = load(&machine_model(kind, bond, &params));
        let eqs = &model.equations;
        eqs.evaluate(0.0, &[]);
        let id = eqs.graph().find("m").unwrap();
        let p_in = eqs.power_into(id);
        let scale = eqs.power_scale(id);
        // ω in the role's convention is the bond's flow (into a pump, out of a motor)
        let omega = read(&model, "b3.f");
        let delta = pa - pb;
        let dissipation = cl * delta * delta + t_f(tc, wt, bv, omega) * omega;
        prop_assert!(dissipation >= 0.0);
        prop_assert!(
            (p_in - dissipation).abs() <= 1e-12 * scale.max(f64::MIN_POSITIVE),
            "{kind}: power in {p_in:e} W, dissipation {dissipation:e} W, through {scale:e} W"
        );
        if lossless {
            prop_assert!(p_in.abs() <= 1e-12 * scale.max(f64::MIN_POSITIVE));
        }
        // volume: what enters at a leaves at b, Q = D·ω + C_l·Δ
        let (qa, qb) = (read(&model, "b1.f"), read(&model, "b2.f"));
        prop_assert_eq!(qa.to_bits(), qb.to_bits());
        let q = d * eps * omega + cl * delta;
        prop_assert!((qa - q).abs() <= 1e-12 * (d * omega.abs() + cl * delta.abs()));
    }

    /// The LS pump: the displacement machine at its stroke ε (the state), the LS port takes
    /// no flow and no power, and the stroke moves toward a target within [0, 1].
    #[test]
    fn ls_pump_dissipates_exactly_its_losses(
        eps in 0.0f64..1.0, pa in -1e5f64..3e7, pb in -1e5f64..3e7, pls in 0.0f64..3e7,
        w in -300.0f64..300.0, cl in 0.0f64..5e-12, tc in 0.0f64..5.0, bv in 0.0f64..0.01,
    ) {
        let d = 8e-6;
        let text = format!(
            r#"
[elements]
sa    = {{ kind = "Se", e = {pa:e} }}
sb    = {{ kind = "Se", e = {pb:e} }}
sl    = {{ kind = "Se", e = {pls:e} }}
drive = {{ kind = "Sf", f = {w:e} }}
m     = {{ kind = "hydraulics.ls_pump", displacement = {d:e}, p_max = 2.5e7, torque_max = 150.0, eps0 = {eps:e}, c_l = {cl:e}, t_c = {tc:e}, b = {bv:e} }}

[bonds]
b1 = "sa -> m.a"
b2 = "m.b -> sb"
b3 = "drive -> m.shaft"
b4 = "sl -> m.LS"
"#
        );
        let model = load(&text);
        let eqs = &model.equations;
        let x0 = eqs.initial_state();
        eqs.evaluate(0.0, &x0);
        let id = eqs.graph().find("m").unwrap();
        let p_in = eqs.power_into(id);
        let scale = eqs.power_scale(id);
        let delta = pa - pb;
        let dissipation = cl * delta * delta + t_f(tc, 0.1, bv, w) * w;
        prop_assert!(
            (p_in - dissipation).abs() <= 1e-12 * scale.max(f64::MIN_POSITIVE),
            "power in {p_in:e} W, dissipation {dissipation:e} W, through {scale:e} W"
        );
        let rd = |n: &str| eqs.read(eqs.probe(n).unwrap(), 0.0, &x0);
        prop_assert!(rd("b4.f") == 0.0, "LS port flow {}", rd("b4.f"));
        let (qa, qb) = (rd("b1.f"), rd("b2.f"));
        prop_assert_eq!(qa.to_bits(), qb.to_bits());
        let q = d * eps * w + cl * delta;
        prop_assert!((qa - q).abs() <= 1e-12 * (d * w.abs() + cl * delta.abs()));
        // τ·dε/dt = ε* − ε with τ = 40 ms (the default, both ways): ε* ∈ [0, 1]
        let mut dx = vec![0.0; x0.len()];
        eqs.rhs(0.0, &x0, &mut dx);
        let target = eps + 0.04 * dx[0];
        prop_assert!((-1e-12..=1.0 + 1e-12).contains(&target), "ε* = {target}");
    }

    /// A pump at a set speed: a flow source; its published drive torque closes the balance.
    #[test]
    fn pump_at_speed_balances_with_its_drive_torque(
        eps in -1.0f64..1.0, pa in -1e5f64..3e7, pb in -1e5f64..3e7, w in -300.0f64..300.0,
        cl in 0.0f64..5e-12, tc in 0.0f64..5.0, bv in 0.0f64..0.01,
    ) {
        let d = 8e-6;
        let text = format!(
            r#"
[parameters]
pa = {pa:e}
pb = {pb:e}
[elements]
sa = {{ kind = "Se", e = "pa" }}
sb = {{ kind = "Se", e = "pb" }}
m  = {{ kind = "hydraulics.pump", displacement = {d:e}, speed = {w:e}, fraction = {eps:e}, c_l = {cl:e}, t_c = {tc:e}, b = {bv:e} }}
[bonds]
b1 = "sa -> m.a"
b2 = "m.b -> sb"
[outputs]
torque = "m.torque"
"#
        );
        let model = load(&text);
        let eqs = &model.equations;
        eqs.evaluate(0.0, &[]);
        let id = eqs.graph().find("m").unwrap();
        let hydraulic_in = eqs.power_into(id);
        let drive_in = read(&model, "m.torque") * w;
        let delta = pa - pb;
        let dissipation = cl * delta * delta + t_f(tc, 0.1, bv, w) * w;
        let scale = hydraulic_in.abs().max(drive_in.abs());
        prop_assert!(
            (hydraulic_in + drive_in - dissipation).abs() <= 1e-12 * scale.max(f64::MIN_POSITIVE),
            "{hydraulic_in:e} + {drive_in:e} vs {dissipation:e}"
        );
        let (qa, qb) = (read(&model, "b1.f"), read(&model, "b2.f"));
        prop_assert_eq!(qa.to_bits(), qb.to_bits());
    }

    /// Friction: F·v ≥ 0, F odd, and F = F_c + b·v once v ≫ v_s, v_tanh.
    #[test]
    fn friction_dissipates_and_is_odd(
        v in -2.0f64..2.0, f_c in 0.0f64..1e3, f_s in 0.0f64..2e3, b in 0.0f64..1e3,
    ) {
        let text = |v: f64| format!(
            r#"
[elements]
src = {{ kind = "Sf", f = {v:e} }}
fr  = {{ kind = "hydraulics.friction", f_c = {f_c:e}, f_s = {f_s:e}, v_s = 1e-2, v_tanh = 1e-4, b = {b:e} }}
[bonds]
b1 = "src -> fr"
"#
        );
        let force = |v: f64| {
            let model = load(&text(v));
            model.equations.evaluate(0.0, &[]);
            let id = model.equations.graph().find("fr").unwrap();
            (read(&model, "b1.e"), model.equations.power_into(id))
        };
        let (f, p) = force(v);
        prop_assert!(p >= 0.0, "F·v = {p:e} at v = {v}");
        prop_assert_eq!(force(-v).0.to_bits(), (-f).to_bits());
        if v.abs() >= 1.0 {
            let expected = f_c * v.signum() + b * v;
            prop_assert!((f - expected).abs() <= 1e-12 * expected.abs().max(1.0), "{f} vs {expected}");
        }
    }
}
