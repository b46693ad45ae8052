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
        "stress-boom-crane.png",
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

/// `--fatigue`: each hot spot's damage equals `bg-sim fatigue` on the same history, written by
/// `bg-sim run` at the hot spot's section and fibre (to 1e-12 relative), with and without
/// `--repeat-per-year`; a bad curve name is refused with status 2 and the list of presets.
#[test]
fn stress_fatigue_equals_bg_sim_fatigue_on_the_hot_spot_history() {
    let dir = tempfile::tempdir().unwrap();
    for per_year in [None, Some("2000")] {
        let mut cmd = bg_sim();
        cmd.arg("stress").arg(model("knuckle_boom")).args([
            "--t-end",
            "6",
            "--points",
            "21",
            "--format",
            "json",
            "--fatigue",
            "ec3-71",
        ]);
        if let Some(n) = per_year {
            cmd.args(["--repeat-per-year", n]);
        }
        let o = cmd.output().unwrap();
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let v: Value = serde_json::from_slice(&o.stdout).unwrap();
        for l in v["links"].as_array().unwrap() {
            let k = l["link"].as_u64().unwrap();
            let hot = &l["hot_spot"];
            let f = &hot["fatigue"];
            assert_eq!(f["curve"], "ec3-71");
            let d = f["damage"].as_f64().unwrap();
            assert!(d > 0.0);
            assert!((f["life_repeats"].as_f64().unwrap() * d - 1.0).abs() < 1e-12);
            // the grid of 21 points on 10 m and 8 m links: x is a short exact decimal
            let x = hot["x"].as_f64().unwrap();
            let fibre = f["fibre"].as_str().unwrap();
            let csv = dir.path().join(format!("hot{k}.csv"));
            let o = bg_sim()
                .arg("run")
                .arg(model("knuckle_boom"))
                .arg("-o")
                .arg(&csv)
                .args(["--t-end", "6", "--set"])
                .arg(format!("elements.crane.stress_at=[{{link={k},x={x}}}]"))
                .arg("--set")
                .arg(format!(
                    "outputs.sigma_hot=crane.link{k}.sigma_{fibre}(x={x})"
                ))
                .output()
                .unwrap();
            assert_eq!(
                o.status.code(),
                Some(0),
                "{}",
                String::from_utf8_lossy(&o.stderr)
            );
            let mut cmd = bg_sim();
            cmd.arg("fatigue").arg(&csv).args([
                "--column",
                "sigma_hot",
                "--sn",
                "ec3-71",
                "--format",
                "json",
            ]);
            if let Some(n) = per_year {
                cmd.args(["--repeat-per-year", n]);
            }
            let o = cmd.output().unwrap();
            assert_eq!(
                o.status.code(),
                Some(0),
                "{}",
                String::from_utf8_lossy(&o.stderr)
            );
            let w: Value = serde_json::from_slice(&o.stdout).unwrap();
            let want = w["damage"].as_f64().unwrap();
            assert!(((d - want) / want).abs() < 1e-12, "link {k}: {d} vs {want}");
            let (a, b) = (
                f["cycles"].as_array().unwrap(),
                w["cycles"].as_array().unwrap(),
            );
            assert_eq!(a.len(), b.len(), "link {k}");
            if per_year.is_some() {
                let years = f["life_years"].as_f64().unwrap();
                let want = w["life_years"].as_f64().unwrap();
                assert!(((years - want) / want).abs() < 1e-12);
            }
        }
    }
    let o = bg_sim()
        .arg("stress")
        .arg(model("knuckle_boom"))
        .args(["--t-end", "0.1", "--fatigue", "ec3-7"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("ec3-7`") && err.contains("ec3-71") && err.contains("dnv-d"),
        "{err}"
    );
}
