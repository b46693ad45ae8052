//! `bg-sim sensitivity`: the CSV's `dy/dp` columns agree with the closed form of the
//! mass–spring–damper's dx/dx0 (= x/x0, the equations being linear in x0); the JSON ranking;
//! an unknown parameter or output exits with status 2 and a "did you mean".
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::Command;

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn sensitivity_csv_and_json_of_the_mass_spring_damper() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("S.csv");
    let png = dir.path().join("S.png");
    let out = bg_sim()
        .current_dir(root())
        .args([
            "sensitivity",
            "models/mass_spring_damper.toml",
            "--params",
            "x0,k",
        ])
        .args([
            "--outputs",
            "x",
            "--t-end",
            "3",
            "--rtol",
            "1e-9",
            "--format",
            "json",
        ])
        .arg("-o")
        .arg(&csv)
        .arg("--plot")
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["params"], serde_json::json!(["x0", "k"]));
    // normalised by x0/max|x| = 1: dx/dx0·x0/max|x| has a maximum of exactly 1 (at t = 0)
    let r = v["ranking"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["param"] == "x0")
        .unwrap();
    assert!((r["max"].as_f64().unwrap() - 1.0).abs() < 1e-6, "{r}");
    assert!(png.exists());
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "t,dx/dx0,dx/dk");
    // dx/dx0 = x(t)/x0 for this linear model: the closed form with x0 = 1
    let (k, c, m) = (10.0f64, 0.5, 1.0);
    let wn = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    for line in lines {
        let f: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        let t = f[0];
        let exact = (-zeta * wn * t).exp() * ((wd * t).cos() + zeta * wn / wd * (wd * t).sin());
        assert!((f[1] - exact).abs() < 1e-5, "t = {t}: {} vs {exact}", f[1]);
    }
}

#[test]
fn sensitivity_bad_names_exit_2_with_a_suggestion() {
    let run = |args: &[&str]| {
        let out = bg_sim()
            .current_dir(root())
            .args(["sensitivity", "models/mass_spring_damper.toml"])
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, err) = run(&["--params", "kk"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("did you mean `k`"), "{err}");
    assert!(err.contains("mass_spring_damper.toml"), "{err}");
    let (code, err) = run(&["--params", "k", "--outputs", "xx"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("did you mean `x`"), "{err}");
    let (code, err) = run(&["--params", "elements.damper.rr"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("elements.damper.r"), "{err}");
}
