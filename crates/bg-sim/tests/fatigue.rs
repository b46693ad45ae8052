//! `bg-sim fatigue` (issue 34, docs/fatigue.md): the ASTM E1049-85 example through the
//! command, the fixed JSON shape, Miner's damage of a constant-amplitude history against
//! n/N written out here, the years with `--repeat-per-year`, and bad input (exit 2, file,
//! line, hint). The comparison with an independent counter (the PyPI package `rainflow`) is
//! `crates/python/tests/test_fatigue.py`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

fn fatigue(csv: &str, extra: &[&str]) -> (Option<i32>, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.csv");
    std::fs::write(&path, csv).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("fatigue")
        .arg(&path)
        .args(extra)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn csv(values: &[f64]) -> String {
    let mut s = String::from("t,sigma\n");
    for (k, v) in values.iter().enumerate() {
        s.push_str(&format!("{},{v:e}\n", k as f64 * 0.1));
    }
    s
}

#[test]
fn the_astm_example_and_the_json_shape() {
    let h = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0];
    let (code, out, err) = fatigue(
        &csv(&h),
        &["--column", "sigma", "--sn", "ec3-71", "--format", "json"],
    );
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    assert_eq!(keys.len(), 3);
    for k in ["cycles", "damage", "life_repeats"] {
        assert!(keys.contains(&k), "{keys:?}");
    }
    let mut by_range = std::collections::BTreeMap::<u64, f64>::new();
    for c in v["cycles"].as_array().unwrap() {
        let o = c.as_object().unwrap();
        assert_eq!(o.len(), 3, "{c}");
        let r = o["range"].as_f64().unwrap();
        assert!(o["mean"].is_number());
        *by_range.entry(r.to_bits()).or_default() += o["count"].as_f64().unwrap();
    }
    let got: Vec<(f64, f64)> = by_range
        .into_iter()
        .map(|(r, c)| (f64::from_bits(r), c))
        .collect();
    // ASTM E1049-85's rainflow table: range 3 ×½, 4 ×1½, 6 ×½, 8 ×1, 9 ×½
    assert_eq!(
        got,
        [(3.0, 0.5), (4.0, 1.5), (6.0, 0.5), (8.0, 1.0), (9.0, 0.5)]
    );
    // ranges of a few Pa are far below any cut-off: no damage, no finite life
    assert!(v["damage"].as_f64().unwrap().abs() < f64::MIN_POSITIVE);
    assert!(v["life_repeats"].is_null());
}

#[test]
fn constant_amplitude_damage_is_n_over_n_and_years_follow() {
    // 500 cycles of ±60 MPa: range 120 MPa on ec3-90 (above the knee): N = 2e6 (90/120)³
    let h: Vec<f64> = (0..=1000)
        .map(|k| if k % 2 == 0 { -60e6 } else { 60e6 })
        .collect();
    let args = [
        "--column",
        "sigma",
        "--sn",
        "ec3-90",
        "--format",
        "json",
        "--repeat-per-year",
        "400",
    ];
    let (code, out, err) = fatigue(&csv(&h), &args);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let n = 2e6 * (90.0_f64 / 120.0).powi(3);
    let want = 500.0 / n;
    let d = v["damage"].as_f64().unwrap();
    assert!(((d - want) / want).abs() < 1e-12, "{d} vs {want}");
    let years = v["life_years"].as_f64().unwrap();
    assert!((years * 400.0 * want - 1.0).abs() < 1e-12);
    // the SCF multiplies the range: 1.5 × 120 MPa
    let (_, out, _) = fatigue(&csv(&h), &[&args[..], &["--scf", "1.5"]].concat());
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let want = 500.0 / (2e6 * (90.0_f64 / 180.0).powi(3));
    let d = v["damage"].as_f64().unwrap();
    assert!(((d - want) / want).abs() < 1e-12, "{d} vs {want}");
}

#[test]
fn bad_input_exits_2_naming_the_file_line_and_a_fix() {
    let text = "t,sigma\n0,1\n\n0.1,NaN\n0.2,3\n";
    for (extra, words) in [
        (
            &["--column", "sigma", "--sn", "ec3-71"][..],
            &["run.csv:4", "NaN", "hint"][..],
        ),
        (
            &["--column", "sigm", "--sn", "ec3-71"][..],
            &["run.csv:1", "did you mean `sigma`"][..],
        ),
        (
            &["--column", "sigma", "--sn", "ec3-72"][..],
            &["unknown S–N curve", "ec3-71", "dnv-w3"][..],
        ),
        (
            &["--column", "sigma", "--sn", "m=3,range=71e6"][..],
            &["lacks", "hint"][..],
        ),
        (
            &["--column", "sigma", "--sn", "ec3-71", "--scf", "0"][..],
            &["--scf", "hint"][..],
        ),
    ] {
        let (code, out, err) = fatigue(text, extra);
        assert_eq!(code, Some(2), "{extra:?}: {out}{err}");
        for w in words {
            assert!(err.contains(w), "{extra:?}: `{w}` not in {err}");
        }
    }
}
