//! `bg-sim plot` and `bg-sim run --plots`: PNGs for the figures whose columns a results CSV
//! has, the others skipped by name; bad input is an error, not a panic.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn is_png(p: &Path) -> bool {
    std::fs::read(p).is_ok_and(|b| b.len() > 1000 && b.starts_with(b"\x89PNG\r\n\x1a\n"))
}

fn pngs(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn plot_draws_the_figures_whose_columns_exist() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("r.csv");
    let mut text = String::from("t,l1,l2,ldot1,ldot2,F_c1,F_c2,x_v1,x_v2\n");
    for k in 0..=200 {
        let t = f64::from(k) * 0.01;
        let l = 6.0 - 2.4 * (-t).exp();
        text += &format!(
            "{t},{l},{l},{},{},{},{},{},{}\n",
            2.4 * (-t).exp(),
            2.4 * (-t).exp(),
            5e5 + 1e5 * (3.0 * t).sin(),
            2e5,
            0.3 * (6.0 - l),
            0.25 * (6.0 - l)
        );
    }
    std::fs::write(&csv, text).unwrap();
    let out = dir.path().join("figs");
    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let files = pngs(&out);
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "fig08_lengths.png",
            "fig11_valves.png",
            "fig17_cylinder_forces.png"
        ]
    );
    assert!(files.iter().all(|p| is_png(p)));
    assert!(
        stdout.contains("skipped fig09_pressures.png: no column p_p1, p_r1, p_p2, p_r2"),
        "{stdout}"
    );
}

#[test]
fn plot_refuses_bad_input_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bad.csv");
    std::fs::write(&csv, "t,l1\n0,6\n0.1,oops\n").unwrap();
    let o = bg_sim().arg("plot").arg(&csv).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("bad.csv:3: `oops` is not a number"),
        "{stderr}"
    );

    let o = bg_sim()
        .arg("plot")
        .arg(dir.path().join("missing.csv"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read"));

    // a CSV with none of the figures' columns draws nothing and says so
    std::fs::write(&csv, "t,x\n0,1\n1,2\n").unwrap();
    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .arg("--out")
        .arg(dir.path().join("none"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("none of the columns"));
}

#[test]
fn run_with_plots_draws_after_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models/knuckle_boom.toml");
    let out = dir.path().join("kb.csv");
    let figs = dir.path().join("figs");
    let o = bg_sim()
        .arg("run")
        .arg(&model)
        .arg("-o")
        .arg(&out)
        .args(["--t-end", "0.2", "--quiet", "--plots"])
        .arg(&figs)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
    let files = pngs(&figs);
    assert_eq!(files.len(), 9, "{files:?}");
    assert!(files.iter().all(|p| is_png(p)));
}
