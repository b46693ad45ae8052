//! `check --format json` and `run --format json`: stdout is one JSON document with the
//! problems (file, line, column, element, kind, message, hint) and, for `run`, the run's
//! outcome and statistics.
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

/// Run `bg-sim` and parse its stdout as JSON.
fn json(args: &[&std::ffi::OsStr]) -> (i32, Value) {
    let o = bg_sim().args(args).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let v: Value = serde_json::from_str(&stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not JSON ({e}):\n{stdout}\nstderr:\n{}",
            String::from_utf8_lossy(&o.stderr)
        )
    });
    (o.status.code().unwrap_or(-1), v)
}

#[test]
fn check_json_lists_the_problem_with_its_line_and_hint() {
    let bad = model("algebraic_loop");
    let (code, v) = json(&[
        "check".as_ref(),
        bad.as_os_str(),
        "--format".as_ref(),
        "json".as_ref(),
    ]);
    assert_eq!(code, 2, "{v:#}");
    assert_eq!(v["ok"], false);
    let problems = v["problems"].as_array().unwrap();
    assert_eq!(problems.len(), 1, "{v:#}");
    let p = &problems[0];
    // the loop is reported at its first resistor, `r1` on line 13 of the model file
    assert_eq!(p["line"], 13, "{p:#}");
    assert_eq!(p["column"], 1, "{p:#}");
    assert_eq!(p["element"], "r1", "{p:#}");
    assert_eq!(p["kind"], "causality", "{p:#}");
    assert!(
        p["message"].as_str().unwrap().contains("algebraic loop"),
        "{p:#}"
    );
    assert!(p["hint"].as_str().unwrap().contains("inertia"), "{p:#}");
    assert!(p["file"].as_str().unwrap().ends_with("algebraic_loop.toml"));
}

#[test]
fn check_json_on_a_good_model_lists_no_problem_and_exits_0() {
    let good = model("mass_spring_damper");
    let (code, v) = json(&[
        "check".as_ref(),
        good.as_os_str(),
        "--format".as_ref(),
        "json".as_ref(),
    ]);
    assert_eq!(code, 0, "{v:#}");
    assert_eq!(v["ok"], true);
    assert_eq!(v["problems"].as_array().unwrap().len(), 0);
    assert!(!v["elements"].as_array().unwrap().is_empty());
    assert!(!v["states"].as_array().unwrap().is_empty());
}

#[test]
fn run_json_has_the_outcome_and_the_step_count() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("msd.csv");
    let m = model("mass_spring_damper");
    let (code, v) = json(&[
        "run".as_ref(),
        m.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--t-end".as_ref(),
        "2".as_ref(),
        "--format".as_ref(),
        "json".as_ref(),
    ]);
    assert_eq!(code, 0, "{v:#}");
    assert_eq!(v["outcome"], "complete", "{v:#}");
    let steps = v["statistics"]["steps"].as_u64().unwrap();
    assert!(steps > 0, "{v:#}");
    assert!(v["statistics"]["rhs"].as_u64().unwrap() >= steps);
    assert!(v["statistics"]["wall_s"].as_f64().unwrap() >= 0.0);
    // the rows in the file are the rows reported
    let rows = std::fs::read_to_string(&out).unwrap().lines().count() - 1;
    assert_eq!(v["rows"].as_u64().unwrap(), rows as u64);
    assert_eq!(v["results"].as_str().unwrap(), out.display().to_string());
}

#[test]
fn run_json_on_a_bad_model_is_refused_with_its_problems() {
    let bad = model("algebraic_loop");
    let (code, v) = json(&[
        "run".as_ref(),
        bad.as_os_str(),
        "--format".as_ref(),
        "json".as_ref(),
    ]);
    assert_eq!(code, 2, "{v:#}");
    assert_eq!(v["outcome"], "refused");
    assert!(v["statistics"].is_null());
    assert_eq!(v["problems"][0]["line"], 13, "{v:#}");
}

#[test]
fn check_json_lists_every_problem_of_a_file_with_two_independent_mistakes() {
    // a misspelt parameter in one element and an out-of-range value in another
    let text = std::fs::read_to_string(model("mass_spring_damper")).unwrap();
    let text = text
        .replacen("kind = \"R\", r = ", "kind = \"R\", rr = ", 1)
        .replacen("kind = \"I\", m = \"m\"", "kind = \"I\", m = -2.0", 1);
    let dir = std::env::temp_dir().join(format!("bg-sim-json-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("two_mistakes.toml");
    std::fs::write(&path, &text).unwrap();
    let (code, v) = json(&[
        "check".as_ref(),
        path.as_os_str(),
        "--format".as_ref(),
        "json".as_ref(),
    ]);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(code, 2, "{v:#}");
    let problems = v["problems"].as_array().unwrap();
    assert_eq!(problems.len(), 2, "{v:#}");
    let by_element = |e: &str| {
        problems
            .iter()
            .find(|p| p["element"] == e)
            .unwrap_or_else(|| panic!("no problem for `{e}`: {v:#}"))
    };
    let (damper, mass) = (by_element("damper"), by_element("mass"));
    assert_eq!(damper["kind"], "extra_parameter", "{damper:#}");
    assert!(
        damper["message"].as_str().unwrap().contains("`rr`"),
        "{damper:#}"
    );
    assert!(
        damper["hint"]
            .as_str()
            .unwrap()
            .contains("did you mean `r`"),
        "{damper:#}"
    );
    assert_eq!(mass["kind"], "bad_parameter", "{mass:#}");
    assert!(
        mass["message"].as_str().unwrap().contains("> 0"),
        "{mass:#}"
    );
    for p in [damper, mass] {
        assert!(p["line"].as_u64().is_some_and(|l| l > 1), "{p:#}");
        assert!(p["hint"].is_string(), "{p:#}");
    }
    assert_ne!(damper["line"], mass["line"]);
    // `run --format json` refuses the same file with the same two problems
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&path, &text).unwrap();
    let out = dir.join("out.csv");
    let (code, v) = json(&[
        "run".as_ref(),
        path.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--format".as_ref(),
        "json".as_ref(),
    ]);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(code, 2, "{v:#}");
    assert_eq!(v["outcome"], "refused", "{v:#}");
    assert_eq!(v["problems"].as_array().unwrap().len(), 2, "{v:#}");
}
