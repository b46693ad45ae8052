//! `bg-sim bench`: the measured error falls with the tolerance, and the reference agrees with
//! the analytic solution better than any measured run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::Command;

use bg_sim::bench::{bench, table, worst_relative_error};
use bondgraph::{Method, Trajectory};

fn msd() -> bg_model::Model {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models/mass_spring_damper.toml");
    bg_model::Model::load(&path, &bg_sim::registry(), &[]).unwrap()
}

#[test]
fn error_falls_with_the_tolerance() {
    let mut m = msd();
    let (reference, rows) = bench(
        &mut m,
        &[Method::Bdf, Method::Esdirk34],
        &[1e-4, 1e-7],
        1e-10,
        1,
    )
    .unwrap();
    assert!(reference.error.is_none());
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

#[test]
fn worst_relative_error_names_the_column() {
    let reference = Trajectory {
        columns: vec!["t".into(), "a".into(), "b".into()],
        rows: vec![vec![0.0, 1.0, 10.0], vec![1.0, 2.0, 20.0]],
    };
    let run = Trajectory {
        columns: reference.columns.clone(),
        rows: vec![vec![0.0, 1.0, 10.0], vec![1.0, 2.2, 20.5]],
    };
    let (e, c) = worst_relative_error(&run, &reference).unwrap();
    assert_eq!(c, "a");
    assert!((e - 0.1).abs() < 1e-12);
    let short = Trajectory {
        columns: reference.columns.clone(),
        rows: vec![vec![0.0, 1.0, 10.0]],
    };
    assert!(worst_relative_error(&short, &reference).is_none());
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
