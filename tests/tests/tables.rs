//! `[tables]` and `[inputs]` through the loader: a model with tables runs, its Jacobian
//! carries the tables' exact slopes (covered for every model by tests/jacobian.rs; here the
//! valve's resistance against a hand-written derivative), and bad tables and inputs are
//! clean errors at their line naming the table or input and the entry.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use bg_model::{ErrorKind, Model};
use bondgraph::DMatrix;

fn load(text: &str) -> Result<Model, bg_model::ModelError> {
    Model::from_text("t.toml", text, &bg_sim::registry(), &[])
}

const BASE: &str = r#"
[tables]
r_of_p = { x = [0, 1, 2, 4], y = [8.0, 6.0, 5.0, 4.0], interp = "cubic", extrapolate = "linear" }
[elements]
tank  = { kind = "C", c = 1.0, q0 = 1.5 }
valve = { kind = "R", r = "r_of_p(tank.e)" }
[bonds]
b1 = "tank -> valve"
[simulation]
t_end = 1.0
"#;

/// dq/dt = −p/r(p) with p = q/c (c = 1): ∂f/∂q = −1/r + p·r'(p)/r², r' from the table.
#[test]
fn the_jacobian_carries_the_tables_exact_slope() {
    let m = load(BASE).unwrap();
    let eqs = &m.equations;
    for q in [0.3, 1.5, 2.7, 5.0] {
        let mut j = DMatrix::zeros(1, 1);
        eqs.jacobian(0.0, &[q], &mut j);
        // central difference of the rhs with a small step: the table is C¹
        let h = 1e-6;
        let (mut fp, mut fm) = ([0.0], [0.0]);
        eqs.rhs(0.0, &[q + h], &mut fp);
        eqs.rhs(0.0, &[q - h], &mut fm);
        let fd = (fp[0] - fm[0]) / (2.0 * h);
        assert!(
            (j[(0, 0)] - fd).abs() < 1e-8 * fd.abs().max(1.0),
            "q = {q}: J = {} vs {fd}",
            j[(0, 0)]
        );
    }
}

#[test]
fn bad_tables_are_errors_naming_the_table_and_the_entry() {
    let cases = [
        (
            "x = [0, 1, 2, 4]",
            "x = [0, 2, 1, 4]",
            "x[2] = 1 is not after x[1] = 2",
        ),
        (
            "y = [8.0, 6.0, 5.0, 4.0]",
            "y = [8.0, 6.0, 5.0]",
            "`x` has 4 entries and `y` 3",
        ),
        (
            "y = [8.0, 6.0, 5.0, 4.0]",
            "y = [8.0, \"nan\", 5.0, 4.0]",
            "y[1] = NaN is not finite",
        ),
        (
            "interp = \"cubic\"",
            "interp = \"spline\"",
            "`interp` = `spline`",
        ),
        (
            "extrapolate = \"linear\"",
            "extrapolat = \"linear\"",
            "did you mean `extrapolate`",
        ),
    ];
    for (from, to, want) in cases {
        let text = BASE.replace(from, to);
        let e = load(&text).unwrap_err();
        assert_eq!(e.kind, ErrorKind::Table, "{to}: {e}");
        assert_eq!(e.line, Some(3), "{to}: {e}");
        assert!(e.message.contains("table `r_of_p`"), "{e}");
        assert!(e.to_string().contains(want), "{to}: {e}");
    }
    let grid = BASE.replace(
        "r_of_p = {",
        "eta = { x = [0, 1], y = [0, 1, 2], z = [[1, 2, 3], [4, 5]] }\nr_of_p = {",
    );
    let e = load(&grid).unwrap_err();
    assert!(
        e.message.contains("row z[1] has 2 entries and `y` 3"),
        "{e}"
    );
    // a table called with the wrong number of arguments is refused at its element
    let e = load(&BASE.replace("r_of_p(tank.e)", "r_of_p(tank.e, t)")).unwrap_err();
    assert!(
        e.to_string()
            .contains("`r_of_p` takes 1 argument(s), got 2"),
        "{e}"
    );
}

#[test]
fn bad_inputs_are_errors_at_their_line() {
    let base = BASE.replace(
        "[elements]",
        "[inputs]\nF = { default = 1.0, unit = \"N\" }\n[elements]",
    );
    assert_eq!(load(&base).unwrap().inputs()[0].name, "F");
    let cases = [
        (
            "F = { default = 1.0, unit = \"N\" }",
            "F = { defaul = 1.0 }",
            "did you mean `default`",
        ),
        (
            "F = { default = 1.0, unit = \"N\" }",
            "tank = 1.0",
            "both an element and an input",
        ),
        (
            "F = { default = 1.0, unit = \"N\" }",
            "t = 1.0",
            "cannot be an input name",
        ),
        (
            "F = { default = 1.0, unit = \"N\" }",
            "F = { column = \"F\" }",
            "no `file`",
        ),
        (
            "F = { default = 1.0, unit = \"N\" }",
            "F = { file = \"missing.csv\" }",
            "cannot read",
        ),
    ];
    for (from, to, want) in cases {
        let e = load(&base.replace(from, to)).unwrap_err();
        assert!(e.to_string().contains(want), "{to}: {e}");
    }
}

/// An input read by an expression and by a signal port: set it and the rhs follows.
#[test]
fn an_input_drives_expressions_and_signal_ports() {
    let text = r#"
[inputs]
u = 2.0
[elements]
tank  = { kind = "C", c = 1.0, q0 = 0.0 }
feed  = { kind = "Sf", f = "3*u" }
lag   = { kind = "lag", input = "u", tau = 0.5 }
[bonds]
b1 = "feed -> tank"
"#;
    let m = load(text).unwrap();
    let eqs = &m.equations;
    let x = m.x0.clone();
    let mut dx = vec![0.0; x.len()];
    eqs.rhs(0.0, &x, &mut dx);
    let q = eqs
        .states()
        .iter()
        .position(|s| s.name == "tank.q")
        .unwrap();
    let y = eqs.states().iter().position(|s| s.name == "lag.y").unwrap();
    assert_eq!((dx[q], dx[y]), (6.0, 4.0));
    eqs.set_input_by_name("u", -1.0).unwrap();
    eqs.rhs(0.0, &x, &mut dx);
    assert_eq!((dx[q], dx[y]), (-3.0, -2.0));
}

/// `[inputs] F = { file = …, column = … }`: the data drive the run; data that end before
/// `t_end` are refused naming that end, unless `extrapolate = "hold"`.
#[test]
fn an_input_from_a_data_file_named_in_the_model() {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/msd_force_step.csv");
    let text = format!(
        r#"
[inputs]
F = {{ file = "{data}", column = "F", interp = "hold" }}
[elements]
force  = {{ kind = "Se", e = "F" }}
v      = {{ kind = "1" }}
mass   = {{ kind = "I", m = 1.0 }}
spring = {{ kind = "C", k = 100.0 }}
damper = {{ kind = "R", r = 2.0 }}
[bonds]
b0 = "force -> v"
b1 = "v -> mass"
b2 = "v -> spring"
b3 = "v -> damper"
[simulation]
t_end = 20.0
dt_out = 0.1
rtol = 1e-10
atol = 1e-13
[outputs]
x = "spring.q"
"#
    );
    let mut m = load(&text).unwrap();
    assert_eq!(m.equations.input_breakpoints(0).unwrap(), [0.0, 1.0, 20.0]);
    let out = m.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    let x = out.trajectory.column("x").unwrap();
    assert!((x.last().unwrap() - 0.1).abs() < 1e-6);
    let long = text.replace("t_end = 20.0", "t_end = 30.0");
    let e = load(&long).unwrap_err();
    assert!(
        e.message.contains("before the run's end t_end = 30 s"),
        "{e}"
    );
    assert_eq!(e.line, Some(4), "{e}");
    let held = long.replace(
        "interp = \"hold\"",
        "interp = \"hold\", extrapolate = \"hold\"",
    );
    assert!(load(&held).is_ok());
}
