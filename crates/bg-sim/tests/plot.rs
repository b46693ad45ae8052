//! `bg-sim plot` and `bg-sim run --plots`: a model's `[[plot]]` figures and a quick look at
//! columns, as PNG and SVG; a column the results lack is named with the similar ones; bad
//! input is an error, not a panic.
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

fn small_csv(dir: &Path) -> PathBuf {
    let csv = dir.join("r.csv");
    let mut text = String::from("t,l1,l2,F_c1\n");
    for k in 0..=200 {
        let t = f64::from(k) * 0.01;
        let l = 6.0 - 2.4 * (-t).exp();
        text += &format!("{t},{l},{l},{}\n", 5e5 + 1e5 * (3.0 * t).sin());
    }
    std::fs::write(&csv, text).unwrap();
    csv
}

const MODEL: &str = r#"
[elements]
m = { kind = "I", m = 1.0 }
j = { kind = "1" }
[bonds]
b1 = "j -> m"
[[plot]]
file = "lengths"
title = "Lengths"
y_label = "length"
convert = "m->mm"
series = [ { column = "l1", label = "cylinder 1" }, { column = "l2", label = "cylinder 2", dashed = true } ]
[[plot]]
file = "force"
title = "Force"
y_label = "force"
convert = "N->kN"
series = [ { column = "F_c1", label = "cylinder 1" } ]
"#;

#[test]
fn plot_draws_a_models_figures_as_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let csv = small_csv(dir.path());
    let model = dir.path().join("m.toml");
    std::fs::write(&model, MODEL).unwrap();
    let out = dir.path().join("figs");
    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .arg("--model")
        .arg(&model)
        .arg("-o")
        .arg(&out)
        .args(["--format", "both"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let names: Vec<String> = pngs(&out)
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        ["force.png", "force.svg", "lengths.png", "lengths.svg"]
    );
    assert!(is_png(&out.join("force.png")) && is_png(&out.join("lengths.png")));
    let svg = std::fs::read_to_string(out.join("lengths.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("length [mm]") && svg.contains("cylinder 2"));
}

#[test]
fn plot_columns_is_a_quick_look_and_names_a_missing_column() {
    let dir = tempfile::tempdir().unwrap();
    let csv = small_csv(dir.path());
    let out = dir.path().join("look");
    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .args(["--columns", "l1,F_c1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(is_png(&out.join("r.png")));

    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .args(["--columns", "l1,f_c1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("no column `f_c1`") && stderr.contains("did you mean `F_c1`"),
        "{stderr}"
    );

    // a model's plot naming a column the results lack: the model's file and line, the plot
    let model = dir.path().join("m.toml");
    std::fs::write(&model, MODEL.replace("\"F_c1\"", "\"F_c2\"")).unwrap();
    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .arg("--model")
        .arg(&model)
        .arg("--out")
        .arg(dir.path().join("none"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("m.toml:18:")
            && stderr.contains("`force`")
            && stderr.contains("`F_c2`")
            && stderr.contains("did you mean `F_c1`"),
        "{stderr}"
    );
    // nothing drawn: the columns are checked before any figure
    assert!(!dir.path().join("none").exists());
}

#[test]
fn plot_refuses_bad_input_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bad.csv");
    std::fs::write(&csv, "t,l1\n0,6\n0.1,oops\n").unwrap();
    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .args(["--columns", "l1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("bad.csv:3: `oops` is not a number"),
        "{stderr}"
    );

    let o = bg_sim()
        .arg("plot")
        .arg(dir.path().join("missing.csv"))
        .args(["--columns", "l1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read"));

    // neither --model nor --columns: say what to give, and the columns there are
    std::fs::write(&csv, "t,x\n0,1\n1,2\n").unwrap();
    let o = bg_sim().arg("plot").arg(&csv).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("--model") && stderr.contains("t, x"),
        "{stderr}"
    );

    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .args(["--columns", "x", "--format", "pdf"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("png, svg or both"));
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
    assert_eq!(files.len(), 10, "{files:?}");
    assert!(files.iter().all(|p| is_png(p)));
}

/// Every runnable model in `models/`: `run --plots` draws its `[[plot]]` figures as PNG and
/// SVG, and `plot --columns` gives a quick look at the CSV the run wrote.
#[test]
fn every_model_runs_with_its_plots_and_its_csv_can_be_looked_at() {
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&models)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let dir = tempfile::tempdir().unwrap();
    let mut n = 0;
    for model in paths {
        let name = model.file_stem().unwrap().to_string_lossy().into_owned();
        if name == "algebraic_loop" || name == "derivative_causality" {
            continue; // refused by design
        }
        let csv = dir.path().join(format!("{name}.csv"));
        let figs = dir.path().join(&name);
        let o = bg_sim()
            .arg("run")
            .arg(&model)
            .arg("-o")
            .arg(&csv)
            .args(["--quiet", "--plot-format", "both", "--plots"])
            .arg(&figs)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let files = pngs(&figs);
        assert!(files.len() >= 2, "{name}: {files:?}");
        assert_eq!(
            files
                .iter()
                .filter(|p| p.extension().unwrap() == "png")
                .count(),
            files
                .iter()
                .filter(|p| p.extension().unwrap() == "svg")
                .count(),
            "{name}: {files:?}"
        );
        for f in &files {
            if f.extension().unwrap() == "png" {
                assert!(is_png(f), "{}", f.display());
            } else {
                let svg = std::fs::read_to_string(f).unwrap();
                assert!(
                    svg.starts_with("<svg") && svg.contains("<polyline"),
                    "{}",
                    f.display()
                );
            }
        }
        // a quick look at (up to) the first four columns after t
        let header = std::fs::read_to_string(&csv).unwrap();
        let columns: Vec<&str> = header
            .lines()
            .next()
            .unwrap()
            .split(',')
            .skip(1)
            .take(4)
            .collect();
        let look = dir.path().join("look");
        let o = bg_sim()
            .arg("plot")
            .arg(&csv)
            .arg("--columns")
            .arg(columns.join(","))
            .arg("-o")
            .arg(&look)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(is_png(&look.join(format!("{name}.png"))), "{name}");
        n += 1;
    }
    assert!(n >= 7, "only {n} models");
}

/// Run `cmd`, killing it after `secs` seconds: `None` if it had to be killed (a hang).
fn within(cmd: &mut Command, secs: u64) -> Option<std::process::Output> {
    let mut child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while start.elapsed().as_secs() < secs {
        if child.try_wait().unwrap().is_some() {
            return Some(child.wait_with_output().unwrap());
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

/// Issue 24, item 6: a column (or the t column) holding 1e308 and −1e308 has a range no f64
/// holds; plotters looped forever over it. Now each such figure is drawn (the axis held
/// within ±1e306, the values beyond it at its edge), as are columns of NaN, ±inf and a
/// single repeated ±1e308.
#[test]
fn plot_of_ranges_that_overflow_f64_is_drawn_not_a_hang() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("y", "t,y\n0,1e308\n1,-1e308\n2,0\n"),
        ("t", "t,y\n1e308,1\n-1e308,2\n0,3\n"),
        ("both", "t,y\n-1e308,1e308\n1e308,-1e308\n"),
        ("nonfinite", "t,y\n0,NaN\n1,inf\n2,-inf\n"),
        ("huge_constant", "t,y\n1e308,1.7e308\n1e308,1.7e308\n"),
        ("tiny", "t,y\n0,5e-324\n1e-320,-5e-324\n"),
    ];
    for (name, text) in cases {
        let csv = dir.path().join(format!("{name}.csv"));
        std::fs::write(&csv, text).unwrap();
        let out = dir.path().join(name);
        let o = within(
            bg_sim()
                .arg("plot")
                .arg(&csv)
                .args(["--columns", "y", "--format", "both", "-o"])
                .arg(&out),
            60,
        )
        .unwrap_or_else(|| panic!("{name}: `bg-sim plot` still running after 60 s"));
        assert_eq!(
            o.status.code(),
            Some(0),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(is_png(&out.join(format!("{name}.png"))), "{name}");
        let svg = std::fs::read_to_string(out.join(format!("{name}.svg"))).unwrap();
        assert!(
            svg.len() < 2_000_000,
            "{name}: an SVG of {} bytes",
            svg.len()
        );
    }
}

/// Issue 24, item 10: a big CSV is read line by line, for the columns drawn only, and a curve
/// of more than `PLOT_ROWS` rows is decimated (each bucket of rows keeps its first, last,
/// smallest and largest values) — before, the whole text and every column were held (a
/// 310 MB CSV of the crane peaked at 432 MB resident, 64 MB after) and every row drawn. At a
/// smaller scale: 250 001 rows give an SVG curve of at most 100 000 points, the run says so,
/// and a one-row spike survives.
#[test]
fn plot_of_a_big_csv_draws_a_bounded_number_of_points_and_keeps_the_peaks() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("big.csv");
    let n = 250_001;
    let mut text = String::with_capacity(n * 40);
    text.push_str("t,y,unused\n");
    for k in 0..n {
        let t = k as f64 * 1e-4;
        let y = if k == 123_457 { 50.0 } else { (40.0 * t).sin() };
        text += &format!("{t},{y},{k}\n");
    }
    std::fs::write(&csv, text).unwrap();
    let out = dir.path().join("out");
    let o = bg_sim()
        .arg("plot")
        .arg(&csv)
        .args(["--columns", "y", "--format", "svg", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("250001 rows: drawn from") && err.contains("smallest and largest"),
        "{err}"
    );
    let svg = std::fs::read_to_string(out.join("big.svg")).unwrap();
    let points: Vec<(f64, f64)> = svg
        .split("<polyline")
        .skip(1)
        .filter_map(|p| {
            let at = p.find("points=\"")? + 8;
            Some(&p[at..at + p[at..].find('"')?])
        })
        .max_by_key(|p| p.len())
        .unwrap()
        .split_whitespace()
        .map(|xy| {
            let (x, y) = xy.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect();
    assert!(
        points.len() > 1000 && points.len() <= bg_sim::plot::PLOT_ROWS,
        "{} points drawn",
        points.len()
    );
    // the spike (50, where the sine stays within ±1) is the curve's highest point, far above
    // the rest: at least 90 % of the curve's pixel height above the sine's top
    let top = points.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    let bottom = points.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let spike = points
        .iter()
        .filter(|p| p.1 < top + 0.9 * (bottom - top))
        .count();
    assert!((1..=3).contains(&spike), "{spike} points near the top");
}
