//! `bg-sim sweep`: results per row against the closed form, failed points kept as rows,
//! resume, and the command line.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

use bg_sim::sweep::{parse_spec, read_summary, sweep, Options, Summary};

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../models")
        .join(format!("{name}.toml"))
}

fn run(spec: &str, dir: &Path) -> Summary {
    let spec = parse_spec("spec.toml", spec).unwrap();
    let opts = Options {
        jobs: 2,
        out_dir: dir.to_path_buf(),
        interrupt: None,
    };
    sweep(&model("mass_spring_damper"), &spec, bg_sim::registry, &opts).unwrap()
}

fn col(head: &[String], name: &str) -> usize {
    head.iter().position(|h| h == name).unwrap()
}

/// The velocity of the released mass is −x0·ωn²/ωd·e^(−ζωn·t)·sin(ωd·t): its first zero
/// after t = 0 is at exactly π/ωd, ωd = ωn·√(1 − ζ²), ωn = √(k/m), ζ = c/(2√(k·m)).
/// Linear interpolation between rows 0.01 s apart misses it by about ζωn·Δt²/4 ≤ 2e-5 s here;
/// the tolerance is 1e-4 relative.
#[test]
fn damped_half_period_matches_the_closed_form_in_every_row() {
    let dir = tempfile::tempdir().unwrap();
    let s = run(
        "[parameters]\nk = [5.0, 10.0, 40.0]\nc = { from = 0.1, to = 1.0, n = 3 }\n\
         [metrics]\nt_half = \"first_crossing(v, 0)\"\nx_max = \"max(abs(x))\"\n",
        dir.path(),
    );
    assert_eq!((s.total, s.ok, s.not_ok, s.skipped), (9, 9, 0, 0));
    let (head, rows) = read_summary(&s.path).unwrap();
    assert_eq!(rows.len(), 9);
    let (ik, ic, it) = (
        col(&head, "parameters.k"),
        col(&head, "parameters.c"),
        col(&head, "t_half"),
    );
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r[col(&head, "index")], i.to_string());
        assert_eq!(r[col(&head, "status")], "ok", "{r:?}");
        let k: f64 = r[ik].parse().unwrap();
        let c: f64 = r[ic].parse().unwrap();
        let (m, x0) = (1.0, 0.01);
        let wn = (k / m).sqrt();
        let zeta = c / (2.0 * (k * m).sqrt());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let t: f64 = r[it].parse().unwrap();
        let expect = std::f64::consts::PI / wd;
        assert!(
            ((t - expect) / expect).abs() < 1e-4,
            "k = {k}, c = {c}: {t} vs π/ωd = {expect}"
        );
        let x_max: f64 = r[col(&head, "x_max")].parse().unwrap();
        assert!((x_max - x0).abs() < 1e-12, "{x_max}");
    }
}

#[test]
fn a_failing_point_is_a_row_with_its_error_and_the_others_run() {
    let dir = tempfile::tempdir().unwrap();
    let s = run(
        "[parameters]\nm = [1.0, -1.0, 2.0]\n[metrics]\nx_end = \"final(x)\"\n",
        dir.path(),
    );
    assert_eq!((s.total, s.ok, s.not_ok), (3, 2, 1));
    let (head, rows) = read_summary(&s.path).unwrap();
    let status: Vec<&str> = rows
        .iter()
        .map(|r| r[col(&head, "status")].as_str())
        .collect();
    assert_eq!(status, ["ok", "error", "ok"]);
    let e = &rows[1][col(&head, "error")];
    assert!(
        e.contains("mass") && e.contains("mass_spring_damper.toml"),
        "{e}"
    );
    assert!(rows[1][col(&head, "x_end")].is_empty());
    assert!(!rows[2][col(&head, "x_end")].is_empty());
}

#[test]
fn a_resumed_sweep_skips_the_runs_already_done() {
    let dir = tempfile::tempdir().unwrap();
    let spec = "[sweep]\ndesign = \"lhs\"\nsamples = 6\nseed = 7\n\
                [parameters]\nk = { from = 5.0, to = 50.0 }\nc = { from = 0.1, to = 1.0 }\n\
                [metrics]\nx_end = \"final(x)\"\n";
    let first = run(spec, dir.path());
    assert_eq!(first.ok, 6);
    // an interrupt after four runs, with the fifth line cut short
    let text = std::fs::read_to_string(&first.path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let kept = lines[..5].join("\n");
    let cut = &lines[5][..lines[5].len() / 2];
    std::fs::write(&first.path, format!("{kept}\n{cut}")).unwrap();
    let second = run(spec, dir.path());
    assert_eq!((second.skipped, second.ok + second.not_ok), (4, 2));
    let after = std::fs::read_to_string(&first.path).unwrap();
    let after: Vec<&str> = after.lines().collect();
    assert_eq!(after.len(), 7);
    // the four rows done before are kept as they were (their wall times too)
    assert_eq!(&after[..5], &lines[..5]);
    let third = run(spec, dir.path());
    assert_eq!((third.skipped, third.ok + third.not_ok), (6, 0));
    // a different spec does not mix its rows into this table
    let other = parse_spec(
        "spec.toml",
        "[parameters]\nk = [1.0]\n[metrics]\nx_max = \"max(x)\"\n",
    )
    .unwrap();
    let e = sweep(
        &model("mass_spring_damper"),
        &other,
        bg_sim::registry,
        &Options {
            jobs: 1,
            out_dir: dir.path().to_path_buf(),
            interrupt: None,
        },
    )
    .unwrap_err();
    assert!(e.message.contains("different sweep spec"), "{e}");
}

#[test]
fn sweep_plot_draws_a_png_of_a_grid() {
    let dir = tempfile::tempdir().unwrap();
    let s = run(
        "[parameters]\nk = [5.0, 10.0, 40.0]\nc = [0.2, 0.5]\n[metrics]\nv_rms = \"rms(v)\"\n",
        dir.path(),
    );
    let png = dir.path().join("map.png");
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("sweep-plot")
        .arg(&s.path)
        .args([
            "--x",
            "parameters.k",
            "--y",
            "parameters.c",
            "--z",
            "v_rms",
            "-o",
        ])
        .arg(&png)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    // a column the summary does not have is bad input, with the columns it has
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("sweep-plot")
        .arg(&s.path)
        .args(["--x", "parameters.k", "--y", "parameters.m", "--z", "v_rms"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no column `parameters.m`"));
}

#[test]
fn cli_sweep_writes_the_summary_and_keeps_runs() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("s.toml");
    std::fs::write(
        &spec,
        "[sweep]\nkeep_runs = true\n[parameters]\nk = [10, 20]\n\"simulation.t_end\" = 1.0\n\
         [metrics]\nF_peak = \"max(abs(F_spring))\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("sweep")
        .arg(model("mass_spring_damper"))
        .arg("--spec")
        .arg(&spec)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("2 runs: 2 done now (2 ok"), "{stdout}");
    let (head, rows) = read_summary(&out.join("summary.csv")).unwrap();
    assert_eq!(head[2..5], ["parameters.k", "simulation.t_end", "F_peak"]);
    // F = k·x, largest at the release: k·x0
    for (r, k) in rows.iter().zip([10.0, 20.0]) {
        let f: f64 = r[4].parse().unwrap();
        assert!((f - k * 0.01).abs() < 1e-12, "{f}");
    }
    assert_eq!(std::fs::read_dir(out.join("runs")).unwrap().count(), 2);

    // sweep-plot needs two values per axis: one axis of one value is refused, named
    let png = dir.path().join("map.png");
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("sweep-plot")
        .arg(out.join("summary.csv"))
        .args([
            "--x",
            "parameters.k",
            "--y",
            "simulation.t_end",
            "--z",
            "F_peak",
            "-o",
        ])
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("2 × 2"));

    // a bad spec is bad input, named
    std::fs::write(
        &spec,
        "[parameters]\nk = [1]\n[metrics]\nm = \"median(x)\"\n",
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("sweep")
        .arg(model("mass_spring_damper"))
        .arg("--spec")
        .arg(&spec)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("s.toml") && stderr.contains("unknown reduction `median`"),
        "{stderr}"
    );
}

/// The spec blocks of docs/sweeps.md (fenced ```` ```toml sweep-spec ````) and the crane
/// study's spec parse, and their grids have the size the doc says.
#[test]
fn the_documented_specs_parse() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("docs/sweeps.md")).unwrap();
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in doc.lines() {
        match (&mut current, line.trim()) {
            (None, "```toml sweep-spec") => current = Some(String::new()),
            (Some(_), "```") => blocks.extend(current.take()),
            (Some(b), l) => {
                b.push_str(l);
                b.push('\n');
            }
            _ => {}
        }
    }
    assert!(!blocks.is_empty());
    for (i, b) in blocks.iter().enumerate() {
        let s = parse_spec(&format!("docs/sweeps.md block {}", i + 1), b).unwrap();
        assert!(!bg_sim::sweep::points(&s).is_empty());
    }
    let crane = std::fs::read_to_string(root.join("docs/sweeps/crane.toml")).unwrap();
    let s = parse_spec("docs/sweeps/crane.toml", &crane).unwrap();
    assert_eq!(bg_sim::sweep::points(&s).len(), 55);
}

/// Ctrl-C during a sweep: the runs under way stop and are not recorded, the finished ones
/// stay in summary.csv, the exit status is 1; the same command again does only the rest.
#[test]
fn an_interrupted_sweep_resumes_where_it_stopped() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("s.toml");
    // 20 runs of 5000 s, about 0.15 s each here: the signal comes after the first two rows,
    // well before the other 18 (about 1.3 s on two threads)
    std::fs::write(
        &spec,
        "[parameters]\nk = { from = 5.0, to = 50.0, n = 20 }\n\"simulation.t_end\" = 5000.0\n\
         [metrics]\nx_end = \"final(x)\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let sweep = || {
        let mut c = Command::new(env!("CARGO_BIN_EXE_bg-sim"));
        c.arg("sweep")
            .arg(model("mass_spring_damper"))
            .arg("--spec")
            .arg(&spec)
            .arg("-o")
            .arg(&out)
            .args(["-j", "2"]);
        c
    };
    let summary = out.join("summary.csv");
    let child = sweep()
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let done = |p: &Path| {
        std::fs::read_to_string(p)
            .map(|t| t.lines().count().saturating_sub(1))
            .unwrap_or(0)
    };
    while done(&summary) < 2 {
        assert!(start.elapsed().as_secs() < 120, "no rows after 120 s");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let o = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let kept = done(&summary);
    assert!((2..20).contains(&kept), "{kept} rows: {stdout}");
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains(&format!("{} left by an interrupt", 20 - kept)),
        "{stdout}"
    );
    let (head, rows) = read_summary(&summary).unwrap();
    assert!(
        rows.iter().all(|r| r[col(&head, "status")] == "ok"),
        "an interrupted run was recorded: {rows:?}"
    );
    let o = sweep().output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}");
    assert!(
        stdout.contains(&format!("20 runs: {} done now", 20 - kept))
            && stdout.contains(&format!("{kept} already in the summary")),
        "{stdout}"
    );
    assert_eq!(read_summary(&summary).unwrap().1.len(), 20);
}

/// Issue 24, item 8: a parameter the model lacks is a mistake common to every run: exit 2
/// before any run (no summary written), naming it, as docs/sweeps.md says; before, every
/// run was an error row and the exit status 1. A spec's mistakes name its file and line.
#[test]
fn a_spec_mistake_is_exit_2_before_any_run_and_names_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("spec.toml");
    std::fs::write(
        &spec,
        "[parameters]\nm = [1.0, 2.0]\nnope = [1.0, 2.0]\n[metrics]\nx_end = \"final(x)\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("sweep")
        .arg(model("mass_spring_damper"))
        .arg("--spec")
        .arg(&spec)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("parameters.nope") && err.contains("no parameter `nope`"),
        "{err}"
    );
    assert!(!out.join("summary.csv").exists(), "a run started");
    // spec errors: file and line
    for (text, line, what) in [
        (
            "[parameters]\nm = [1.0]\nk = { from = nan, to = 1.0, n = 2 }\n",
            3,
            "`k`: `from` must be a finite number",
        ),
        (
            "[sweep]\ndesign = \"grid\"\nkeep_runs = 3\n[parameters]\nm = [1.0]\n",
            3,
            "keep_runs is true or false",
        ),
        (
            "[parameters]\nm = [1.0]\n[metrics]\n\n\"peak\" = \"biggest(x)\"\n",
            5,
            "peak",
        ),
        (
            "[parameters]\nm = [1.0]\nk = { from = 1.0, to = 2.0 }\n",
            3,
            "needs n",
        ),
        ("[parameters]\nm = [1.0\n", 2, "not a valid TOML"),
    ] {
        let e = parse_spec("spec.toml", text).unwrap_err().to_string();
        assert!(e.starts_with(&format!("spec.toml:{line}: ")), "{text}: {e}");
        assert!(e.contains(what), "{e}");
    }
}
