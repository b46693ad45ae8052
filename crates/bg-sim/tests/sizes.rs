//! What is dense refuses a model too large for it, before any work, with a message that
//! names the file, the state count, the limit and what to do (exit 2); a bad
//! `simulation.linear_algebra` is an error at its file, line and key, with a hint.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The pipe of docs/performance.md in `n` segments (scripts/pipe-model.sh), with `extra`
/// appended, written into `dir`.
fn pipe(dir: &Path, n: usize, extra: &str) -> PathBuf {
    let o = Command::new("bash")
        .arg(root().join("scripts/pipe-model.sh"))
        .arg(n.to_string())
        .output()
        .unwrap();
    assert!(o.status.success());
    let path = dir.join(format!("pipe{n}.toml"));
    let text = String::from_utf8(o.stdout).unwrap() + extra;
    std::fs::write(&path, text).unwrap();
    path
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn modes_refuses_a_model_above_its_limit_and_takes_one_below() {
    let dir = tempfile::tempdir().unwrap();
    // 150 segments: 302 states, two above the limit of 300
    let big = pipe(dir.path(), 150, "");
    let o = bg_sim().arg("modes").arg(&big).output().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for w in [
        "pipe150.toml",
        "302 states",
        "more than the 300",
        "dense",
        "hint:",
        "linearize",
    ] {
        assert!(err.contains(w), "`{w}` missing: {err}");
    }
    // 10 segments: analysed
    let small = pipe(dir.path(), 10, "");
    let o = bg_sim().arg("modes").arg(&small).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_steady_start_with_too_many_unknowns_is_refused_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    // 300 segments: every pressure and flow of the line: 600 unknowns, above 500
    let path = pipe(
        dir.path(),
        300,
        "\n[initial.steady]\nunknowns = [\"line.p[*]\", \"line.q[*]\"]\nconditions = [\"vol.p.dot = 0\"]\n",
    );
    let o = bg_sim().arg("check").arg(&path).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout).into_owned() + &stderr(&o);
    assert_ne!(o.status.code(), Some(0), "{out}");
    for w in [
        "pipe300.toml:",
        "[initial.steady]",
        "600 unknowns",
        "more than the 500",
        "hint:",
    ] {
        assert!(out.contains(w), "`{w}` missing: {out}");
    }
    let o = bg_sim()
        .arg("run")
        .arg(&path)
        .arg("-o")
        .arg(dir.path().join("out.csv"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("600 unknowns"), "{}", stderr(&o));
}

#[test]
fn a_bad_linear_algebra_is_an_error_at_its_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let path = pipe(dir.path(), 10, "").to_string_lossy().into_owned();
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text.replace("linear_algebra = \"auto\"", "linear_algebra = \"fastest\"");
    std::fs::write(&path, &text).unwrap();
    let line = text.lines().position(|l| l.contains("fastest")).unwrap() + 1;
    let o = bg_sim()
        .arg("run")
        .arg(&path)
        .arg("-o")
        .arg(dir.path().join("out.csv"))
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for w in [
        format!("pipe10.toml:{line}"),
        "linear_algebra".into(),
        "`fastest`".into(),
        "hint:".into(),
        "\"dense\", \"sparse\" or \"auto\"".into(),
    ] {
        assert!(err.contains(&w), "`{w}` missing: {err}");
    }
    assert!(!dir.path().join("out.csv").exists());
    // the same through `--set`
    let o = bg_sim()
        .arg("run")
        .arg(&path)
        .args(["--set", "simulation.linear_algebra=\"Dense!\""])
        .arg("-o")
        .arg(dir.path().join("out.csv"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("`Dense!`"), "{}", stderr(&o));
}

#[test]
fn linearize_refuses_a_model_above_its_limit_and_summarises_a_large_one() {
    let dir = tempfile::tempdir().unwrap();
    // 1 000 segments: 2 002 states, two above the limit of 2 000: refused before any work
    let big = pipe(dir.path(), 1000, "");
    let o = bg_sim()
        .args(["linearize", "--outputs", "vol.p"])
        .arg(&big)
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for w in [
        "pipe1000.toml",
        "2002 states",
        "more than the 2000",
        "dense",
        "hint:",
    ] {
        assert!(err.contains(w), "`{w}` missing: {err}");
    }
    // 160 segments (322 states): A, B, C, D and the DC gain, the poles left out with a note,
    // the matrices summarised in the text
    let mid = pipe(dir.path(), 160, "");
    let o = bg_sim()
        .args(["linearize", "--outputs", "vol.p,line.p[1]"])
        .arg(&mid)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(o.status.success(), "{}", stderr(&o));
    for w in [
        "322 states",
        "A = ∂f/∂x (322×322):",
        "nonzero entries, too many rows or columns to print",
        "poles: not computed: 322 states, more than the 300",
        "writes A for an eigen-solver of your own",
    ] {
        assert!(out.contains(w), "`{w}` missing: {out}");
    }
    let o = bg_sim()
        .args(["linearize", "--outputs", "vol.p", "--format", "json"])
        .arg(&mid)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["poles"].is_null());
    assert!(v["poles_note"].as_str().unwrap().contains("322 states"));
    assert_eq!(v["A"].as_array().unwrap().len(), 322);
    // a frequency response is refused above its own limit, before any work
    let o = bg_sim()
        .args(["linearize", "--outputs", "vol.p", "--bode", "x:vol.p"])
        .arg(&mid)
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for w in [
        "pipe160.toml",
        "--bode",
        "322 states",
        "more than the 300",
        "hint:",
    ] {
        assert!(err.contains(w), "`{w}` missing: {err}");
    }
}
