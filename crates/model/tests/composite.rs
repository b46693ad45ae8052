//! Composite kinds: one model-file entry expands into members and internal bonds, exposes
//! ports, is listed member by member, and is rebuilt by events.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::{ErrorKind, Model, Registry};
use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::{Capacitor, Composite, OneJunction, Resistor};

/// An RC branch: a 1-junction carrying a resistor and a capacitor, exposed as port `in`.
fn rc_branch(s: &dyn Params) -> Result<Composite, BuildError> {
    let r = Resistor::new(s.modulated("r")?)?;
    let c = Capacitor::new(s.number("c")?, 0.0)?;
    let mut comp = Composite::default();
    comp.element("loop", OneJunction)
        .element("r", r)
        .element("c", c);
    comp.bond("b1", "loop", "r")
        .bond("b2", "loop", "c")
        .port("in", "loop");
    Ok(comp)
}

fn registry() -> Registry {
    let mut r = Registry::with_core();
    const PARAMS: &[ParamDecl] = &[
        ParamDecl::modulated("r", "Ω", "resistance").non_negative(),
        ParamDecl::number("c", "F", "capacitance").positive(),
    ];
    r.register(KindDecl::composite(
        "test.rc",
        "an RC branch",
        PARAMS,
        rc_branch,
    ));
    r
}

const MODEL: &str = r#"
[parameters]
R = 1000.0
[elements]
src = { kind = "Se", e = 12.0 }
rc  = { kind = "test.rc", r = "R", c = 1e-6 }
[bonds]
b1 = "src -> rc.in"
[simulation]
t_end = 5e-3
dt_out = 1e-3
rtol = 1e-9
[[events]]
t = 2e-3
set = { R = 2000.0 }
[outputs]
u = "rc_c.e"
"#;

#[test]
fn composite_expands_runs_and_switches() {
    let mut m = Model::from_text("rc.toml", MODEL, &registry(), &[]).unwrap();
    let g = m.equations.graph();
    for name in ["rc_loop", "rc_r", "rc_c"] {
        assert!(g.find(name).is_some(), "{name} missing");
    }
    assert!(g.bonds().any(|b| b.name == "rc_b1"));
    assert_eq!(m.element_line("rc_c"), Some(6));
    let out = m.run().unwrap();
    assert!(out.error.is_none());
    // u = 12(1 − e^(−t/RC)) until 2 ms, then the time constant doubles.
    let u = out.trajectory.column("u").unwrap();
    let u2 = 12.0 * (1.0 - (-2.0f64).exp());
    assert!((u[2] - u2).abs() < 1e-6, "{}", u[2]);
    let u5 = 12.0 - (12.0 - u2) * (-3e-3f64 / 2e-3).exp();
    assert!((u[5] - u5).abs() < 1e-6, "{} vs {u5}", u[5]);
    // the model can run again: the members were restored after the event
    let again = m.run().unwrap();
    assert!((again.trajectory.column("u").unwrap()[5] - u5).abs() < 1e-6);
}

#[test]
fn unknown_composite_port_is_reported_with_its_ports() {
    let text = MODEL.replace("rc.in", "rc.out");
    let e = Model::from_text("rc.toml", &text, &registry(), &[]).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Graph);
    assert_eq!(e.line, Some(8));
    assert!(e.hint.as_deref().unwrap_or("").contains("in"), "{e}");
}
