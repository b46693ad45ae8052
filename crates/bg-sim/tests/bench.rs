//! `bg-sim bench`: the measured error falls with the tolerance, and the reference agrees with
//! the analytic solution better than any measured run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::Command;

use bg_sim::bench::{bench, reference_run, table, Reference};
use bondgraph::{Method, Trajectory};

fn msd() -> bg_model::Model {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models/mass_spring_damper.toml");
    bg_model::Model::load(&path, &bg_sim::registry(), &[]).unwrap()
}

#[test]
fn error_falls_with_the_tolerance() {
    let mut m = msd();
    let (reference_out, reference) = reference_run(&mut m, Method::Bdf, 1e-10, None, &[]).unwrap();
    assert!(reference_out.error.is_none());
    let rows = bench(
        &mut m,
        &[Method::Bdf, Method::Esdirk34],
        &[1e-4, 1e-7],
        &reference,
        1,
    )
    .unwrap();
    assert_eq!(rows.len(), 4);
    for pair in rows.chunks(2) {
        let (loose, tight) = (&pair[0], &pair[1]);
        let (e_loose, e_tight) = (
            loose.error.as_ref().unwrap().0,
            tight.error.as_ref().unwrap().0,
        );
        assert!(
            e_tight < e_loose / 10.0,
            "{:?}: {e_loose:e} → {e_tight:e}",
            loose.method
        );
        assert!(tight.steps > loose.steps);
        assert!(e_loose < 1e-2, "{e_loose}");
    }
    let t = table(&rows);
    assert_eq!(t.lines().count(), 6, "{t}");
    assert!(t.contains("| bdf | 1e-4 |"), "{t}");
}

fn traj(rows: Vec<Vec<f64>>) -> Trajectory {
    Trajectory {
        columns: vec!["t".into(), "a".into(), "qb1_1".into(), "qb2_3".into()],
        rows,
    }
}

/// The scale is max(range, |mean|, floor); the floor of a quantity is 1 % of its largest
/// column's scale, so a column that barely moves is not measured against its own range.
#[test]
fn scaled_error_names_the_column_and_applies_the_floors() {
    let reference = traj(vec![
        vec![0.0, 1.0, 0.0, 0.0],
        vec![1.0, 3.0, 0.5, 1e-6],
        vec![2.0, 2.0, 1.0, 0.0],
    ]);
    let r = Reference::from_trajectory(&reference, None, &[]).unwrap();
    // a: range 2, |mean| 2 → scale 2; qb1_1: range 1 → 1; qb2_3: own 1e-6, floor 1 % of 1
    let run = traj(vec![
        vec![0.0, 1.0, 0.0, 0.0],
        vec![1.0, 3.2, 0.5, 1e-6 + 5e-4],
        vec![2.0, 2.0, 1.03, 0.0],
    ]);
    let errors = r.errors(&run).unwrap();
    let e = |n: &str| errors.iter().find(|(c, _)| c == n).unwrap().1;
    assert!((e("a") - 0.1).abs() < 1e-12);
    assert!((e("qb1_1") - 0.03).abs() < 1e-12);
    assert!((e("qb2_3") - 0.05).abs() < 1e-9, "{}", e("qb2_3"));
    let (worst, col) = r.worst(&run).unwrap();
    assert_eq!(col, "a");
    assert!((worst - 0.1).abs() < 1e-12);
    // an explicit floor wins over the quantity's
    let r = Reference::from_trajectory(&reference, None, &[("qb2*".into(), 1e-3)]).unwrap();
    assert!((r.errors(&run).unwrap()[2].1 - 0.5).abs() < 1e-9);
    // only the named columns; an unknown one is refused with the columns there are
    let only = Reference::from_trajectory(&reference, Some(&["qb1_1".into()]), &[]).unwrap();
    assert_eq!(only.columns.len(), 1);
    let err = Reference::from_trajectory(&reference, Some(&["nope".into()]), &[]).unwrap_err();
    assert!(err.contains("nope") && err.contains("qb1_1"), "{err}");
    // a run over a different span is not scored
    let short = traj(vec![vec![0.0, 1.0, 0.0, 0.0]]);
    assert!(r.errors(&short).is_none());
}

/// Output times that differ from the reference's are scored against the reference
/// interpolated linearly.
#[test]
fn scaled_error_interpolates_the_reference() {
    let reference = traj(vec![vec![0.0, 0.0, 0.0, 0.0], vec![2.0, 2.0, 1.0, 1.0]]);
    let r = Reference::from_trajectory(&reference, Some(&["a".into()]), &[]).unwrap();
    let run = Trajectory {
        columns: vec!["t".into(), "a".into()],
        rows: vec![vec![0.0, 0.0], vec![1.0, 1.1], vec![2.0, 2.0]],
    };
    let (e, _) = r.worst(&run).unwrap();
    assert!((e - 0.05).abs() < 1e-12, "{e}");
}

#[test]
fn the_command_prints_a_table() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models/dc_motor.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("bench")
        .arg(path)
        .args(["--solvers", "bdf", "--rtols", "1e-5", "--repeat", "1"])
        .output()
        .unwrap();
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{s}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        s.contains("| solver | rtol |") && s.contains("| bdf | 1e-5 |"),
        "{s}"
    );
}

#[test]
fn the_command_scores_against_a_reference_file_and_draws_the_diagram() {
    let dir = tempfile::tempdir().unwrap();
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models/dc_motor.toml");
    let reference = dir.path().join("ref.csv");
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("run")
        .arg(&model)
        .args(["--rtol", "1e-10", "-q", "-o"])
        .arg(&reference)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let png = dir.path().join("wp.png");
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("bench")
        .arg(&model)
        .arg("--reference")
        .arg(&reference)
        .args([
            "--solvers",
            "bdf,esdirk34",
            "--rtols",
            "1e-3,1e-6",
            "--repeat",
            "1",
        ])
        .arg("--plot")
        .arg(&png)
        .output()
        .unwrap();
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{s}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        s.lines()
            .filter(|l| l.starts_with("| bdf |") || l.starts_with("| esdirk34 |"))
            .count(),
        4,
        "{s}"
    );
    let bytes = std::fs::read(&png).unwrap();
    assert!(
        bytes.len() > 5_000 && bytes.starts_with(b"\x89PNG"),
        "{} bytes",
        bytes.len()
    );
    // a column the reference lacks is refused before any run
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("bench")
        .arg(&model)
        .arg("--reference")
        .arg(&reference)
        .args(["--columns", "no_such_column"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no_such_column"));
    // --rhs times the right-hand side only
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("bench")
        .arg(&model)
        .arg("--rhs")
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("µs per call"));
}
