//! `bg-sim run`'s progress bar (on a terminal only, after a second, not with `--quiet`) and
//! `bg-sim graph` end to end.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::Command;

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../models")
        .join(format!("{name}.toml"))
}

/// What a bar leaves on stderr: its fill, its rate, a carriage return or an escape sequence.
fn has_bar(s: &str) -> bool {
    s.contains("s/s") || s.contains("=>") || s.contains('\r') || s.contains('\u{1b}')
}

/// The crane over 250 s: about 2.5 s of wall time in the test profile, past the second after
/// which a bar would be drawn.
const LONG: [&str; 2] = ["--t-end", "250"];

#[test]
fn a_piped_run_prints_no_progress() {
    let dir = tempfile::tempdir().unwrap();
    let o = bg_sim()
        .arg("run")
        .arg(model("knuckle_boom"))
        .arg("-o")
        .arg(dir.path().join("kb.csv"))
        .args(LONG)
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!has_bar(&err), "stderr: {err}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!has_bar(&out), "stdout: {out}");
}

/// Under a pseudo-terminal (`script` of util-linux; skipped where it is missing) a long run
/// shows the bar, and `--quiet` hides it.
#[test]
fn a_run_on_a_terminal_shows_progress_unless_quiet() {
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("skipped: no `script` to give the run a terminal");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let run = |quiet: bool| {
        let cmd = format!(
            "{} run {} -o {} {} {}{}",
            env!("CARGO_BIN_EXE_bg-sim"),
            model("knuckle_boom").display(),
            dir.path().join("kb.csv").display(),
            LONG[0],
            LONG[1],
            if quiet { " --quiet" } else { "" }
        );
        let o = Command::new("script")
            .args(["-qec", &cmd, "/dev/null"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{o:?}");
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let shown = run(false);
    assert!(shown.contains("s/s") && shown.contains(" left"), "{shown}");
    let quiet = run(true);
    assert!(!has_bar(&quiet), "{quiet}");
}

#[test]
fn graph_writes_svg_and_dot() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("g/cyl.svg");
    let o = bg_sim()
        .arg("graph")
        .arg(model("cylinder_lift"))
        .arg("-o")
        .arg(&svg)
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("class=\"causal-stroke\""));
    // the extension picks DOT; --format overrides it
    let dot = dir.path().join("cyl.dot");
    let o = bg_sim()
        .arg("graph")
        .arg(model("cylinder_lift"))
        .arg("--expand")
        .arg("-o")
        .arg(&dot)
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let text = std::fs::read_to_string(&dot).unwrap();
    assert!(text.starts_with("digraph") && text.contains("subgraph cluster_0"));
    let o = bg_sim()
        .arg("graph")
        .arg(model("cylinder_lift"))
        .args(["--format", "svg", "-o"])
        .arg(&dot)
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    assert!(std::fs::read_to_string(&dot).unwrap().starts_with("<svg"));
    // a refused model is drawn, with a note on stderr
    let o = bg_sim()
        .arg("graph")
        .arg(model("derivative_causality"))
        .arg("-o")
        .arg(dir.path().join("dc.svg"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    assert!(String::from_utf8_lossy(&o.stderr).contains("without causal strokes"));
    // a missing model is bad input
    let o = bg_sim()
        .arg("graph")
        .arg(model("no_such_model"))
        .arg("-o")
        .arg(dir.path().join("x.svg"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}
