//! `bg-sim stress`: the fixed JSON shape on the crane, the envelopes' consistency with each
//! other, the figures, and exit status 2 for bad input.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::Command;

use serde_json::Value;

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../models")
        .join(format!("{name}.toml"))
}

#[test]
fn stress_json_has_the_fixed_shape_and_consistent_envelopes() {
    let dir = tempfile::tempdir().unwrap();
    let o = bg_sim()
        .arg("stress")
        .arg(model("knuckle_boom"))
        .args([
            "--t-end", "2", "--points", "21", "--format", "json", "--plot",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let links = v["links"].as_array().unwrap();
    assert_eq!(links.len(), 2);
    for (k, l) in links.iter().enumerate() {
        assert_eq!(l["link"], k + 1);
        let x = l["x"].as_array().unwrap();
        assert_eq!(x.len(), 21);
        assert_eq!(x[0].as_f64(), Some(0.0));
        for q in ["N", "V", "M", "sigma_top", "sigma_bottom"] {
            let (max, min) = (
                l[q]["max"].as_array().unwrap(),
                l[q]["min"].as_array().unwrap(),
            );
            assert_eq!(max.len(), 21);
            for (a, b) in max.iter().zip(min) {
                assert!(a.as_f64().unwrap() >= b.as_f64().unwrap(), "{q}");
            }
        }
        let hot = &l["hot_spot"];
        let sigma = hot["sigma"].as_f64().unwrap();
        // the hot spot is the largest |σ| of the envelopes
        let top = ["sigma_top", "sigma_bottom"]
            .iter()
            .flat_map(|q| ["max", "min"].map(|m| (q, m)))
            .flat_map(|(q, m)| {
                l[*q][m]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap().abs())
            })
            .fold(0.0_f64, f64::max);
        assert!((sigma.abs() - top).abs() <= 1e-12 * top, "{sigma} vs {top}");
        assert!(hot["x"].as_f64().is_some() && hot["t"].as_f64().is_some());
    }
    let cyl = v["cylinders"].as_array().unwrap();
    assert_eq!(cyl.len(), 2);
    for c in cyl {
        for key in [
            "name",
            "p_max",
            "force_push_max",
            "force_pull_max",
            "buckling_margin",
        ] {
            assert!(c.get(key).is_some(), "{key}");
        }
        assert!(c["p_max"].as_f64().unwrap() > 1e6);
        // the crane's cylinders have their default rod checks (docs/fatigue.md)
        assert!(c["buckling_margin"].as_f64().unwrap() > 0.0);
    }
    for f in [
        "stress-envelope-crane-link1.png",
        "stress-hot-spot-crane-link1.png",
        "stress-envelope-crane-link2.png",
    ] {
        assert!(dir.path().join(f).metadata().unwrap().len() > 1000, "{f}");
    }
}

#[test]
fn stress_refuses_bad_input_with_status_2() {
    let o = bg_sim()
        .arg("stress")
        .arg(model("knuckle_boom"))
        .args(["--points", "1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let o = bg_sim()
        .arg("stress")
        .arg(model("knuckle_boom"))
        .args(["--link", "7"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--link 7"));
    let o = bg_sim()
        .arg("stress")
        .arg(model("mass_spring_damper"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("manipulator.planar_arm"));
}
