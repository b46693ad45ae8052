//! `bg-sim run --inputs`: the mass–spring–damper driven by a CSV step of 10 N ends at the
//! static deflection and matches the same step written in the model; bad data are clean
//! errors (file, line, column, hint) with exit status 2; `check` lists the inputs.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read_csv(p: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let head = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

fn run(args: &[&str], out: &Path) -> std::process::Output {
    bg_sim()
        .arg("run")
        .arg(root().join("models/msd_force.toml"))
        .arg("-o")
        .arg(out)
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn a_csv_step_ends_at_f_over_k_and_matches_the_step_written_in_the_model() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = (dir.path().join("data.csv"), dir.path().join("model.csv"));
    let step = root().join("data/msd_force_step.csv");
    let o = run(
        &[
            "--inputs",
            step.to_str().unwrap(),
            "--inputs-interp",
            "hold",
        ],
        &data,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(&["--set", "parameters.F_step=10"], &model);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (head, a) = read_csv(&data);
    let (_, b) = read_csv(&model);
    let x = head.iter().position(|h| h == "x").unwrap();
    let f = head.iter().position(|h| h == "F").unwrap();
    let end = a.last().unwrap();
    assert!((end[x] - 0.1).abs() < 1e-6, "x(20) = {}", end[x]);
    assert_eq!(end[f], 10.0);
    assert_eq!(a.len(), b.len());
    let mut worst = 0.0_f64;
    for (ra, rb) in a.iter().zip(&b) {
        // the data run's column F is the input, the model run's F stays 0: compare x and v
        for k in [0, x, x + 1] {
            worst = worst.max((ra[k] - rb[k]).abs());
        }
    }
    assert!(worst <= 1e-9, "the two runs differ by {worst:e}");
}

#[test]
fn bad_data_are_clean_errors_with_exit_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.csv");
    let cases: [(&str, &str, &[&str]); 6] = [
        (
            "t,F\n0,0\n1,x\n20,1\n",
            "bad.csv:3:",
            &["not a number", "column"],
        ),
        ("t,F\n0,0\n1,1\n1,2\n20,1\n", "bad.csv:4:", &["repeats"]),
        ("t,F\n0,0\n2,1\n1,2\n20,1\n", "bad.csv:4:", &["is before"]),
        ("t,f\n0,0\n20,1\n", "bad.csv:1:", &["did you mean `F`"]),
        (
            "t,F\n0,0\n5,1\n",
            "bad.csv:3:",
            &["before the run's end", "extrapolate"],
        ),
        ("t,F\n1,0\n20,1\n", "bad.csv:2:", &["after the run's start"]),
    ];
    for (text, line, words) in cases {
        let data = dir.path().join("bad.csv");
        std::fs::write(&data, text).unwrap();
        let o = run(&["--inputs", data.to_str().unwrap()], &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{text:?}: {err}");
        assert!(err.contains("bad.csv"), "{err}");
        assert!(err.contains(line), "{text:?}: {err}");
        for w in words {
            assert!(err.contains(w), "{text:?}: no `{w}` in {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
    }
    // the end not covered is fine when asked to hold
    let data = dir.path().join("short.csv");
    std::fs::write(&data, "t,F\n0,0\n5,1\n").unwrap();
    let o = run(
        &[
            "--inputs",
            data.to_str().unwrap(),
            "--inputs-extrapolate",
            "hold",
        ],
        &out,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn check_lists_the_inputs() {
    let o = bg_sim()
        .arg("check")
        .arg(root().join("models/msd_force.toml"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("inputs (1):"), "{text}");
    assert!(text.contains("default 0 N"), "{text}");
    assert!(text.contains("external force on the mass"), "{text}");
}
