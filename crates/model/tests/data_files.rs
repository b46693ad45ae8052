//! Data files a model names (`[tables]` and `[inputs]` files): headers read by name, and
//! every refusal placed at the model's file and line with the data file named (issue 37,
//! item 8).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use bg_model::{ErrorKind, Model, ModelError, Registry};

/// A model in `dir` whose flow source reads `expr` into a capacitor, with `extra` sections.
fn model(dir: &Path, expr: &str, extra: &str) -> (String, Result<Model, ModelError>) {
    let text = format!(
        r#"{extra}
[elements]
feed = {{ kind = "Sf", f = "{expr}" }}
tank = {{ kind = "C", c = 1.0 }}
[bonds]
b1 = "feed -> tank"
"#
    );
    let path = dir.join("m.toml");
    std::fs::write(&path, &text).unwrap();
    let shown = path.display().to_string();
    (
        text.clone(),
        Model::from_text(&shown, &text, &Registry::with_core(), &[]),
    )
}

/// The flow the source delivers at t = 0 (the tank's dq/dt).
fn flow(m: &Model) -> f64 {
    let mut dx = vec![0.0; m.x0.len()];
    m.equations.rhs(0.0, &m.x0, &mut dx);
    dx[0]
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn a_table_file_is_read_by_its_header_names() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("xy.csv"), "x,y\n0,1\n1,3\n").unwrap();
    std::fs::write(dir.path().join("yx.csv"), "y,x\n1,0\n3,1\n").unwrap();
    for f in ["xy.csv", "yx.csv"] {
        let (_, m) = model(
            dir.path(),
            "tb(0.5)",
            &format!("[tables]\ntb = {{ file = \"{f}\" }}"),
        );
        let m = m.unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!((flow(&m) - 2.0).abs() < 1e-12, "{f}: {}", flow(&m));
    }
}

#[test]
fn a_table_file_without_a_header_or_with_unknown_names_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("none.csv"), "0,1\n1,2\n2,3\n").unwrap();
    std::fs::write(dir.path().join("ab.csv"), "a,b\n0,1\n1,2\n").unwrap();
    std::fs::write(dir.path().join("grid.csv"), "0,1,2\n0,1,2\n1,2,3\n").unwrap();
    for (f, want) in [
        ("none.csv", "no header"),
        ("ab.csv", "`a`"),
        ("grid.csv", "no header"),
    ] {
        let (text, m) = model(
            dir.path(),
            "tb(0.5)",
            &format!("[tables]\ntb = {{ file = \"{f}\" }}"),
        );
        let e = m.err().unwrap_or_else(|| panic!("{f} loaded"));
        assert_eq!(e.kind, ErrorKind::Table, "{f}: {e}");
        assert!(e.file.ends_with("m.toml"), "{f}: {e}");
        assert_eq!(e.line, Some(line_of(&text, "tb = ")), "{f}: {e}");
        assert!(e.message.contains(f), "{f}: {e}");
        assert!(e.message.contains(want), "{f}: {e}");
        let hint = e.hint.clone().unwrap_or_default();
        assert!(hint.contains("x,y") || hint.contains("x\\y"), "{f}: {e}");
        assert!(!e.to_string().contains("element"), "{f}: {e}");
    }
}

#[test]
fn missing_empty_or_directory_data_files_are_placed_in_the_model() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("empty.csv"), "").unwrap();
    std::fs::create_dir(dir.path().join("sub.csv")).unwrap();
    for f in ["missing.csv", "empty.csv", "sub.csv"] {
        // a table
        let (text, m) = model(
            dir.path(),
            "tb(0.5)",
            &format!("[tables]\ntb = {{ file = \"{f}\" }}"),
        );
        let e = m.err().unwrap_or_else(|| panic!("{f} loaded"));
        assert!(e.file.ends_with("m.toml"), "{f}: {e}");
        assert_eq!(e.line, Some(line_of(&text, "tb = ")), "{f}: {e}");
        assert!(e.message.contains(f), "{f}: {e}");
        assert!(e.to_string().contains("table `tb`"), "{f}: {e}");
        assert!(!e.to_string().contains("element"), "{f}: {e}");
        // an input
        let (text, m) = model(
            dir.path(),
            "pump_q",
            &format!("[inputs]\npump_q = {{ file = \"{f}\", column = \"pump_q\" }}"),
        );
        let e = m.err().unwrap_or_else(|| panic!("{f} loaded"));
        assert!(e.file.ends_with("m.toml"), "{f}: {e}");
        assert_eq!(e.line, Some(line_of(&text, "pump_q = {")), "{f}: {e}");
        assert!(e.message.contains(f), "{f}: {e}");
        assert!(e.to_string().contains("input `pump_q`"), "{f}: {e}");
        assert!(!e.to_string().contains("element"), "{f}: {e}");
        if f == "empty.csv" {
            let hint = e.hint.clone().unwrap_or_default();
            assert!(hint.contains("`t,pump_q`"), "{e}");
        }
    }
}

#[test]
fn a_byte_order_mark_before_the_header_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bom.csv"), "\u{feff}x,y\n0,1\n1,3\n").unwrap();
    std::fs::write(dir.path().join("in.csv"), "\u{feff}t,u\n0,4\n10,4\n").unwrap();
    let (_, m) = model(
        dir.path(),
        "tb(0.5)",
        "[tables]\ntb = { file = \"bom.csv\" }",
    );
    assert!((flow(&m.unwrap()) - 2.0).abs() < 1e-12);
    let (_, m) = model(
        dir.path(),
        "u",
        "[simulation]\nt_end = 1.0\n[inputs]\nu = { file = \"in.csv\", column = \"u\" }",
    );
    assert!((flow(&m.unwrap()) - 4.0).abs() < 1e-12);
}

#[test]
fn an_integer_too_large_is_refused_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let (text, m) = model(dir.path(), "1", "[simulation]\nt_end = 9223372036854775808");
    let e = m.unwrap_err();
    assert_eq!(e.line, Some(line_of(&text, "t_end")), "{e:?}");
}

#[test]
fn an_empty_inputs_file_hints_the_header_of_this_model() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    let (_, m) = model(dir.path(), "pump_q", "[inputs]\npump_q = 0.0");
    let e = m
        .unwrap()
        .set_inputs_from_csv(
            &empty,
            bondgraph::Interp::Linear,
            bg_model::Extrapolate::Error,
        )
        .unwrap_err();
    let hint = e.hint.clone().unwrap_or_default();
    assert!(hint.contains("`t,pump_q`"), "{e}");
    assert!(!hint.contains("t,F"), "{e}");
}
