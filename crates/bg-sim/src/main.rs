//! `bg-sim`: run and check bond-graph model files. No physics lives here: the CLI loads a
//! model through `bg-model`, runs it through `bondgraph`, and writes the results.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

use bg_model::{inspect, Model};
use bg_sim::plot::{work_precision, Results, WorkPrecisionLine};
use bg_sim::registry;
use bondgraph::{Method, RowSink, SimulationError};
use clap::{Parser, Subcommand};

/// The first error writing to stdout (a closed pipe, a full disk). The report is lost, not
/// the run: the CSV is still written and the checks still decide the exit status.
static STDOUT_ERROR: Mutex<Option<std::io::ErrorKind>> = Mutex::new(None);

/// Write one line to stdout (`to_stderr`: stderr) without ever panicking.
fn emit(to_stderr: bool, args: std::fmt::Arguments<'_>) {
    let written = if to_stderr {
        let mut e = std::io::stderr().lock();
        e.write_fmt(args).and_then(|()| e.write_all(b"\n"))
    } else {
        let mut o = std::io::stdout().lock();
        o.write_fmt(args).and_then(|()| o.write_all(b"\n"))
    };
    if let (Err(e), false) = (written, to_stderr) {
        if let Ok(mut first) = STDOUT_ERROR.lock() {
            first.get_or_insert(e.kind());
        }
    }
}

/// `println!` that never panics.
macro_rules! say {
    ($($arg:tt)*) => { emit(false, format_args!($($arg)*)) };
}

/// `eprintln!` that never panics.
macro_rules! tell {
    ($($arg:tt)*) => { emit(true, format_args!($($arg)*)) };
}

#[derive(Parser)]
#[command(
    name = "bg-sim",
    version,
    about = "Simulate port-based bond graphs described in TOML model files"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a model and write its results as CSV.
    Run {
        /// The model file.
        model: PathBuf,
        /// Output CSV (default: out/<model name>.csv).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Integration method: bdf, esdirk34, tr-bdf2 or tsit45.
        #[arg(long)]
        solver: Option<String>,
        /// Relative tolerance.
        #[arg(long)]
        rtol: Option<f64>,
        /// Absolute tolerance (scaled per state by its nominal magnitude).
        #[arg(long)]
        atol: Option<f64>,
        /// End time (s).
        #[arg(long)]
        t_end: Option<f64>,
        /// Output interval (s).
        #[arg(long)]
        dt_out: Option<f64>,
        /// Override a value of the model file: --set parameters.k=5 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Print only errors.
        #[arg(short, long)]
        quiet: bool,
        /// Also draw the model's `[[plot]]` figures from the results into this folder.
        #[arg(long, value_name = "DIR")]
        plots: Option<PathBuf>,
        /// Format of those figures: png, svg or both.
        #[arg(long, value_name = "FORMAT", default_value = "png")]
        plot_format: String,
    },
    /// Run a model many times over a grid or a Latin-hypercube sample of values, in
    /// parallel, and write one summary row per run (docs/sweeps.md). Started again on the
    /// same folder, it skips the runs already done.
    Sweep {
        /// The model file.
        model: PathBuf,
        /// The sweep spec: [parameters] to vary, [metrics] to keep, [sweep] design.
        #[arg(long, value_name = "SWEEP.toml")]
        spec: PathBuf,
        /// Worker threads (default: one per core).
        #[arg(short, long, default_value_t = 0)]
        jobs: usize,
        /// Output folder for summary.csv (and runs/ with keep_runs).
        #[arg(short, long, default_value = "out/sweep")]
        output: PathBuf,
    },
    /// Draw one column of a sweep's summary over two swept parameters as filled contours
    /// (PNG); runs without a value are crosses.
    SweepPlot {
        /// The summary.csv of `bg-sim sweep`.
        summary: PathBuf,
        /// The column along x (a swept parameter, e.g. parameters.m3).
        #[arg(long)]
        x: String,
        /// The column along y.
        #[arg(long)]
        y: String,
        /// The column to map (a metric).
        #[arg(long)]
        z: String,
        /// Divide x, y and z by these factors for the labels (e.g. 1000 for t, kN).
        #[arg(long, value_delimiter = ',', default_value = "1,1,1")]
        scale: Vec<f64>,
        /// Axis labels x,y,z (default: the column names).
        #[arg(long, value_delimiter = ',')]
        labels: Option<Vec<String>>,
        /// Title.
        #[arg(long, default_value = "")]
        title: String,
        /// The PNG to write.
        #[arg(short, long, default_value = "out/sweep.png")]
        output: PathBuf,
    },
    /// Check a model: list elements, bonds with causal strokes, states and problems.
    Check {
        /// The model file.
        model: PathBuf,
        /// Override a value of the model file (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Draw a model's bond graph as SVG (or Graphviz DOT): element symbols, half-arrows,
    /// causal strokes, signals; composites as one box each unless --expand (docs/graph.md).
    Graph {
        /// The model file.
        model: PathBuf,
        /// Output file (default: out/<model name>.svg, or .dot).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Draw the members of every composite inside a frame instead of one box.
        #[arg(long)]
        expand: bool,
        /// svg or dot (default: from the extension of --output, else svg).
        #[arg(long, value_enum)]
        format: Option<bg_sim::graph::Format>,
        /// Override a value of the model file (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// List the element kinds a model file can use, or describe one: its ports, parameters
    /// (units, defaults, ranges), states and published signals.
    Kinds {
        /// A kind to describe in full (`hydraulics.chamber`).
        name: Option<String>,
    },
    /// The model's time scales: linearise at the initial state (or at time T of a run) and
    /// list every eigenvalue as frequency, damping ratio and time constant with the states
    /// that take part in it, the stiffness ratio and what it means for the solver.
    Modes {
        /// The model file.
        model: PathBuf,
        /// Linearise at this time of a run (s) instead of the initial state.
        #[arg(long, value_name = "T")]
        at: Option<f64>,
        /// Override a value of the model file (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Write JSON (for scripts) instead of the table.
        #[arg(long)]
        json: bool,
        /// Dominant states named per mode (those with a participation of at least 5 %).
        #[arg(long, default_value_t = 3)]
        top: usize,
    },
    /// Measure the speed–accuracy trade: every solver at every rtol against a reference
    /// (wall time, steps, rhs evaluations, the worst scaled error of the scored columns).
    Bench {
        /// The model file.
        model: PathBuf,
        /// Solvers, comma-separated.
        #[arg(long, default_value = "bdf,esdirk34,tr-bdf2", value_delimiter = ',')]
        solvers: Vec<String>,
        /// Relative tolerances, comma-separated.
        #[arg(long, default_value = "1e-4,1e-6,1e-8", value_delimiter = ',')]
        rtols: Vec<f64>,
        /// A results CSV to score against (e.g. `bg-sim run --rtol 1e-10`); without it, a
        /// BDF run at --reference-rtol is the reference.
        #[arg(long, value_name = "REF.csv")]
        reference: Option<PathBuf>,
        /// Relative tolerance of the reference run (when no --reference is given).
        #[arg(long, default_value_t = 1e-10)]
        reference_rtol: f64,
        /// Columns to score, comma-separated (default: every column of the reference).
        #[arg(long, value_delimiter = ',')]
        columns: Option<Vec<String>>,
        /// Error floor of the columns matching PATTERN (`*` matches any text), repeatable:
        /// --floor 'qb*=1e-3'. By default a column's floor is 1 % of the largest scale among
        /// the columns of its quantity.
        #[arg(long = "floor", value_name = "PATTERN=VALUE")]
        floors: Vec<String>,
        /// Also draw the work–precision diagram (error vs wall time per method) as PNG.
        #[arg(long, value_name = "FILE.png")]
        plot: Option<PathBuf>,
        /// Only time the right-hand side (µs per call) and the Jacobian; no runs.
        #[arg(long)]
        rhs: bool,
        /// Runs per configuration (the median wall time is reported).
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        /// End time (s), shorter than the model's for a quick look.
        #[arg(long)]
        t_end: Option<f64>,
        /// Override a value of the model file (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Find the cheapest scene of the model's `[scene]` switches whose scaled error against
    /// the richest scene stays within --tol on the named columns.
    Reduce {
        /// The model file (with a `[scene]` table).
        model: PathBuf,
        /// Largest scaled error of the scored columns (as in `bench`: |x − x_ref| / scale).
        #[arg(long)]
        tol: f64,
        /// Columns to score, comma-separated (default: every output column).
        #[arg(long, value_delimiter = ',')]
        columns: Option<Vec<String>>,
        /// End time (s), shorter than the model's.
        #[arg(long)]
        t_end: Option<f64>,
        /// Solver of every run (default: the model's).
        #[arg(long)]
        solver: Option<String>,
        /// Relative tolerance of every run (default: the model's).
        #[arg(long)]
        rtol: Option<f64>,
        /// Search: auto (the grid up to 400 scenes, else greedy), grid or greedy.
        #[arg(long, default_value = "auto")]
        search: String,
        /// Scenes run side by side (default: the number of cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Runs of the reference and of the answer, timed alone (median).
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        /// Error floor of the columns matching PATTERN, repeatable (as for `bench`).
        #[arg(long = "floor", value_name = "PATTERN=VALUE")]
        floors: Vec<String>,
        /// Fixed scale of the columns matching PATTERN, repeatable: --scale 'x_e3=1' scores
        /// x_e3 in its own unit (an error of 1e-3 is 1 mm).
        #[arg(long = "scale", value_name = "PATTERN=VALUE")]
        scales: Vec<String>,
        /// Also write every scene's error per column to this CSV.
        #[arg(long, value_name = "FILE.csv")]
        csv: Option<PathBuf>,
        /// Override a value of the model file before every scene's (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Compare a results CSV with a reference CSV, column by column, with the scaled error
    /// of `bench` (|run − reference| / max(range, |mean|, quantity floor)).
    Compare {
        /// The results to score.
        results: PathBuf,
        /// The reference results (same time span).
        reference: PathBuf,
        /// Columns to score, comma-separated (default: every column of the reference).
        #[arg(long, value_delimiter = ',')]
        columns: Option<Vec<String>>,
        /// Error floor of the columns matching PATTERN, repeatable (as for `bench`).
        #[arg(long = "floor", value_name = "PATTERN=VALUE")]
        floors: Vec<String>,
    },
    /// Draw a model's `[[plot]]` figures from a results CSV (--model), or a quick look at
    /// some of its columns, one panel each (--columns), as PNG and/or SVG.
    Plot {
        /// A CSV written by `bg-sim run`.
        results: PathBuf,
        /// The model file whose `[[plot]]` tables to draw.
        #[arg(short, long, value_name = "MODEL.toml")]
        model: Option<PathBuf>,
        /// Draw these columns instead, comma-separated, one panel each.
        #[arg(long, value_delimiter = ',', conflicts_with = "model")]
        columns: Option<Vec<String>>,
        /// Folder for the figures (created if needed).
        #[arg(
            short = 'o',
            long = "out",
            visible_alias = "output",
            default_value = "out/plots"
        )]
        out: PathBuf,
        /// png, svg or both.
        #[arg(long, default_value = "png")]
        format: String,
    },
}

/// Exit statuses (README, "Exit status").
const BAD_INPUT: u8 = 2;
const FAILED: u8 = 1;

fn main() -> ExitCode {
    let cli = Cli::parse();
    // For these commands the report on stdout is the product: losing it is a failure.
    let stdout_is_product = matches!(
        cli.command,
        Command::Kinds { .. }
            | Command::Check { .. }
            | Command::Compare { .. }
            | Command::Modes { .. }
    );
    let code = dispatch(cli.command);
    let lost = STDOUT_ERROR.lock().ok().and_then(|e| *e);
    match lost {
        // the reader went away (`| head`): what it read is what it wanted
        None | Some(std::io::ErrorKind::BrokenPipe) => code,
        Some(kind) => {
            tell!("warning: the report on stdout is incomplete: {kind}");
            if stdout_is_product && code == ExitCode::SUCCESS {
                ExitCode::from(FAILED)
            } else {
                code
            }
        }
    }
}

fn dispatch(command: Command) -> ExitCode {
    match command {
        Command::Run {
            model,
            output,
            solver,
            rtol,
            atol,
            t_end,
            dt_out,
            set,
            quiet,
            plots,
            plot_format,
        } => {
            let (code, written) = run(
                &model,
                output,
                solver.as_deref(),
                rtol,
                atol,
                t_end,
                dt_out,
                &set,
                quiet,
            );
            match (plots, written) {
                (Some(dir), Some(csv)) => match plot(
                    &csv,
                    PlotWhat::Model(&model, &set),
                    &dir,
                    &plot_format,
                    quiet,
                ) {
                    ExitCode::SUCCESS => code,
                    failed => failed,
                },
                _ => code,
            }
        }
        Command::Check { model, set } => check(&model, &set),
        Command::Graph {
            model,
            output,
            expand,
            format,
            set,
        } => graph(&model, output.as_deref(), expand, format, &set),
        Command::Modes {
            model,
            at,
            set,
            json,
            top,
        } => modes(&model, at, &set, json, top),
        Command::SweepPlot {
            summary,
            x,
            y,
            z,
            scale,
            labels,
            title,
            output,
        } => sweep_plot(
            &summary,
            [&x, &y, &z],
            &scale,
            labels.as_deref(),
            &title,
            &output,
        ),
        Command::Sweep {
            model,
            spec,
            jobs,
            output,
        } => sweep(&model, &spec, jobs, output),
        Command::Kinds { name: None } => {
            say!("{}", bg_sim::kinds::list(&registry()).trim_end());
            ExitCode::SUCCESS
        }
        Command::Kinds { name: Some(name) } => match bg_sim::kinds::report(&registry(), &name) {
            Ok(text) => {
                say!("{}", text.trim_end());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
        Command::Plot {
            results,
            model,
            columns,
            out,
            format,
        } => {
            let what = match (&model, &columns) {
                (Some(m), _) => PlotWhat::Model(m, &[]),
                (None, Some(c)) => PlotWhat::Columns(c),
                (None, None) => PlotWhat::Nothing,
            };
            plot(&results, what, &out, &format, false)
        }
        Command::Compare {
            results,
            reference,
            columns,
            floors,
        } => compare(&results, &reference, columns.as_deref(), &floors),
        Command::Reduce {
            model,
            tol,
            columns,
            t_end,
            solver,
            rtol,
            search,
            jobs,
            repeat,
            floors,
            scales,
            csv,
            set,
        } => {
            let Some(floors) = parse_floors(&floors) else {
                return ExitCode::from(BAD_INPUT);
            };
            let Some(scales) = parse_floors(&scales) else {
                return ExitCode::from(BAD_INPUT);
            };
            let Some(search) = bg_sim::reduce::Search::parse(&search) else {
                tell!("error: unknown search `{search}`\n  hint: auto, grid or greedy");
                return ExitCode::from(BAD_INPUT);
            };
            let method = match solver.as_deref().map(bg_model::solver).transpose() {
                Ok(m) => m,
                Err(e) => {
                    tell!("error: {e}\n  hint: {}", e.hint());
                    return ExitCode::from(BAD_INPUT);
                }
            };
            let mut o = bg_sim::reduce::ReduceOptions::new(tol);
            o.columns = columns;
            o.t_end = t_end;
            o.method = method;
            o.rtol = rtol;
            o.search = search;
            if let Some(j) = jobs {
                o.jobs = j.max(1);
            }
            o.repeat = repeat;
            o.floors = floors;
            o.scales = scales;
            o.set = set;
            reduce(&model, &o, csv.as_deref())
        }
        Command::Bench {
            model,
            solvers,
            rtols,
            reference,
            reference_rtol,
            columns,
            floors,
            plot,
            rhs,
            repeat,
            t_end,
            set,
        } => bench(&BenchArgs {
            path: &model,
            solvers: &solvers,
            rtols: &rtols,
            reference: reference.as_deref(),
            reference_rtol,
            columns: columns.as_deref(),
            floors: &floors,
            plot: plot.as_deref(),
            rhs_only: rhs,
            repeat,
            t_end,
            set: &set,
        }),
    }
}

fn graph(
    model: &Path,
    out: Option<&Path>,
    expand: bool,
    format: Option<bg_sim::graph::Format>,
    set: &[String],
) -> ExitCode {
    match bg_sim::graph::write(model, out, expand, format, set) {
        Ok(w) => {
            if let Some(p) = &w.problem {
                tell!("note: drawn without causal strokes: {p}");
            }
            say!("{} nodes, {} bonds: {}", w.nodes, w.bonds, w.path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
    }
}

fn sweep(model: &Path, spec: &Path, jobs: usize, out_dir: PathBuf) -> ExitCode {
    use bg_sim::sweep::{parse_spec, sweep, Options};
    let shown = spec.display().to_string();
    let parsed = std::fs::read_to_string(spec)
        .map_err(|e| format!("{shown}: {e}"))
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

struct BenchArgs<'a> {
    path: &'a Path,
    solvers: &'a [String],
    rtols: &'a [f64],
    reference: Option<&'a Path>,
    reference_rtol: f64,
    columns: Option<&'a [String]>,
    floors: &'a [String],
    plot: Option<&'a Path>,
    rhs_only: bool,
    repeat: usize,
    t_end: Option<f64>,
    set: &'a [String],
}

fn bench(a: &BenchArgs<'_>) -> ExitCode {
    use bg_sim::bench::{bench, reference_run, rhs_cost, table, Reference};
    let mut model = match Model::load(a.path, &registry(), a.set) {
        Ok(m) => m,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(2);
        }
    };
    if a.rhs_only {
        let c = rhs_cost(&model, 20_000);
        say!(
            "{}: {} states; rhs {:.3} µs per call, Jacobian {:.3} µs per call ({:.1} rhs-equivalents; medians of 7 samples)",
            model.file(),
            c.n,
            c.rhs_us,
            c.jacobian_us,
            c.jacobian_us / c.rhs_us
        );
        return ExitCode::SUCCESS;
    }
    let mut methods = Vec::new();
    for s in a.solvers {
        match bg_model::solver(s) {
            Ok(m) => methods.push(m),
            Err(e) => {
                tell!("error: {e}\n  hint: {}", e.hint());
                return ExitCode::from(2);
            }
        }
    }
    let Some(floors) = parse_floors(a.floors) else {
        return ExitCode::from(2);
    };
    if let Some(t) = a.t_end {
        model.settings.t_end = t;
    }
    for &r in a.rtols.iter().chain(std::iter::once(&a.reference_rtol)) {
        model.settings.rtol = r;
        if let Err(e) = model.settings.validate() {
            tell!("error: {e}");
            return ExitCode::from(2);
        }
    }
    let reference = match a.reference {
        Some(p) => Reference::read(p, a.columns, &floors).map(|r| (format!("{}", p.display()), r)),
        None => reference_run(
            &mut model,
            Method::Bdf,
            a.reference_rtol,
            a.columns,
            &floors,
        )
        .map(|(o, r)| {
            (
                format!("bdf at rtol {:e}: {}", a.reference_rtol, o.stats),
                r,
            )
        }),
    };
    let (what, reference) = match reference {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(2);
        }
    };
    say!(
        "{}: {} states, 0 → {} s; reference {what}; {} columns scored",
        model.file(),
        model.equations.n_states(),
        model.settings.t_end,
        reference.columns.len()
    );
    match bench(&mut model, &methods, a.rtols, &reference, a.repeat) {
        Ok(rows) => {
            say!("{}", table(&rows).trim_end_matches('\n'));
            if let Some(png) = a.plot {
                let lines: Vec<WorkPrecisionLine> = methods
                    .iter()
                    .map(|m| WorkPrecisionLine {
                        label: m.name().to_owned(),
                        points: rows
                            .iter()
                            .filter(|r| r.method == *m)
                            .filter_map(|r| {
                                r.error
                                    .as_ref()
                                    .map(|(e, _)| (r.wall.as_secs_f64() * 1e3, *e))
                            })
                            .collect(),
                    })
                    .collect();
                let title = format!(
                    "{}: work–precision",
                    model.title.as_deref().unwrap_or(model.file())
                );
                match work_precision(&title, &lines, png) {
                    Ok(p) => say!("wrote {}", p.display()),
                    Err(e) => {
                        tell!("error: {e}");
                        return ExitCode::from(1);
                    }
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(1)
        }
    }
}

fn reduce(path: &Path, o: &bg_sim::reduce::ReduceOptions, csv: Option<&Path>) -> ExitCode {
    let r = match bg_sim::reduce::reduce(path, o) {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    say!(
        "{}: {} switches, {} scenes in the grid; {} search, {} scenes run on {} threads; tol {:e}",
        path.display(),
        r.scene.switches.len(),
        r.scene.grid_size(),
        r.search.name(),
        r.tried.len(),
        o.jobs,
        r.tol
    );
    say!("{}", r.table().trim_end_matches('\n'));
    let a = r.answer();
    if r.answer == 0 {
        let passed = (1..r.tried.len())
            .filter(|&i| r.tried[i].passes(r.tol))
            .count();
        say!(
            "answer: the richest scene, {}: of the {} cheaper scenes tried, {passed} stay within {:e} and none of them runs faster",
            a.label,
            r.tried.len() - 1,
            r.tol
        );
    } else {
        let (col, err) = a.worst().unwrap_or(("?", f64::NAN));
        say!(
            "answer: {} (worst {col} {err:.2e} ≤ {:e}); {:.1} ms against {:.1} ms for the richest scene ({}), {:.1}× faster (each the median of {} runs alone)",
            a.label,
            r.tol,
            r.answer_wall.as_secs_f64() * 1e3,
            r.reference_wall.as_secs_f64() * 1e3,
            r.tried[0].label,
            r.speedup(),
            o.repeat.max(1)
        );
        // quoted for a shell where a value is a TOML string
        let sets: Vec<String> = r
            .scene
            .overrides(&a.pick)
            .into_iter()
            .map(|o| {
                if o.contains(['"', ' ', '\'']) {
                    format!("'{}'", o.replace('\'', "'\\''"))
                } else {
                    o
                }
            })
            .collect();
        say!("  --set {}", sets.join(" --set "));
    }
    if let Some(p) = csv {
        if let Err(e) = std::fs::write(p, r.csv()) {
            tell!("error: cannot write {}: {e}", p.display());
            return ExitCode::from(BAD_INPUT);
        }
        say!("wrote {}", p.display());
    }
    ExitCode::SUCCESS
}

/// `--floor PATTERN=VALUE` arguments, or `None` after printing why one is refused.
fn parse_floors(args: &[String]) -> Option<Vec<(String, f64)>> {
    let mut floors = Vec::new();
    for f in args {
        match f
            .split_once('=')
            .map(|(p, v)| (p.trim(), v.trim().parse::<f64>()))
        {
            Some((p, Ok(v))) if !p.is_empty() && v.is_finite() && v >= 0.0 => {
                floors.push((p.to_owned(), v));
            }
            _ => {
                tell!("error: --floor `{f}`: expected PATTERN=VALUE with a finite VALUE ≥ 0\n  hint: --floor 'qb*=1e-3'");
                return None;
            }
        }
    }
    Some(floors)
}

fn compare(
    results: &Path,
    reference: &Path,
    columns: Option<&[String]>,
    floors: &[String],
) -> ExitCode {
    let Some(floors) = parse_floors(floors) else {
        return ExitCode::from(2);
    };
    let scored = bg_sim::bench::Reference::read(reference, columns, &floors).and_then(|r| {
        let run = Results::read(results)
            .map_err(|e| e.to_string())?
            .to_trajectory();
        let errors = r.errors(&run).ok_or_else(|| {
            format!(
                "{} does not cover the time span of {} or lacks one of its columns",
                results.display(),
                reference.display()
            )
        })?;
        Ok((r, errors))
    });
    match scored {
        Ok((r, errors)) => {
            say!("| column | scale | scaled error |\n|---|---|---|");
            for ((name, e), (_, _, scale)) in errors.iter().zip(&r.columns) {
                say!("| {name} | {scale:.4e} | {e:.3e} |");
            }
            if let Some((name, e)) = errors.iter().max_by(|a, b| a.1.total_cmp(&b.1)) {
                say!("worst: {name} {e:.3e}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// What `plot` draws.
enum PlotWhat<'a> {
    /// The `[[plot]]` tables of this model (with these `--set` overrides).
    Model(&'a Path, &'a [String]),
    /// A quick look at these columns.
    Columns(&'a [String]),
    /// Nothing was asked for.
    Nothing,
}

fn plot(results: &Path, what: PlotWhat<'_>, dir: &Path, format: &str, quiet: bool) -> ExitCode {
    use bg_sim::plot::{draw, draw_all, quick_look, Format};
    let Some(format) = Format::parse(format) else {
        tell!("error: --format {format}: expected png, svg or both");
        return ExitCode::from(BAD_INPUT);
    };
    let table = match Results::read(results) {
        Ok(t) => t,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    let drawn = match what {
        PlotWhat::Model(path, set) => {
            let model = match Model::load(path, &registry(), set) {
                Ok(m) => m,
                Err(e) => {
                    tell!("error: {e}");
                    return ExitCode::from(BAD_INPUT);
                }
            };
            if model.plots().is_empty() {
                tell!(
                    "error: {} has no [[plot]] tables\n  hint: add one (docs/model-format.md, section Plots), or look at columns with `bg-sim plot {} --columns a,b`",
                    path.display(),
                    results.display()
                );
                return ExitCode::from(FAILED);
            }
            draw_all(&table, model.plots(), model.file(), dir, format)
        }
        PlotWhat::Columns(columns) => {
            let stem = results.file_stem().map_or_else(
                || "columns".to_owned(),
                |s| s.to_string_lossy().into_owned(),
            );
            quick_look(&table, results, &stem, columns).and_then(|p| {
                std::fs::create_dir_all(dir).map_err(|source| bg_sim::plot::PlotError::Dir {
                    path: dir.to_path_buf(),
                    source,
                })?;
                draw(&table, &p, dir, format)
            })
        }
        PlotWhat::Nothing => {
            tell!(
                "error: say what to draw: --model MODEL.toml (its [[plot]] tables) or --columns a,b (a quick look)\n  hint: {} has the columns {}",
                results.display(),
                table.names().join(", ")
            );
            return ExitCode::from(BAD_INPUT);
        }
    };
    match drawn {
        Ok(files) => {
            if !quiet {
                for f in &files {
                    say!("wrote {}", f.display());
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn run(
    path: &Path,
    output: Option<PathBuf>,
    solver: Option<&str>,
    rtol: Option<f64>,
    atol: Option<f64>,
    t_end: Option<f64>,
    dt_out: Option<f64>,
    set: &[String],
    quiet: bool,
) -> (ExitCode, Option<PathBuf>) {
    let refuse = |m: String| {
        tell!("error: {m}");
        (ExitCode::from(BAD_INPUT), None)
    };
    let mut model = match Model::load(path, &registry(), set) {
        Ok(m) => m,
        Err(e) => return refuse(e.to_string()),
    };
    if let Some(s) = solver {
        match bg_model::solver(s) {
            Ok(m) => model.settings.method = m,
            Err(e) => return refuse(format!("{e}\n  hint: {}", e.hint())),
        }
    }
    if let Some(v) = rtol {
        model.settings.rtol = v;
    }
    if let Some(v) = atol {
        model.settings.atol = v;
    }
    if let Some(v) = t_end {
        model.settings.t_end = v;
    }
    if let Some(v) = dt_out {
        model.settings.dt_out = v;
    }
    if let Err(e) = model.settings.validate() {
        return refuse(e.to_string());
    }
    let out_path = output.unwrap_or_else(|| {
        let stem = path
            .file_stem()
            .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("out").join(format!("{stem}.csv"))
    });
    let partial = partial_path(&out_path);
    // Before any work: the destination must be writable and must not be the model itself.
    let mut sink = match open_output(&out_path, &partial, path, &model) {
        Ok(s) => s,
        Err(m) => return refuse(m),
    };
    if !quiet {
        let s = &model.settings;
        say!(
            "{}: {} states, {} → {} s, {} (rtol {:e}, atol {:e}), output every {} s",
            model.title.as_deref().unwrap_or(model.file()),
            model.equations.n_states(),
            s.t_start,
            s.t_end,
            s.method.name(),
            s.rtol,
            s.atol,
            s.dt_out
        );
        if let Some(st) = &model.steady {
            say!("{st}");
        }
        for n in model.notes() {
            tell!("note: {n}");
        }
    }
    model.settings.interrupt = Some(interrupt_on_signals());
    let mut progress = bg_sim::progress::Progress::new(
        &mut sink,
        model.settings.t_start,
        model.settings.t_end,
        !quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()),
        !model.checks.is_empty(),
    );
    let ran = model.run_into(&mut progress);
    drop(progress);
    let (outcome, checks) = match ran {
        Ok(r) => r,
        Err(e) => {
            let _ = std::fs::remove_file(&partial);
            return refuse(e.to_string());
        }
    };
    // The rows still buffered; a failure here (a full disk) makes the run incomplete.
    let flushed = sink.flush();
    let error = match (&outcome.error, &flushed) {
        (Some(e), _) => Some(e.to_string()),
        (None, Err(e)) => Some(
            SimulationError::Output {
                t: outcome.t_final,
                message: e.to_string(),
            }
            .to_string(),
        ),
        (None, Ok(())) => None,
    };
    let target = if error.is_none() {
        // complete: the rows become OUT.csv in one rename (a reader never sees half a file),
        // and no partial file is left beside it
        if let Err(e) = std::fs::rename(&partial, &out_path) {
            return refuse(format!(
                "cannot rename {} to {}: {e} (the complete results are in {})",
                partial.display(),
                out_path.display(),
                partial.display()
            ));
        }
        out_path.clone()
    } else {
        partial.clone()
    };
    if !quiet {
        say!("solver: {}", outcome.stats);
        say!(
            "wrote {} rows × {} columns to {}",
            sink.rows,
            outcome.trajectory.columns.len(),
            target.display()
        );
    }
    for w in &outcome.watched {
        if let Some(warning) = &w.warning {
            tell!("warning: {warning}");
        } else if !quiet {
            say!(
                "minimum {} of {}: {:.6e} at t = {:.6} s",
                w.name,
                w.element,
                w.min,
                w.t_min
            );
        }
    }
    let mut code = ExitCode::SUCCESS;
    if let Some(e) = &error {
        tell!("error: {}: the run stopped early: {e}", model.file());
        match sink.last_t {
            Some(t) => tell!(
                "  the {} rows computed up to t = {t} s are in {} ({} was not written)",
                sink.rows,
                partial.display(),
                out_path.display()
            ),
            None => tell!(
                "  no row was computed: {} holds the header only ({} was not written)",
                partial.display(),
                out_path.display()
            ),
        }
        code = ExitCode::from(FAILED);
    } else {
        for r in checks {
            let status = if r.passed { "ok  " } else { "FAIL" };
            if !quiet || !r.passed {
                say!(
                    "check {status} {}: max |error| {:.3e} at t = {:.6} (tolerance {:.1e}; {} points: every accepted step and output row)",
                    r.value,
                    r.max_error,
                    r.t_worst,
                    r.tol,
                    r.points
                );
            }
            if !r.passed {
                code = ExitCode::from(FAILED);
            }
        }
    }
    (code, Some(target))
}

/// SIGINT and SIGTERM set the returned flag, which the run checks after every step: it stops
/// and keeps its rows in `OUT.partial.csv`. A second signal ends the process at once (exit 1),
/// leaving the rows written so far in `OUT.partial.csv`.
fn interrupt_on_signals() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // registration fails only for forbidden signals; without it, the default action stays
        let _ = signal_hook::flag::register_conditional_shutdown(
            sig,
            i32::from(FAILED),
            Arc::clone(&flag),
        );
        let _ = signal_hook::flag::register(sig, Arc::clone(&flag));
    }
    flag
}

fn partial_path(p: &Path) -> PathBuf {
    let stem = p
        .file_stem()
        .map_or_else(|| "results".into(), |s| s.to_string_lossy().into_owned());
    p.with_file_name(format!("{stem}.partial.csv"))
}

/// Refuse to write over `p` unless it is absent or a regular file other than the model:
/// `-o model.toml`, a symbolic link, a FIFO, a directory or a device are refused.
fn check_destination(p: &Path, model: &Path) -> Result<(), String> {
    if let Ok(m) = std::fs::symlink_metadata(p) {
        let t = m.file_type();
        let what = if t.is_symlink() {
            Some("a symbolic link")
        } else if t.is_dir() {
            Some("a directory")
        } else if !t.is_file() {
            Some("not a regular file (a FIFO, socket or device)")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(format!(
                "{} is {what}: bg-sim writes results only to regular files\n  hint: name a new or regular file with -o",
                p.display()
            ));
        }
    }
    if same_file(p, model) {
        return Err(format!(
            "{} is the model file: writing the results there would destroy it\n  hint: name another file with -o",
            p.display()
        ));
    }
    Ok(())
}

/// Whether two paths name the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        x.dev() == y.dev() && x.ino() == y.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (x, y);
        matches!((a.canonicalize(), b.canonicalize()), (Ok(p), Ok(q)) if p == q)
    }
}

/// Check both destinations, create `OUT.partial.csv` with the header, and remove an `OUT.csv`
/// of an earlier run (so that `OUT.csv` and `OUT.partial.csv` never both exist after a run).
fn open_output(
    out: &Path,
    partial: &Path,
    model_path: &Path,
    model: &Model,
) -> Result<CsvSink, String> {
    check_destination(out, model_path)?;
    check_destination(partial, model_path)?;
    let columns: Vec<&str> = std::iter::once("t")
        .chain(model.outputs.iter().map(|o| o.name.as_str()))
        .collect();
    let cannot = |p: &Path, e: std::io::Error| format!("cannot write {}: {e}", p.display());
    if let Some(dir) = partial.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| cannot(dir, e))?;
    }
    let sink = CsvSink::create(partial, &columns).map_err(|e| cannot(partial, e))?;
    match std::fs::remove_file(out) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            let _ = std::fs::remove_file(partial);
            Err(format!("cannot replace {}: {e}", out.display()))
        }
        _ => Ok(sink),
    }
}

/// A CSV field: quoted (RFC 4180) if it holds a comma, a quote or a line break. The loader
/// allows only plain column names; this keeps any other name from breaking the header.
fn csv_field(s: &str) -> std::borrow::Cow<'_, str> {
    if s.contains([',', '"', '\n', '\r']) || s.is_empty() {
        format!("\"{}\"", s.replace('"', "\"\"")).into()
    } else {
        s.into()
    }
}

/// Rows streamed to `OUT.partial.csv` as they are computed, in whole lines: rows are
/// formatted into a buffer of complete lines and written 64 kB at a time. If a write fails
/// (a full disk), the file is cut back to its last complete row and as many of the buffered
/// rows as still fit are written one by one.
struct CsvSink {
    file: File,
    buf: Vec<u8>,
    /// Time of each buffered row.
    buffered: Vec<f64>,
    /// Bytes of complete lines in the file.
    committed: u64,
    /// Rows in the file.
    rows: usize,
    /// Time of the last row in the file.
    last_t: Option<f64>,
}

impl CsvSink {
    fn create(path: &Path, columns: &[&str]) -> std::io::Result<Self> {
        let file = File::create(path)?;
        let mut sink = Self {
            file,
            buf: Vec::with_capacity(1 << 17),
            buffered: Vec::new(),
            committed: 0,
            rows: 0,
            last_t: None,
        };
        let header: Vec<_> = columns.iter().map(|c| csv_field(c)).collect();
        writeln!(sink.buf, "{}", header.join(","))?;
        sink.flush()?;
        Ok(sink)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        use std::io::{Seek, SeekFrom};
        if self.buf.is_empty() {
            return Ok(());
        }
        let buf = std::mem::take(&mut self.buf);
        let times = std::mem::take(&mut self.buffered);
        let r = self.file.write_all(&buf);
        // lines before the rows: the header, in the first flush
        let lines = buf.iter().filter(|b| **b == b'\n').count();
        let header = lines.saturating_sub(times.len());
        let mut t = times.iter().copied();
        match r {
            Ok(()) => {
                self.committed += buf.len() as u64;
                self.rows += times.len();
                self.last_t = times.last().copied().or(self.last_t);
            }
            Err(ref _e) => {
                // keep whole rows only, then as many of the buffered ones as fit
                let _ = self.file.set_len(self.committed);
                let _ = self.file.seek(SeekFrom::Start(self.committed));
                for (k, line) in buf.split_inclusive(|b| *b == b'\n').enumerate() {
                    if self.file.write_all(line).is_err() {
                        let _ = self.file.set_len(self.committed);
                        break;
                    }
                    self.committed += line.len() as u64;
                    if k >= header {
                        self.rows += 1;
                        self.last_t = t.next().or(self.last_t);
                    }
                }
            }
        }
        self.buf = buf;
        self.buf.clear();
        r
    }
}

impl RowSink for CsvSink {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        let mut first = true;
        for v in row {
            if !first {
                self.buf.push(b',');
            }
            first = false;
            // infallible: writing to a Vec
            let _ = write!(self.buf, "{v}");
        }
        self.buf.push(b'\n');
        self.buffered.push(row.first().copied().unwrap_or(f64::NAN));
        if self.buf.len() >= 1 << 16 {
            self.flush().map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

fn modes(path: &Path, at: Option<f64>, set: &[String], json: bool, top: usize) -> ExitCode {
    let mut model = match Model::load(path, &registry(), set) {
        Ok(m) => m,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    if let Some(t) = at {
        if !(t.is_finite() && t >= model.settings.t_start) {
            tell!(
                "error: --at must be a finite time from t_start = {} s on, got {t}",
                model.settings.t_start
            );
            return ExitCode::from(BAD_INPUT);
        }
    }
    match bg_sim::modes::analyse(&mut model, at) {
        Ok(r) => {
            if json {
                say!("{}", r.json(top));
            } else {
                if let Some(s) = &model.steady {
                    say!("{s}");
                }
                say!("{}", r.text(top));
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(FAILED)
        }
    }
}

fn check(path: &Path, set: &[String]) -> ExitCode {
    let report = inspect(path, &registry(), set);
    if !report.elements.is_empty() {
        say!("elements ({}):", report.elements.len());
        for (name, kind, line) in &report.elements {
            say!("  {name:<20} {kind:<20} line {line}");
        }
    }
    if !report.bonds.is_empty() {
        say!(
            "bonds ({}), `|` marks the causal stroke (the end that receives the effort):",
            report.bonds.len()
        );
        for b in &report.bonds {
            say!("  {b}");
        }
    }
    if !report.states.is_empty() {
        say!("states ({}):", report.states.len());
        for (name, v) in &report.states {
            say!("  {name:<24} initial {v}");
        }
    }
    if !report.scene.is_empty() {
        say!(
            "scene switches ({}, {} scenes; `bg-sim reduce` searches them), richest choice first:",
            report.scene.switches.len(),
            report.scene.grid_size()
        );
        for sw in &report.scene.switches {
            let choices: Vec<&str> = sw.choices.iter().map(|c| c.label.as_str()).collect();
            say!("  {:<20} {} = {}", sw.name, sw.set, choices.join(" | "));
        }
    }
    for n in &report.notes {
        say!("  note: {n}");
    }
    if report.problems.is_empty() {
        say!("no problems found");
        ExitCode::SUCCESS
    } else {
        say!("problems ({}):", report.problems.len());
        for p in &report.problems {
            say!("  error: {p}");
        }
        ExitCode::from(1)
    }
}
