//! `bg-sim linearize`: the crane's poles are those of `bg-sim modes`; the mass–spring–damper
//! with a force input has poles −1 ± 9.95i and DC gain 1/k; Bode data and figure; bad
//! requests exit with status 2.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

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

/// models/msd_force.toml (m = 1, k = 100, c = 2, force input F, output x): poles
/// −1 ± 9.95i (√99 = 9.9499), DC gain 0.01, B = [1, 0]ᵀ, D = 0; the Bode data's magnitude
/// equals 1/|k − mω² + jcω| and a PNG is drawn.
#[test]
fn msd_force_input_poles_dc_gain_and_bode() {
    let lin = json(&[
        "linearize",
        "models/msd_force.toml",
        "--inputs",
        "F",
        "--outputs",
        "x",
        "--format",
        "json",
    ]);
    let wd = 99f64.sqrt();
    let poles = lin["poles"].as_array().unwrap();
    assert_eq!(poles.len(), 2);
    for p in poles {
        let (re, im) = (p["re"].as_f64().unwrap(), p["im"].as_f64().unwrap());
        assert!(
            (re + 1.0).abs() < 1e-12 && (im.abs() - wd).abs() < 1e-12,
            "{p}"
        );
    }
    assert!(format!("{wd:.2}") == "9.95");
    let dc = lin["dc_gain"][0][0].as_f64().unwrap();
    assert!((dc - 0.01).abs() < 1e-15, "{dc}");
    assert_eq!(lin["states"], serde_json::json!(["mass.p", "spring.q"]));
    assert_eq!(lin["B"], serde_json::json!([[1.0], [0.0]]));
    assert_eq!(lin["D"], serde_json::json!([[0.0]]));

    let dir = std::env::temp_dir().join(format!("bg-sim-linearize-{}", std::process::id()));
    let png = dir.join("bode.png");
    let out = bg_sim()
        .current_dir(root())
        .args([
            "linearize",
            "models/msd_force.toml",
            "--bode",
            "F:x",
            "--freq",
            "0.1..100",
        ])
        .args(["--points", "50", "--format", "csv", "--plot"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("f_hz,magnitude,db,phase_deg"));
    let mut n = 0;
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
        let w = 2.0 * std::f64::consts::PI * v[0];
        let want = 1.0 / (100.0 - w * w).hypot(2.0 * w);
        assert!((v[1] / want - 1.0).abs() < 1e-12, "{l}");
        assert!(v[3] <= 0.0 && v[3] >= -180.0, "{l}");
        n += 1;
    }
    assert_eq!(n, 50);
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    let _ = std::fs::remove_dir_all(&dir);
}
