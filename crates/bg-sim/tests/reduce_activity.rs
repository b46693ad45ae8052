//! `bg-sim reduce --by activity` (issue 26 items 3–4): the activity ranking against a hand
//! calculation, a kind augmented with one declared simplification used by the reducer, the
//! lift circuit reduced within the tolerance, every simplification the kinds declare loading
//! and running on a model, and bad options.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

use bg_model::Model;
use bg_sim::reduce::ReduceOptions;
use bg_sim::simplify::{apply, candidates, energy_audit, reduce_by_activity, Candidate};
use bondgraph::kind::{Change, KindDecl, Simplification};

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../models")
        .join(format!("{name}.toml"))
}

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

/// A force e0 drives a mass m from rest against a damper r1 and a seal r2 in series (one
/// 1-junction): v(t) = (e0/R)(1 − e^(−Rt/m)), R = r1 + r2.
const DRIVEN_MASS: &str = r#"
title = "A mass driven by a constant force against a damper and a seal"
[parameters]
e0 = 10.0
m = 1.0
r1 = 2.0
r2 = 0.01
[elements]
force = { kind = "Se", e = "e0" }
j = { kind = "1" }
mass = { kind = "I", m = "m" }
damper = { kind = "R", r = "r1" }
seal = { kind = "R", r = "r2" }
[bonds]
b_f = "force -> j"
b_m = "j -> mass"
b_d = "j -> damper"
b_s = "j -> seal"
[simulation]
t_end = 5.0
dt_out = 0.01
rtol = 1e-10
atol = 1e-12
[outputs]
v = "mass.f"
"#;

fn write_model(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("driven_mass.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// The activities by hand, with a = R·T/m:
///   ∫v dt  = (e0/R)·(T − (m/R)(1 − e^(−a)))
///   ∫v² dt = (e0/R)²·(T − 2(m/R)(1 − e^(−a)) + (m/2R)(1 − e^(−2a)))
///   A_force = e0·∫v, A_r = r·∫v², A_mass = ½·m·v(T)² (v rises monotonically), and
///   A_force = A_r1 + A_r2 + A_mass (the balance), so the total is 2·A_force.
#[test]
fn the_ranking_is_the_hand_calculation() {
    let (e0, m, r1, r2, t): (f64, f64, f64, f64, f64) = (10.0, 1.0, 2.0, 0.01, 5.0);
    let r = r1 + r2;
    let a = r * t / m;
    let int_v = e0 / r * (t - m / r * (1.0 - (-a).exp()));
    let int_v2 = (e0 / r).powi(2)
        * (t - 2.0 * m / r * (1.0 - (-a).exp()) + m / (2.0 * r) * (1.0 - (-2.0 * a).exp()));
    let v_end = e0 / r * (1.0 - (-a).exp());
    let total = 2.0 * e0 * int_v;
    let expected = [
        ("force", e0 * int_v / total),
        ("damper", r1 * int_v2 / total),
        ("mass", 0.5 * m * v_end * v_end / total),
        ("seal", r2 * int_v2 / total),
    ];
    let mut mdl =
        Model::from_text("driven_mass.toml", DRIVEN_MASS, &bg_sim::registry(), &[]).unwrap();
    let (out, mut ranking) = energy_audit(&mut mdl).unwrap();
    assert!(out.error.is_none());
    assert_eq!(out.trajectory.rows.len(), 501, "the rows are kept");
    ranking.sort_by(|a, b| b.share.total_cmp(&a.share));
    let ranked: Vec<&str> = ranking
        .iter()
        .filter(|e| e.share > 0.0)
        .map(|e| e.name.as_str())
        .collect();
    assert_eq!(ranked, ["force", "damper", "mass", "seal"]);
    for (name, share) in expected {
        let got = ranking.iter().find(|e| e.name == name).unwrap();
        assert!(
            (got.share / share - 1.0).abs() < 1e-6,
            "{name}: share {} against {share} by hand",
            got.share
        );
        assert_eq!(got.composite, name);
    }
}

/// The seal's resistance removed (r = 0): declared by an augmented `R` kind only.
const SEAL_REMOVED: &[Simplification] = &[Simplification::new(
    "removed",
    "no resistance: r = 0",
    &[Change::Set("r", "0")],
)];

#[test]
fn a_kind_augmented_with_a_simplification_is_used_by_the_reducer() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_model(dir.path(), DRIVEN_MASS);
    let mut o = ReduceOptions::new(1e-2);
    o.columns = Some(vec!["v".into()]);
    o.repeat = 1;
    // as registered, R declares nothing: nothing to try
    let plain = bg_sim::registry();
    assert!(plain.get("R").unwrap().simplifications.is_empty());
    let r = reduce_by_activity(&path, &plain, &o, 1e-2, &energy_audit).unwrap();
    assert!(r.candidates.is_empty());
    assert_eq!((r.trials.len(), r.answer), (1, 0));
    // augmented: the seal (share 2.5e-3) is simplified; the damper (share 0.48) is not
    let mut reg = bg_sim::registry();
    let base = *reg.get("R").unwrap();
    reg.register(KindDecl {
        simplifications: SEAL_REMOVED,
        ..base
    });
    let r = reduce_by_activity(&path, &reg, &o, 1e-2, &energy_audit).unwrap();
    let labels: Vec<String> = r.candidates.iter().map(Candidate::label).collect();
    assert_eq!(labels, ["seal: removed", "damper: removed"]);
    assert_eq!(r.proposed(), 1);
    assert_eq!(r.answer, 1, "{}", r.table());
    let applied: Vec<String> = r.applied().iter().map(|c| c.label()).collect();
    assert_eq!(applied, ["seal: removed"]);
    // the speed rises by r2/R = 0.5 %: the scaled error of v is about that
    let (col, err) = r.answer().worst().unwrap();
    assert_eq!(col, "v");
    assert!((4e-3..6e-3).contains(&err), "{err:e}");
    // at 1e-3 the removal is refused and the full model is the answer
    o.tol = 1e-3;
    let r = reduce_by_activity(&path, &reg, &o, 1e-2, &energy_audit).unwrap();
    assert_eq!(r.answer, 0, "{}", r.table());
    assert!(!r.trials[1].passes(1e-3));
}

/// The lift circuit within 1 % on stroke, speed and both cylinder pressures: the relief
/// valve's seat leak (share 7e-6) is removed; the 4/3 valve's and the counterbalance valve's
/// leaks are inside elements whose share is 7 % and 15 %, so they stay.
#[test]
fn the_lift_circuit_reduced_by_activity_stays_within_tol() {
    let mut o = ReduceOptions::new(1e-2);
    o.columns = Some(vec!["s".into(), "v".into(), "p_p".into(), "p_b".into()]);
    o.repeat = 1;
    let r = reduce_by_activity(
        &model("lift_circuit"),
        &bg_sim::registry(),
        &o,
        1e-2,
        &energy_audit,
    )
    .unwrap();
    assert!(r.answer > 0, "{}", r.table());
    let a = r.answer();
    assert!(a.passes(1e-2));
    assert_eq!(a.errors.len(), 4);
    let applied: Vec<String> = r.applied().iter().map(|c| c.label()).collect();
    assert_eq!(applied, ["relief: no_seat_leak"], "{}", r.table());
    for c in &r.candidates {
        assert_eq!(
            c.share < 1e-2,
            c.instance == "relief",
            "{}: {}",
            c.label(),
            c.share
        );
    }
    // the ranking: gravity and the pump lead, the relief valve (shut all run) is last
    assert_eq!(r.ranking[0].name, "gravity");
    assert_eq!(r.ranking[1].name, "pump");
    let total: f64 = r.ranking.iter().map(|e| e.share).sum();
    assert!((total - 1.0).abs() < 1e-9, "{total}");
    assert!(r.speedup() > 0.0 && r.step_ratio() > 0.0);
}

/// Every simplification a registered kind declares, applied alone to a model that has the
/// kind (with `--set` making it applicable where the file lacks the key): the reduced
/// model loads and runs. A new declaration must add its line here.
#[test]
fn every_declared_simplification_loads_and_runs() {
    // (kind, simplification, model, --set, element, end time)
    type Case<'a> = (&'a str, &'a str, &'a str, &'a [&'a str], &'a str, f64);
    let cases: &[Case] = &[
        (
            "hydraulics.relief_valve",
            "no_seat_leak",
            "lift_circuit",
            &[],
            "relief",
            2.0,
        ),
        (
            "hydraulics.relief_valve",
            "static_poppet",
            "lift_circuit",
            &["elements.relief.tau=1e-3"],
            "relief",
            2.0,
        ),
        (
            "hydraulics.counterbalance_valve",
            "no_seat_leak",
            "lift_circuit",
            &[],
            "cbv",
            2.0,
        ),
        (
            "hydraulics.directional_valve",
            "no_edge_leak",
            "lift_circuit",
            &[],
            "dcv",
            2.0,
        ),
        (
            "hydraulics.line",
            "one_segment",
            "accumulator_circuit",
            &[],
            "line",
            1.0,
        ),
        (
            "hydraulics.cylinder",
            "no_internal_leakage",
            "cylinder_lift",
            &[],
            "lift",
            1.0,
        ),
        (
            "hydraulics.cylinder",
            "no_external_leakage",
            "cylinder_lift",
            &["elements.lift.r_ext=1e13"],
            "lift",
            1.0,
        ),
        (
            "hydraulics.cylinder",
            "no_end_stop",
            "cylinder_lift",
            &[],
            "lift",
            1.0,
        ),
        (
            "manipulator.planar_arm",
            "rigid_lumped_masses",
            "knuckle_boom",
            &[],
            "crane",
            0.2,
        ),
        (
            "manipulator.planar_arm",
            "no_lumped_masses",
            "knuckle_boom",
            &[],
            "crane",
            0.2,
        ),
        (
            "manipulator.planar_arm",
            "rigid_links",
            "knuckle_boom",
            &[],
            "crane",
            0.2,
        ),
    ];
    let reg = bg_sim::registry();
    for k in reg.kinds() {
        for s in k.simplifications {
            assert!(
                cases.iter().any(|c| c.0 == k.name && c.1 == s.name),
                "{}: {} has no case here",
                k.name,
                s.name
            );
            let text = bg_sim::kinds::report(&reg, k.name).unwrap();
            assert!(
                text.contains(&format!("  {} — {}", s.name, s.doc)),
                "{text}"
            );
            for ch in s.changes {
                let key = ch.key().split("[*].").next().unwrap_or("");
                assert!(
                    k.param(key).is_some(),
                    "{}: {} changes `{key}`, not a parameter",
                    k.name,
                    s.name
                );
            }
        }
    }
    for &(kind, name, file, set, element, t_end) in cases {
        let path = model(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let sets: Vec<String> = set.iter().map(|s| (*s).to_owned()).collect();
        let text = bg_model::overrides::apply(file, &text, &sets).unwrap();
        // the reducer keeps the scored columns only: the line's p[2]… go with one segment
        let text = if kind == "hydraulics.line" {
            bg_sim::simplify::keep_only(&text, &["p1".to_owned()]).unwrap()
        } else {
            text
        };
        let all = candidates(&text, &reg, &[]).unwrap();
        let c = all
            .iter()
            .find(|c| c.instance == element && c.simplification.name == name)
            .unwrap_or_else(|| panic!("{kind}: {name} does not apply to {file}'s {element}"));
        assert_eq!(c.kind, kind);
        let reduced = apply(&text, &[c]).unwrap();
        assert_ne!(reduced, text);
        let mut m = Model::from_text(file, &reduced, &reg, &[])
            .unwrap_or_else(|e| panic!("{kind}: {name} on {file}: {e}"));
        m.settings.t_end = t_end;
        let out = m.run().unwrap();
        assert!(
            out.error.is_none(),
            "{kind}: {name} on {file}: {:?}",
            out.error
        );
        // and it is no longer a candidate
        assert!(!candidates(&reduced, &reg, &[])
            .unwrap()
            .iter()
            .any(|c| c.instance == element && c.simplification.name == name));
    }
}

#[test]
fn bad_options_exit_2_with_a_hint() {
    let lift = model("lift_circuit");
    for (args, says) in [
        (vec!["--tol", "0"], "--tol must be finite and > 0"),
        (vec!["--tol=-1e-2"], "--tol must be finite and > 0"),
        (vec!["--tol", "NaN"], "--tol must be finite and > 0"),
        (
            vec!["--tol", "1e-2", "--threshold", "0"],
            "--threshold must be in (0, 1]",
        ),
        (
            vec!["--tol", "1e-2", "--threshold", "2"],
            "--threshold must be in (0, 1]",
        ),
        (
            vec!["--tol", "1e-2", "--columns", "s,nope"],
            "no output column `nope`",
        ),
        (
            vec!["--tol", "1e-2", "--search", "grid"],
            "--csv and --search belong to the switch search",
        ),
    ] {
        let out = bg_sim()
            .arg("reduce")
            .arg(&lift)
            .args(["--by", "activity"])
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(err.contains("hint:"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn the_cli_reports_text_and_json() {
    let lift = model("lift_circuit");
    let out = bg_sim()
        .args([
            "reduce",
            "--by",
            "activity",
            "--tol",
            "1e-2",
            "--columns",
            "s,p_p",
            "--repeat",
            "1",
        ])
        .arg(&lift)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("| relief | no_seat_leak"), "{text}");
    assert!(
        text.contains("answer: relief: no_seat_leak simplified"),
        "{text}"
    );
    assert!(text.contains("  s: "), "{text}");
    let out = bg_sim()
        .args([
            "reduce",
            "--by",
            "activity",
            "--tol",
            "1e-2",
            "--columns",
            "s,p_p",
            "--repeat",
            "1",
            "--format",
            "json",
        ])
        .arg(&lift)
        .output()
        .unwrap();
    assert!(out.status.success());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["by"], "activity");
    assert_eq!(doc["simplified"][0]["element"], "relief");
    assert_eq!(doc["simplified"][0]["changes"][0], "g_leak = 0");
    assert!(doc["answer"]["errors"]["p_p"].as_f64().unwrap() <= 1e-2);
    assert!(doc["speedup"].as_f64().unwrap() > 0.0);
    assert_eq!(doc["ranking"][0]["element"], "gravity");
}
