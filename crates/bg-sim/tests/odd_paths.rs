//! Issue 24, item 10: a model path that is a directory or a FIFO, for every command that
//! reads a model (a FIFO without a writer blocked `check`, `run`, `graph`, `modes`,
//! `bench`, `reduce`, `plot --model` and `sweep` for ever in `open`); `modes` of a model
//! with no states; `reduce --tol 0`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn bg_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bg-sim"))
}

fn docs() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs")
}

/// Run `cmd`, killing it (SIGKILL) after 30 s: `None` if it had to be killed.
fn within(cmd: &mut Command) -> Option<std::process::Output> {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while start.elapsed().as_secs() < 30 {
        if child.try_wait().unwrap().is_some() {
            return Some(child.wait_with_output().unwrap());
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

fn commands(dir: &Path, model: &Path) -> Vec<Vec<std::ffi::OsString>> {
    let csv = dir.join("r.csv");
    std::fs::write(&csv, "t,x\n0,1\n1,2\n").unwrap();
    let m = model.as_os_str().to_owned();
    let spec = docs().join("sweeps/crane.toml").into_os_string();
    let out = dir.join("out").into_os_string();
    vec![
        vec!["check".into(), m.clone()],
        vec![
            "run".into(),
            m.clone(),
            "-o".into(),
            dir.join("o.csv").into_os_string(),
        ],
        vec![
            "graph".into(),
            m.clone(),
            "-o".into(),
            dir.join("g.svg").into_os_string(),
        ],
        vec!["modes".into(), m.clone()],
        vec!["bench".into(), m.clone()],
        vec!["reduce".into(), m.clone(), "--tol".into(), "0.1".into()],
        vec![
            "plot".into(),
            csv.into_os_string(),
            "--model".into(),
            m.clone(),
            "-o".into(),
            out.clone(),
        ],
        vec!["sweep".into(), m, "--spec".into(), spec, "-o".into(), out],
    ]
}

#[test]
fn a_model_path_that_is_a_directory_or_a_fifo_is_refused_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("model.toml");
    std::fs::create_dir(&folder).unwrap();
    let fifo = dir.path().join("pipe.toml");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for (path, what) in [(&folder, "a directory"), (&fifo, "a FIFO")] {
        for args in commands(dir.path(), path) {
            let o = within(bg_sim().args(&args))
                .unwrap_or_else(|| panic!("{args:?}: still waiting after 30 s"));
            let text = format!(
                "{}{}",
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr)
            );
            // bad input, exit 2 — `check` too: a model it cannot read is not one with
            // problems (exit 1 before)
            assert_eq!(o.status.code(), Some(2), "{args:?}: {text}");
            assert!(
                text.contains(&format!("it is {what}")) && text.contains("not a model file"),
                "{args:?}: {text}"
            );
        }
    }
}

/// `check` of a model it cannot read at all (missing) is bad input, exit 2 (it was 1, the
/// status of a model with problems); a model with problems stays 1.
#[test]
fn check_of_an_unreadable_model_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere.toml");
    for format in ["text", "json"] {
        let o = within(bg_sim().args(["check", "--format", format]).arg(&missing)).unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert_eq!(o.status.code(), Some(2), "{format}: {text}");
        assert!(text.contains("nowhere.toml"), "{format}: {text}");
    }
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[elements]\nm = { kind = \"I\" }\n").unwrap();
    let o = within(bg_sim().arg("check").arg(&bad)).unwrap();
    assert_eq!(o.status.code(), Some(2), "{o:?}");
}

/// A FIFO (or a directory) given where a results CSV, a sweep spec or a sweep summary is
/// read is refused at once, exit 2, naming it — before, a FIFO without a writer blocked
/// `plot`, `compare`, `sweep --spec` and `sweep-plot` for ever in `read_to_string`.
#[test]
fn a_fifo_or_a_directory_as_results_spec_or_summary_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("r.csv");
    std::fs::write(&csv, "t,x\n0,1\n1,2\n").unwrap();
    let fifo = dir.path().join("pipe.csv");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let folder = dir.path().join("folder.csv");
    std::fs::create_dir(&folder).unwrap();
    let msd =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models/mass_spring_damper.toml");
    let out = dir.path().join("out");
    for (odd, what) in [(&fifo, "a FIFO"), (&folder, "a directory")] {
        let png = out.join("s.png");
        let cases: Vec<Vec<&dyn AsRef<std::ffi::OsStr>>> = vec![
            vec![&"plot", odd, &"--columns", &"x", &"-o", &out],
            vec![&"plot", odd, &"--model", &msd, &"-o", &out],
            vec![&"compare", odd, &csv],
            vec![&"compare", &csv, odd],
            vec![&"sweep", &msd, &"--spec", odd, &"-o", &out],
            vec![
                &"sweep-plot",
                odd,
                &"--x",
                &"a",
                &"--y",
                &"b",
                &"--z",
                &"c",
                &"-o",
                &png,
            ],
        ];
        for args in cases {
            let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_ref()).collect();
            let o = within(bg_sim().args(&args))
                .unwrap_or_else(|| panic!("{args:?}: still waiting after 30 s"));
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert!(
                err.contains(&format!("it is {what}")) && err.contains(&*odd.to_string_lossy()),
                "{args:?}: {err}"
            );
        }
    }
}

#[test]
fn modes_without_states_and_reduce_with_no_tolerance_are_answered() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("se_r.toml");
    std::fs::write(
        &model,
        "[elements]\nsrc = { kind = \"Se\", e = 1.0 }\nr = { kind = \"R\", r = 2.0 }\n[bonds]\nb = \"src -> r\"\n",
    )
    .unwrap();
    let o = within(bg_sim().arg("modes").arg(&model)).unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{text}");
    assert!(
        text.contains("0 states") && text.contains("0 modes"),
        "{text}"
    );
    let o = within(bg_sim().args(["modes", "--json"]).arg(&model)).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["modes"].as_array().map(Vec::len), Some(0), "{json}");
    let msd =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models/mass_spring_damper.toml");
    for tol in ["0", "-1", "nan", "inf"] {
        let o = within(bg_sim().arg("reduce").arg(&msd).arg(format!("--tol={tol}"))).unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--tol {tol}: {err}");
        assert!(
            err.contains("--tol must be finite and > 0"),
            "--tol {tol}: {err}"
        );
    }
}
