//! The composite kind `manipulator.planar_arm` in a model file: it expands into the fields,
//! connects to the rest of the model through `cyl1`, `cyl2`, runs, is rebuilt by an event
//! (the modal damping switched off), and reports mistakes in its nested tables.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::{Model, Registry};

fn registry() -> Registry {
    let mut r = Registry::with_core();
    r.add(bg_manipulator::KINDS);
    r
}

const MODEL: &str = r#"
title = "Knuckle boom arm held by constant cylinder forces"

[parameters]
g = 9.81
L1 = 10.0
L2 = 8.0
L3 = 6.0
E = 210e9
rho = 7850.0
A = 0.0264
I = 5.89e-4
m3 = 5000.0
d0 = 3.0
beta3 = "pi/3"
h1 = 4.0
h2 = 4.0
h3 = 3.0
m_p = 235.0
m_b = 713.0
k_c = 1e8
c_c = 2e5
r_p = 5000.0
r_e = 2.5e5
F1 = 207073.0
F2 = -80556.0

[elements]
force1 = { kind = "Se", e = "F1" }
force2 = { kind = "Se", e = "F2" }

[elements.crane]
kind = "manipulator.planar_arm"
gravity = "g"
q0 = [0.0, "-2*pi/3", "pi/6"]
damping = [0, 0, "r_p", "r_e", "r_e", "r_e", "r_e", "r_e", "r_e"]
links = [
  { type = "beam", length = "L1", E = "E", rho = "rho", A = "A", I = "I", modes = 3 },
  { type = "beam", length = "L2", E = "E", rho = "rho", A = "A", I = "I", modes = 3 },
  { type = "pendulum", length = "L3", mass = "m3" },
]
actuators = [
  { from = { ground = ["d0*cos(beta3)", "-d0*sin(beta3)"] }, to = { link = 1, x = "h1" } },
  { from = { link = 1, x = "L1 - h2" }, to = { link = 2, x = "h3" } },
]
lumped_masses = [
  { link = 1, x = "h1", mass = "m_p" },
  { link = 1, x = "L1 - h2", mass = "m_b" },
  { link = 2, x = "h3", mass = "m_p" },
]
lumped_model = "springs"
lumped_stiffness = "k_c"
lumped_damping = "c_c"

[bonds]
b1 = "force1 -> crane.cyl1"
b2 = "force2 -> crane.cyl2"

[simulation]
t_end = 0.6
dt_out = 0.1
rtol = 1e-6

[[events]]
t = 0.5
set = { r_e = 0.0 }

[outputs]
q1 = "crane_arm.q[0]"
l1 = "crane_act1.l1"
l2 = "crane_act2.l2"
w1_mid = "crane_arm.w1_mid"
rho5 = "crane_rho.rho5"
rho6 = "crane_rho.rho6"
P_r = "crane_r.P"
u3 = "crane_arm.u[2]"
"#;

#[test]
fn the_knuckle_boom_arm_loads_runs_and_switches_its_damping() {
    let mut m = Model::from_text("arm.toml", MODEL, &registry(), &[]).unwrap();
    let g = m.equations.graph();
    for name in [
        "crane_arm",
        "crane_c",
        "crane_r",
        "crane_act1",
        "crane_act2",
        "crane_lump",
        "crane_masses",
        "crane_rho",
    ] {
        assert!(g.find(name).is_some(), "{name} missing");
    }
    let out = m.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    assert_eq!(out.stats.events, 1);
    let col = |c: &str| out.trajectory.column(c).unwrap();
    let (l1, l2) = (col("l1"), col("l2"));
    assert!((l1[0] - 13f64.sqrt()).abs() < 1e-12 && (l2[0] - 13f64.sqrt()).abs() < 1e-12);
    // Link 1 bends by centimetres: cylinder 1 pushes it up between its joints.
    let w1 = col("w1_mid");
    assert!(w1[5] > 1e-3 && w1[5] < 0.1, "w1_mid = {}", w1[5]);
    // Before the switch the modal dampers dissipate too; after it only r_p on q3 does.
    let (p_r, u3) = (col("P_r"), col("u3"));
    let joint = |k: usize| 5000.0 * u3[k] * u3[k];
    for (k, p) in p_r.iter().enumerate().take(5).skip(1) {
        assert!(p - joint(k) > 1e-6, "t = 0.{k}: {p} vs {}", joint(k));
    }
    assert!(
        (p_r[6] - joint(6)).abs() <= 1e-9 * joint(6).max(1e-12),
        "t = 0.6: {} vs {}",
        p_r[6],
        joint(6)
    );
    // The payload is briefly almost in free fall (the pins start unloaded), then hangs again.
    let rho5 = col("rho5");
    assert!(rho5.iter().all(|r| r.is_finite() && *r < 0.0), "{rho5:?}");
}

#[test]
fn mistakes_in_nested_tables_are_reported_with_their_path() {
    for (from, to, expect) in [
        (
            "modes = 3 },\n  { type = \"beam\"",
            "modes = 3, mdoes = 2 },\n  { type = \"beam\"",
            "unknown key `mdoes`",
        ),
        (
            "{ type = \"pendulum\"",
            "{ type = \"string\"",
            "links[3].type",
        ),
        (
            "{ link = 2, x = \"h3\" } },",
            "{ link = 4, x = \"h3\" } },",
            "link 4 does not exist",
        ),
        (
            "lumped_model = \"springs\"",
            "lumped_model = \"spring\"",
            "lumped_model",
        ),
        (
            "q0 = [0.0, \"-2*pi/3\", \"pi/6\"]",
            "q0 = [0.0, \"-2*pi/3\", \"pi/6\", 0, 0, 0, 0, 0, 0, 0]",
            "q0",
        ),
    ] {
        assert!(MODEL.contains(from), "{from}");
        let text = MODEL.replacen(from, to, 1);
        let e = Model::from_text("arm.toml", &text, &registry(), &[])
            .err()
            .unwrap();
        let msg = format!("{e} {}", e.hint.clone().unwrap_or_default());
        assert!(msg.contains(expect), "expected `{expect}` in: {msg}");
        assert!(e.line.is_some(), "{msg}");
    }
}

/// A free two-link arm whose first link is given by `link1` (a TOML inline table's inside).
fn two_links(link1: &str) -> String {
    format!(
        r#"
[parameters]
E = 210e9
rho = 7850.0
A = 0.0264
I = 5.89e-4

[tables]
boom_EI = {{ x = [0, 10], y = [1.9e8, 0.76e8] }}
boom_rhoA = {{ x = [0, 10], y = [260, 104] }}

[elements.arm]
kind = "manipulator.planar_arm"
q0 = [0.3, -1.0, 0.02, -0.01, 0.005, 0.01, 0.0, -0.003]
u0 = [0.2, -0.4, 0.3, 0.1, -0.2, 0.05, 0.1, 0.2]
geometric_stiffening = true
links = [
  {{ type = "beam", length = 10.0, modes = 3, {link1} }},
  {{ type = "beam", length = 8.0, E = "E", rho = "rho", A = "A", I = "I", modes = 3 }},
]

[simulation]
t_end = 0.1
"#
    )
}

/// The right-hand side at the initial state.
fn rhs(link1: &str) -> Vec<f64> {
    let model = Model::from_text("arm.toml", &two_links(link1), &registry(), &[])
        .unwrap_or_else(|e| panic!("{link1}: {e} {:?}", e.hint));
    let eqs = &model.equations;
    let x = eqs.initial_state();
    let mut dx = vec![0.0; x.len()];
    eqs.rhs(0.0, &x, &mut dx);
    dx
}

fn assert_same(what: &str, a: &[f64], b: &[f64], tol: f64) {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let err = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    eprintln!("{what}: max |Δ| / max |ẋ| = {:.1e}", err / scale);
    assert!(err <= tol * scale, "{what}: {err:e} of {scale:e}");
}

#[test]
fn link_profiles_may_be_expressions_or_tables_of_x() {
    let uniform = rhs(r#"E = "E", rho = "rho", A = "A", I = "I""#);
    // a uniform link given as expressions (constant, or reading x) equals the uniform link
    let base = r#"E = "E", rho = "rho", A = "A", I = "I""#;
    for given in [
        r#"EI_of_x = "E*I", rhoA_of_x = "rho*A", rhoI_of_x = "rho*I""#,
        r#"EI_of_x = "E*I*(1 + 0*x)", rhoA_of_x = "rho*A + 0*x", rhoI_of_x = "rho*I + x - x""#,
    ] {
        let other = rhs(&format!("{base}, {given}"));
        assert_same(given, &other, &uniform, 1e-12);
    }
    // a linear taper: by samples, by an expression of x, by tables called at x
    let samples = rhs(&format!(
        "{base}, EI_samples = [1.9e8, 1.33e8, 0.76e8], rhoA_samples = [260, 182, 104]"
    ));
    let expression = rhs(&format!(
        r#"{base}, EI_of_x = "1.9e8*(1 - 0.06*x)", rhoA_of_x = "260*(1 - 0.06*x)""#
    ));
    let tables = rhs(&format!(
        r#"{base}, EI_of_x = "boom_EI(x)", rhoA_of_x = "boom_rhoA(x)""#
    ));
    assert_same("taper by expression", &expression, &samples, 1e-12);
    assert_same("taper by tables", &tables, &samples, 1e-12);
    let diff = uniform
        .iter()
        .zip(&samples)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff > 1e-3, "the taper changes the dynamics");
    // mistakes: another variable than x, or samples and an expression at once
    for (given, expect) in [
        (r#"EI_of_x = "2e8*s""#, "is an expression of `x`"),
        (r#"EI_of_x = "2e8*(1 + arm_arm.q1*x)""#, "may read only x"),
        (r#"EI_of_x = "2e8", EI_samples = [2e8, 1e8]"#, "not both"),
    ] {
        let text = two_links(&format!("{base}, {given}"));
        let e = Model::from_text("arm.toml", &text, &registry(), &[])
            .err()
            .unwrap();
        let msg = format!("{e} {}", e.hint.clone().unwrap_or_default());
        assert!(msg.contains(expect), "expected `{expect}` in: {msg}");
        assert!(msg.contains("links[1]"), "{msg}");
        assert!(e.line.is_some(), "{msg}");
    }
}
