//! `bg-sim sweep` (many runs in parallel, one summary row each, [`bg_sim::sweep`]) and
//! `bg-sim sweep-plot` (one summary column over two swept parameters as contours).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_sim::registry;

use super::{interrupt_on_signals, BAD_INPUT, FAILED};

/// The options of `bg-sim sweep` (its summary is on `Command::Sweep` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// The sweep spec: [parameters] to vary, [metrics] to keep, [sweep] design.
    #[arg(long, value_name = "SWEEP.toml")]
    pub spec: PathBuf,
    /// Worker threads (default: one per core).
    #[arg(short, long, default_value_t = 0)]
    pub jobs: usize,
    /// Output folder for summary.csv (and runs/ with keep_runs).
    #[arg(short, long, default_value = "out/sweep")]
    pub output: PathBuf,
}

/// The options of `bg-sim sweep-plot` (its summary is on `Command::SweepPlot` in main.rs).
#[derive(clap::Args)]
pub struct PlotArgs {
    /// The summary.csv of `bg-sim sweep`.
    pub summary: PathBuf,
    /// The column along x (a swept parameter, e.g. parameters.m3).
    #[arg(long)]
    pub x: String,
    /// The column along y.
    #[arg(long)]
    pub y: String,
    /// The column to map (a metric).
    #[arg(long)]
    pub z: String,
    /// Divide x, y and z by these factors for the labels (e.g. 1000 for t, kN).
    #[arg(long, value_delimiter = ',', default_value = "1,1,1")]
    pub scale: Vec<f64>,
    /// Axis labels x,y,z (default: the column names).
    #[arg(long, value_delimiter = ',')]
    pub labels: Option<Vec<String>>,
    /// Title.
    #[arg(long, default_value = "")]
    pub title: String,
    /// The PNG to write.
    #[arg(short, long, default_value = "out/sweep.png")]
    pub output: PathBuf,
}

/// `bg-sim sweep`.
pub fn command(a: Args) -> ExitCode {
    let Args {
        model,
        spec,
        jobs,
        output,
    } = a;
    sweep(&model, &spec, jobs, output)
}

/// `bg-sim sweep-plot`.
pub fn plot_command(a: &PlotArgs) -> ExitCode {
    let PlotArgs {
        summary,
        x,
        y,
        z,
        scale,
        labels,
        title,
        output,
    } = a;
    sweep_plot(summary, [x, y, z], scale, labels.as_deref(), title, output)
}

fn sweep(model: &Path, spec: &Path, jobs: usize, out_dir: PathBuf) -> ExitCode {
    use bg_sim::sweep::{parse_spec, sweep, Options};
    let shown = spec.display().to_string();
    let parsed = regular(spec)
        .and_then(|()| std::fs::read_to_string(spec).map_err(|e| format!("{shown}: {e}")))
        .and_then(|t| parse_spec(&shown, &t).map_err(|e| e.to_string()));
    let spec = match parsed {
        Ok(s) => s,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    let opts = Options {
        jobs,
        out_dir,
        interrupt: Some(interrupt_on_signals()),
    };
    match sweep(model, &spec, registry, &opts) {
        Ok(s) => {
            say!(
                "{} runs: {} done now ({} ok, {} not ok), {} already in the summary{}",
                s.total,
                s.ok + s.not_ok,
                s.ok,
                s.not_ok,
                s.skipped,
                if s.interrupted > 0 {
                    format!(
                        ", {} left by an interrupt (run again to resume)",
                        s.interrupted
                    )
                } else {
                    String::new()
                }
            );
            say!(
                "wall time {:.3} s; the runs' own times add up to {:.3} s ({:.2}× on {} threads)",
                s.wall_s,
                s.run_s,
                if s.wall_s > 0.0 {
                    s.run_s / s.wall_s
                } else {
                    0.0
                },
                rayon_threads(jobs)
            );
            say!("summary: {}", s.path.display());
            for f in &s.band {
                say!("band: {}", f.display());
            }
            if s.interrupted > 0 || s.not_ok > 0 {
                ExitCode::from(FAILED)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
    }
}

fn sweep_plot(
    summary: &Path,
    cols: [&String; 3],
    scale: &[f64],
    labels: Option<&[String]>,
    title: &str,
    output: &Path,
) -> ExitCode {
    match sweep_map(summary, cols, scale) {
        Ok(map) => {
            let name = |k: usize| {
                labels
                    .and_then(|l| l.get(k))
                    .map_or(cols[k].as_str(), String::as_str)
            };
            match bg_sim::plot::contour(title, (name(0), name(1), name(2)), &map, output) {
                Ok(p) => {
                    say!("wrote {}", p.display());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    tell!("error: {e}");
                    ExitCode::from(FAILED)
                }
            }
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
    }
}

/// The grid of one summary column over two others; runs whose value is empty are `None`.
fn sweep_map(
    summary: &Path,
    cols: [&String; 3],
    scale: &[f64],
) -> Result<bg_sim::plot::Map, String> {
    regular(summary)?;
    let (head, rows) = bg_sim::sweep::read_summary(summary).map_err(|e| e.to_string())?;
    let mut idx = [0usize; 3];
    for (k, c) in cols.iter().enumerate() {
        idx[k] = head.iter().position(|h| h == *c).ok_or_else(|| {
            format!(
                "{}: no column `{c}`; columns: {}",
                summary.display(),
                head.join(", ")
            )
        })?;
    }
    if scale.len() != 3 || scale.iter().any(|s| !s.is_finite() || *s == 0.0) {
        return Err("--scale takes three finite, non-zero factors: x,y,z".into());
    }
    let num = |r: &[String], k: usize| r.get(idx[k]).and_then(|v| v.parse::<f64>().ok());
    let axis = |k: usize| {
        let mut v: Vec<f64> = rows.iter().filter_map(|r| num(r, k)).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let (xs, ys) = (axis(0), axis(1));
    let mut z = vec![vec![None; ys.len()]; xs.len()];
    for r in &rows {
        if let (Some(x), Some(y), v) = (num(r, 0), num(r, 1), num(r, 2)) {
            let i = xs.partition_point(|&a| a < x);
            let j = ys.partition_point(|&a| a < y);
            z[i][j] = v.map(|v| v / scale[2]);
        }
    }
    Ok(bg_sim::plot::Map {
        x: xs.iter().map(|v| v / scale[0]).collect(),
        y: ys.iter().map(|v| v / scale[1]).collect(),
        z,
    })
}

fn rayon_threads(jobs: usize) -> usize {
    if jobs > 0 {
        jobs
    } else {
        std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
    }
}

/// Err if `path` is a FIFO, a socket, a directory or a device: a FIFO without a writer
/// blocked `read_to_string` for ever (issue 24, item 10).
fn regular(path: &Path) -> Result<(), String> {
    match bg_sim::plot::not_a_regular_file(path) {
        None => Ok(()),
        Some(what) => Err(format!(
            "{}: cannot read: it is {what}, not a file\n  hint: write piped text to a file first",
            path.display()
        )),
    }
}
