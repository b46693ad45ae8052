//! The `bg-sim` binary end to end: CSV output, statistics, `check`, errors and partial results.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::Command;

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../models")
        .join(format!("{name}.toml"))
}

#[test]
fn run_writes_csv_with_header_and_prints_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("msd.csv");
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .arg("-o")
        .arg(&out)
        .args(["--t-end", "2", "--dt-out", "0.5"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        stdout.contains("steps") && stdout.contains("rhs evals") && stdout.contains("wall time"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "t,x,v,F_spring");
    let times: Vec<f64> = lines[1..]
        .iter()
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 1.5, 2.0]);
    // no temporary files left behind
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn solver_and_set_options_apply() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.csv");
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .arg("-o")
        .arg(&out)
        .args([
            "--solver",
            "esdirk34",
            "--rtol",
            "1e-9",
            "--set",
            "parameters.x0=0.02",
            "--set",
            "simulation.t_end=1",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("esdirk34"), "{stdout}");
    let csv = std::fs::read_to_string(&out).unwrap();
    let first: Vec<f64> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((first[1] - 0.02).abs() < 1e-15, "x0 override: {first:?}");
    assert!(csv.lines().last().unwrap().starts_with("1,"));
    assert!(o.status.success());
}

#[test]
fn check_lists_causality_and_refuses_bad_models() {
    let o = bg_sim()
        .arg("check")
        .arg(model("dc_motor"))
        .output()
        .unwrap();
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{s}");
    assert!(
        s.contains("b5: shaft ---|> rotor") || s.contains("b5: shaft |---> rotor"),
        "{s}"
    );
    assert!(
        s.contains("rotor.p") && s.contains("no problems found"),
        "{s}"
    );

    for (name, words) in [
        (
            "derivative_causality",
            ["derivative causality", "load", "cart"],
        ),
        ("algebraic_loop", ["algebraic loop", "r1", "r2"]),
    ] {
        let o = bg_sim().arg("check").arg(model(name)).output().unwrap();
        let s = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(1), "{s}");
        for w in words {
            assert!(s.contains(w), "`{w}` missing: {s}");
        }
        assert!(s.contains("hint:"), "{s}");
        assert!(s.contains(&format!("{name}.toml:")), "file and line: {s}");
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .args(["--solver", "euler"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown solver"));
    let o = bg_sim()
        .args(["run", "does/not/exist.toml"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read"));
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .args(["--set", "parameters.c=-1"])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("mass_spring_damper.toml:") && e.contains("damper") && e.contains(">= 0"),
        "{e}"
    );
}

#[test]
fn a_failed_run_keeps_its_rows_in_a_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blowup.toml");
    std::fs::write(
        &path,
        r#"
title = "Blows up at t = 1: the source's effort is 1/(1 - t)"
[elements]
src = { kind = "Se", e = "1/(1 - t)" }
j = { kind = "1" }
r = { kind = "R", r = 1.0 }
c = { kind = "C", c = 1.0 }
[bonds]
b1 = "src -> j"
b2 = "j -> r"
b3 = "j -> c"
[simulation]
t_end = 2.0
dt_out = 0.1
"#,
    )
    .unwrap();
    let out = dir.path().join("blowup.csv");
    let o = bg_sim()
        .arg("run")
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        !out.exists(),
        "a failed run must not leave a file that looks complete"
    );
    let partial = std::fs::read_to_string(dir.path().join("blowup.partial.csv")).unwrap();
    let rows = partial.lines().count() - 1;
    assert!(
        (9..=11).contains(&rows),
        "rows up to t ≈ 1 kept, got {rows}"
    );
    assert!(
        e.contains("t = 0.9") || e.contains("t = 1"),
        "time of failure: {e}"
    );
}
