//! The `bg-sim` binary end to end: CSV output, statistics, `check`, errors and partial results.
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

#[test]
fn run_writes_csv_with_header_and_prints_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("msd.csv");
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .arg("-o")
        .arg(&out)
        .args(["--t-end", "2", "--dt-out", "0.5"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        stdout.contains("steps") && stdout.contains("rhs evals") && stdout.contains("wall time"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "t,x,v,F_spring");
    let times: Vec<f64> = lines[1..]
        .iter()
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 1.5, 2.0]);
    // no temporary files left behind
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn solver_and_set_options_apply() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.csv");
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .arg("-o")
        .arg(&out)
        .args([
            "--solver",
            "esdirk34",
            "--rtol",
            "1e-9",
            "--set",
            "parameters.x0=0.02",
            "--set",
            "simulation.t_end=1",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("esdirk34"), "{stdout}");
    let csv = std::fs::read_to_string(&out).unwrap();
    let first: Vec<f64> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((first[1] - 0.02).abs() < 1e-15, "x0 override: {first:?}");
    assert!(csv.lines().last().unwrap().starts_with("1,"));
    assert!(o.status.success());
}

#[test]
fn check_lists_causality_and_refuses_bad_models() {
    let o = bg_sim()
        .arg("check")
        .arg(model("dc_motor"))
        .output()
        .unwrap();
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{s}");
    assert!(
        s.contains("b5: shaft ---|> rotor") || s.contains("b5: shaft |---> rotor"),
        "{s}"
    );
    assert!(
        s.contains("rotor.p") && s.contains("no problems found"),
        "{s}"
    );

    for (name, words) in [
        (
            "derivative_causality",
            ["derivative causality", "load", "cart"],
        ),
        ("algebraic_loop", ["algebraic loop", "r1", "r2"]),
    ] {
        let o = bg_sim().arg("check").arg(model(name)).output().unwrap();
        let s = String::from_utf8_lossy(&o.stdout);
        // a model with problems is bad input: 2, as in every command (issue 37)
        assert_eq!(o.status.code(), Some(2), "{s}");
        for w in words {
            assert!(s.contains(w), "`{w}` missing: {s}");
        }
        assert!(s.contains("hint:"), "{s}");
        assert!(s.contains(&format!("{name}.toml:")), "file and line: {s}");
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .args(["--solver", "euler"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("unknown solver") && err.contains("radau5"),
        "{err}"
    );
    // the same text through the file's door
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .args(["--set", "simulation.solver=\"euler\""])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("unknown solver") && err.contains("radau5"),
        "{err}"
    );
    for rtol in ["0", "-1e-6"] {
        let o = bg_sim()
            .args(["run"])
            .arg(model("mass_spring_damper"))
            .args(["--solver", "radau5", &format!("--rtol={rtol}")])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "rtol {rtol}");
        assert!(
            String::from_utf8_lossy(&o.stderr).contains("rtol"),
            "rtol {rtol}"
        );
    }
    let o = bg_sim()
        .args(["run", "does/not/exist.toml"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read"));
    let o = bg_sim()
        .args(["run"])
        .arg(model("mass_spring_damper"))
        .args(["--set", "parameters.c=-1"])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("mass_spring_damper.toml:") && e.contains("damper") && e.contains(">= 0"),
        "{e}"
    );
}

#[test]
fn a_failed_run_keeps_its_rows_in_a_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blowup.toml");
    std::fs::write(
        &path,
        r#"
title = "Blows up at t = 1: the source's effort is 1/(1 - t)"
[elements]
src = { kind = "Se", e = "1/(1 - t)" }
j = { kind = "1" }
r = { kind = "R", r = 1.0 }
c = { kind = "C", c = 1.0 }
[bonds]
b1 = "src -> j"
b2 = "j -> r"
b3 = "j -> c"
[simulation]
t_end = 2.0
dt_out = 0.1
"#,
    )
    .unwrap();
    let out = dir.path().join("blowup.csv");
    let o = bg_sim()
        .arg("run")
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        !out.exists(),
        "a failed run must not leave a file that looks complete"
    );
    let partial = std::fs::read_to_string(dir.path().join("blowup.partial.csv")).unwrap();
    let rows = partial.lines().count() - 1;
    assert!(
        (9..=11).contains(&rows),
        "rows up to t ≈ 1 kept, got {rows}"
    );
    assert!(
        e.contains("t = 0.9") || e.contains("t = 1"),
        "time of failure: {e}"
    );
}

// ---- Issue "hardening": no crash, no lost result, no silently wrong file ----

/// Run `bg-sim` with `args`; (exit code, stdout, stderr). A panic (101) or a signal (None)
/// fails the test.
fn run_ok(args: &[&std::ffi::OsStr]) -> (i32, String, String) {
    let o = bg_sim().args(args).output().unwrap();
    let code = o.status.code();
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    );
    assert!(
        matches!(code, Some(0..=2)),
        "exit {code:?} (a panic or a signal):\n{out}\n{err}"
    );
    (code.unwrap_or(-1), out, err)
}

fn os<S: AsRef<std::ffi::OsStr> + ?Sized>(s: &S) -> &std::ffi::OsStr {
    s.as_ref()
}

/// #1: 9 000 nested parentheses in `--set` aborted the process (stack overflow, exit 134).
#[test]
fn a_deeply_nested_expression_is_an_error_not_a_stack_overflow() {
    let m = model("mass_spring_damper");
    for n in [3_000, 9_000] {
        let deep = format!("parameters.k={}10{}", "(".repeat(n), ")".repeat(n));
        let (code, out, _) = run_ok(&[os("check"), os(&m), os("--set"), os(&deep)]);
        assert_eq!(code, 2, "{out}");
        assert!(
            out.contains("nested more than 200") || out.contains("more than 10000"),
            "{out}"
        );
        assert!(
            out.len() < 2_000,
            "the value is not echoed whole: {} bytes",
            out.len()
        );
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("m.csv");
        let (code, _, err) = run_ok(&[
            os("run"),
            os(&m),
            os("-o"),
            os(&csv),
            os("--set"),
            os(&deep),
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("parameter `k`"), "{err}");
    }
}

/// #2: an output named "a,b" gave a header of 11 fields over rows of 10, exit 0.
#[test]
fn an_output_name_that_would_break_the_csv_header_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(model("mass_spring_damper"))
        .unwrap()
        .replace("F_spring = ", "\"a,b\" = ");
    let path = dir.path().join("m.toml");
    std::fs::write(&path, text).unwrap();
    let csv = dir.path().join("m.csv");
    let (code, _, err) = run_ok(&[os("run"), os(&path), os("-o"), os(&csv)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cannot be a column name"), "{err}");
    assert!(!csv.exists());
}

/// #3: `run m.toml -o m.toml` overwrote the model with CSV; a symlink or FIFO given to `-o`
/// was replaced.
#[test]
fn o_never_destroys_the_model_a_symlink_or_a_fifo() {
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("m.toml");
    std::fs::copy(model("mass_spring_damper"), &m).unwrap();
    let before = std::fs::read_to_string(&m).unwrap();
    // the model itself, by its name, through another spelling, and as the partial file
    let other = dir.path().join(".").join("m.toml");
    for o in [&m, &other] {
        let (code, _, err) =
            run_ok(&[os("run"), os(&m), os("-o"), os(o), os("--t-end"), os("0.1")]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("is the model file"), "{err}");
        assert_eq!(std::fs::read_to_string(&m).unwrap(), before);
    }
    // a model named like the partial file of `-o`
    let mp = dir.path().join("r.partial.csv");
    std::fs::copy(&m, &mp).unwrap();
    let r = dir.path().join("r.csv");
    let (code, _, err) = run_ok(&[
        os("run"),
        os(&mp),
        os("-o"),
        os(&r),
        os("--t-end"),
        os("0.1"),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is the model file"), "{err}");
    assert_eq!(std::fs::read_to_string(&mp).unwrap(), before);
    // a symbolic link to a file: refused, the file untouched
    let target = dir.path().join("keep.csv");
    std::fs::write(&target, "precious").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let (code, _, err) = run_ok(&[
        os("run"),
        os(&m),
        os("-o"),
        os(&link),
        os("--t-end"),
        os("0.1"),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("symbolic link"), "{err}");
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    // a FIFO (reading it would block: it must not even be opened) and a directory
    let fifo = dir.path().join("fifo.csv");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for (o, what) in [
        (&fifo, "not a regular file"),
        (&dir.path().to_path_buf(), "a directory"),
    ] {
        let (code, _, err) =
            run_ok(&[os("run"), os(&m), os("-o"), os(o), os("--t-end"), os("0.1")]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(what), "{err}");
    }
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
}

use std::os::unix::fs::FileTypeExt;

/// #4: t_start = 1e16 gave "steps 0" and 10 001 identical rows with exit 0.
#[test]
fn times_too_large_to_resolve_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("m.csv");
    let (code, _, err) = run_ok(&[
        os("run"),
        os(&model("mass_spring_damper")),
        os("-o"),
        os(&csv),
        os("--set"),
        os("simulation.t_start=1e16"),
        os("--set"),
        os("simulation.t_end=1.00000000000001e16"),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("too short to integrate"), "{err}");
    assert!(!csv.exists());
}

/// #5: `-o /proc/kb.csv` computed for 4 s, then kept nothing. The destination is opened
/// before the first step.
#[test]
fn an_unwritable_output_is_refused_before_integrating() {
    let (code, out, err) = run_ok(&[
        os("run"),
        os(&model("mass_spring_damper")),
        os("-o"),
        os("/proc/kb.csv"),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cannot write /proc/kb.partial.csv"), "{err}");
    assert!(!out.contains("solver:"), "nothing was integrated: {out}");
}

/// A long run of the mass–spring–damper (1e7 output rows), its CSV and partial file.
fn long_run(dir: &std::path::Path) -> (std::process::Child, PathBuf, PathBuf) {
    let csv = dir.join("long.csv");
    let child = bg_sim()
        .arg("run")
        .arg(model("mass_spring_damper"))
        .arg("-o")
        .arg(&csv)
        .args(["--t-end", "1e5", "--dt-out", "0.01", "--quiet"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    (child, csv, dir.join("long.partial.csv"))
}

/// Wait until `path` has at least `lines` lines.
fn wait_for_rows(path: &std::path::Path, lines: usize) {
    let start = std::time::Instant::now();
    while std::fs::read_to_string(path).map_or(0, |s| s.lines().count()) < lines {
        assert!(
            start.elapsed().as_secs() < 60,
            "no rows in {}",
            path.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Every line of a CSV has as many fields as its header; (rows, last time).
fn complete_rows(text: &str) -> (usize, f64) {
    let mut lines = text.lines();
    let n = lines.next().unwrap().split(',').count();
    let mut rows = 0;
    let mut last = f64::NAN;
    for l in lines {
        let cells: Vec<&str> = l.split(',').collect();
        assert_eq!(cells.len(), n, "incomplete row `{l}`");
        last = cells[0].parse().unwrap();
        rows += 1;
    }
    assert!(text.ends_with('\n'), "the last row is complete");
    (rows, last)
}

/// #5: SIGINT/SIGTERM during integration kept no rows; a kill during the CSV write left a
/// hidden temporary file of 16–25 MB. Rows stream to OUT.partial.csv as they are computed;
/// a signal stops the run there, keeps every row (exit 1), and no other file is left.
#[test]
fn sigint_and_sigterm_keep_the_rows_in_the_partial_file() {
    for sig in ["-INT", "-TERM"] {
        let dir = tempfile::tempdir().unwrap();
        let (child, csv, partial) = long_run(dir.path());
        wait_for_rows(&partial, 2_000);
        assert!(Command::new("kill")
            .args([sig, &child.id().to_string()])
            .status()
            .unwrap()
            .success());
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{sig}: {err}");
        assert!(err.contains("interrupted at t ="), "{err}");
        assert!(!csv.exists());
        let (rows, last) = complete_rows(&std::fs::read_to_string(&partial).unwrap());
        assert!(rows >= 2_000, "{rows}");
        assert!(err.contains(&format!("the {rows} rows computed")), "{err}");
        assert!((last - (rows - 1) as f64 * 0.01).abs() < 1e-6);
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(
            names,
            [std::ffi::OsString::from("long.partial.csv")],
            "{sig}"
        );
    }
}

/// #5: SIGKILL cannot be caught: what was written is in OUT.partial.csv, under its own name,
/// and no hidden temporary file is left.
#[test]
fn a_killed_run_leaves_only_the_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let (mut child, _, partial) = long_run(dir.path());
    wait_for_rows(&partial, 2_000);
    child.kill().unwrap();
    let _ = child.wait();
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, [std::ffi::OsString::from("long.partial.csv")]);
}

/// A shell command running bg-sim with the file size limited to `kib` KiB (a full disk:
/// writes past it fail with EFBIG; SIGXFSZ is ignored so that they fail rather than kill).
fn with_full_disk(kib: usize, args: &str) -> std::process::Output {
    Command::new("bash")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f {kib}; exec {} {args}",
            env!("CARGO_BIN_EXE_bg-sim")
        ))
        .output()
        .unwrap()
}

/// #5: a full disk keeps the complete rows written so far in OUT.partial.csv (exit 1); a
/// failed run left the old OUT.csv beside OUT.partial.csv, and a later good run left the
/// stale partial file. Now exactly one of them is left, from the last run.
#[test]
fn a_full_disk_keeps_complete_rows_and_old_results_never_mix_with_new() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("m.csv");
    let partial = dir.path().join("m.partial.csv");
    let m = model("mass_spring_damper");
    let good = || {
        let (code, _, err) = run_ok(&[
            os("run"),
            os(&m),
            os("-o"),
            os(&csv),
            os("--t-end"),
            os("1"),
        ]);
        assert_eq!(code, 0, "{err}");
    };
    good();
    assert!(csv.exists() && !partial.exists());
    let o = with_full_disk(
        64,
        &format!(
            "run {} -o {} --t-end 100 --dt-out 1e-3",
            m.display(),
            csv.display()
        ),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("could not be written"), "{err}");
    assert!(!csv.exists(), "the old results were removed");
    let text = std::fs::read_to_string(&partial).unwrap();
    assert!(text.len() <= 64 * 1024);
    let (rows, _) = complete_rows(&text);
    assert!(rows > 100, "{rows}");
    good();
    assert!(
        csv.exists() && !partial.exists(),
        "the stale partial file is gone"
    );
}

/// #8: a closed or full stdout panicked (exit 101) and the checks never ran.
#[test]
fn a_closed_or_full_stdout_loses_the_report_not_the_run() {
    // closed: the reader is gone before bg-sim writes
    for args in [vec!["kinds"], vec!["check", "MODEL"]] {
        let mut c = bg_sim()
            .args(args.iter().map(|a| {
                if *a == "MODEL" {
                    model("dc_motor").into_os_string()
                } else {
                    a.into()
                }
            }))
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(c.stdout.take());
        let o = c.wait_with_output().unwrap();
        assert_eq!(
            o.status.code(),
            Some(0),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("m.csv");
    let mut c = bg_sim()
        .arg("run")
        .arg(model("mass_spring_damper"))
        .arg("-o")
        .arg(&csv)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(c.stdout.take());
    assert_eq!(c.wait().unwrap().code(), Some(0));
    assert!(csv.exists());
    // full: the report is lost (a warning on stderr); the run and its checks still decide
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    std::fs::remove_file(&csv).unwrap();
    let o = bg_sim()
        .arg("run")
        .arg(model("mass_spring_damper"))
        .arg("-o")
        .arg(&csv)
        .args(["--set", "check[0].tol=0"])
        .stdout(full())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(1),
        "the failing check still fails the run: {err}"
    );
    assert!(err.contains("the report on stdout is incomplete"), "{err}");
    assert!(csv.exists());
    let o = bg_sim().arg("kinds").stdout(full()).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "kinds' product is its report");
}

/// #9: a model with no states (`Se -> R`) passed `check`, then panicked in `run`.
#[test]
fn a_model_without_states_runs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("se_r.toml");
    std::fs::write(
        &path,
        "[elements]\nsrc = { kind = \"Se\", e = \"2*t\" }\nr = { kind = \"R\", r = 4.0 }\n[bonds]\nb = \"src -> r\"\n[simulation]\nt_end = 1.0\ndt_out = 0.5\n[outputs]\nP = \"r.P\"\n",
    )
    .unwrap();
    let csv = dir.path().join("se_r.csv");
    let (code, _, err) = run_ok(&[os("run"), os(&path), os("-o"), os(&csv)]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        "t,P\n0,0\n0.5,0.25\n1,1\n"
    );
}

/// #10: result files were created mode 0600 whatever the umask.
#[test]
fn result_files_follow_the_umask() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("m.csv");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "umask 022; exec {} run {} -o {} --t-end 0.1",
            env!("CARGO_BIN_EXE_bg-sim"),
            model("mass_spring_damper").display(),
            csv.display()
        ))
        .output()
        .unwrap();
    assert!(o.status.success());
    let mode = std::fs::metadata(&csv).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o644);
}

/// #7: `bg-sim check /dev/zero` read until memory ran out. A file `check` cannot read is bad
/// input, exit 2 (issue 24: it was 1, the status of a model with problems).
#[test]
fn check_of_an_endless_file_is_refused() {
    let (code, out, _) = run_ok(&[os("check"), os("/dev/zero")]);
    assert_eq!(code, 2);
    assert!(out.contains("larger than 16 MiB"), "{out}");
}

/// #7: all rows were held in memory (the crane at 1e6 rows × 55 columns: 540 MB; under a
/// 1 GB limit the run aborted and kept nothing). Rows stream to the file: 3e6 rows run in
/// 150 MB of address space, which the rows alone would have exceeded (3e6 × 56 bytes).
#[test]
fn three_million_rows_stream_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("m.csv");
    let o = Command::new("bash")
        .arg("-c")
        .arg(format!(
            "ulimit -v 150000; exec {} run {} -o {} --t-end 3e4 --dt-out 0.01 --quiet",
            env!("CARGO_BIN_EXE_bg-sim"),
            model("mass_spring_damper").display(),
            csv.display()
        ))
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let lines =
        std::io::BufRead::lines(std::io::BufReader::new(std::fs::File::open(&csv).unwrap()))
            .count();
    assert_eq!(lines, 3_000_002);
}

/// The number after `"key": ` in `json` (the first occurrence).
fn json_number(json: &str, key: &str) -> f64 {
    let at = json.find(&format!("\"{key}\": ")).unwrap() + key.len() + 4;
    let end = json[at..].find([',', '}']).unwrap() + at;
    json[at..end].trim().parse().unwrap()
}

/// `bg-sim modes` on the series RLC circuit: ω_n = 1/√(LC) = 316.23 rad/s and
/// ζ = (R/2)·√(C/L) = 0.1581 (R = 10 Ω, L = 0.1 H, C = 1e-4 F), to 1e-6 relative, in the JSON
/// for scripts and in the table; `--at` runs to T first; a bad `--at` is refused.
#[test]
fn modes_lists_eigenvalues_against_closed_forms() {
    let o = bg_sim()
        .args(["modes", "--json"])
        .arg(model("rlc_series"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json = String::from_utf8(o.stdout).unwrap();
    let (r, l, c) = (10.0f64, 0.1f64, 1e-4f64);
    let fn_hz = 1.0 / (l * c).sqrt() / (2.0 * std::f64::consts::PI);
    let zeta = r / 2.0 * (c / l).sqrt();
    let got_f = json_number(&json, "natural_hz");
    let got_z = json_number(&json, "damping_ratio");
    eprintln!("f_n {got_f} vs {fn_hz}, ζ {got_z} vs {zeta}");
    assert!((got_f / fn_hz - 1.0).abs() < 1e-6, "{json}");
    assert!((got_z / zeta - 1.0).abs() < 1e-6, "{json}");
    assert!(json.contains("\"state\": \"inductor.p\""), "{json}");

    let o = bg_sim()
        .args(["modes", "--at", "0.05"])
        .arg(model("rlc_series"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("linearised at t = 0.05 s"), "{text}");
    assert!(text.contains("50.329212"), "{text}");
    assert!(text.contains("stiffness ratio"), "{text}");

    let o = bg_sim()
        .args(["modes", "--at=-1"])
        .arg(model("rlc_series"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("from t_start = 0 s on"));
}

/// The crane at t = 0 (default start): 38 states, the fastest mode a bending mode of the
/// knuckle boom, the payload swing's period near 5 s, and no growing mode.
#[test]
fn modes_of_the_crane() {
    let o = bg_sim()
        .arg("modes")
        .arg(model("knuckle_boom"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("38 states"), "{text}");
    assert!(text.contains("steady start `hold`"), "{text}");
    assert!(
        text.contains("slowest lightly damped oscillation: period 4.9"),
        "{text}"
    );
    assert!(!text.contains("grow"), "{text}");
}
