//! A unit on a core kind's parameter (issue 37, item 2): `C`, `I`, `R`, … have no unit of
//! their own (their bonds decide it), so a value with a unit is converted to SI and not
//! checked — it was refused as "`k` is a dimensionless (), … give `k` in  or a unit".
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::{Model, Registry};

#[test]
fn a_core_kind_takes_a_value_with_a_unit_in_si() {
    let text = r#"
[elements]
j      = { kind = "1" }
mass   = { kind = "I", m = "2 t" }
spring = { kind = "C", k = "1.4577 MN/m", q0 = 1.0 }
[bonds]
b1 = "j -> mass"
b2 = "j -> spring"
"#;
    let m = Model::from_text("core.toml", text, &Registry::with_core(), &[])
        .unwrap_or_else(|e| panic!("{e}"));
    let states = m.equations.states();
    let p = states.iter().position(|s| s.name == "mass.p").unwrap();
    let mut dx = vec![0.0; m.x0.len()];
    m.equations.rhs(0.0, &m.x0, &mut dx);
    // dp/dt = −k·q = −1.4577e6 N at q = 1 m
    assert!((dx[p] + 1.4577e6).abs() < 1e-6, "{}", dx[p]);
    // and the mass is 2000 kg: p = 1 gives a velocity 1/2000 into the spring
    let mut x = m.x0.clone();
    x[p] = 1.0;
    m.equations.rhs(0.0, &x, &mut dx);
    let q = states.iter().position(|s| s.name == "spring.q").unwrap();
    assert!((dx[q] - 5e-4).abs() < 1e-15, "{}", dx[q]);
}
