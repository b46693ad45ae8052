//! `bg-sim`: run and check bond-graph model files. No physics lives here: the CLI loads a
//! model through `bg-model`, runs it through `bondgraph`, and writes the results.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_model::{inspect, Model};
use bg_sim::plot::{plot_all, work_precision, Drawn, Results, WorkPrecisionLine};
use bg_sim::registry;
use bondgraph::{Method, Outcome};
use clap::{Parser, Subcommand};

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
        /// Also draw the paper's figures (`bg-sim plot`) from the results into this folder.
        #[arg(long, value_name = "DIR")]
        plots: Option<PathBuf>,
    },
    /// Check a model: list elements, bonds with causal strokes, states and problems.
    Check {
        /// The model file.
        model: PathBuf,
        /// Override a value of the model file (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// List the element kinds a model file can use.
    Kinds,
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
    /// Draw the knuckle boom figures of the paper (Figs. 7-11, 15-18) from a results CSV as
    /// PNG; figures whose columns are missing are skipped.
    Plot {
        /// A CSV written by `bg-sim run`.
        results: PathBuf,
        /// Folder for the PNGs (created if needed).
        #[arg(long, default_value = "out/plots")]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
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
                (Some(dir), Some(csv)) => match plot(&csv, &dir, quiet) {
                    ExitCode::SUCCESS => code,
                    failed => failed,
                },
                _ => code,
            }
        }
        Command::Check { model, set } => check(&model, &set),
        Command::Kinds => {
            for (k, info) in registry().kinds() {
                println!("{k:<24} {}", info.summary);
            }
            ExitCode::SUCCESS
        }
        Command::Plot { results, out } => plot(&results, &out, false),
        Command::Compare {
            results,
            reference,
            columns,
            floors,
        } => compare(&results, &reference, columns.as_deref(), &floors),
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
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    if a.rhs_only {
        let c = rhs_cost(&model, 20_000);
        println!(
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
        match Method::parse(s) {
            Some(m) => methods.push(m),
            None => {
                eprintln!(
                    "error: unknown solver `{s}`\n  hint: solvers are {}",
                    Method::names()
                );
                return ExitCode::from(2);
            }
        }
    }
    let mut floors = Vec::new();
    for f in a.floors {
        match f
            .split_once('=')
            .map(|(p, v)| (p.trim(), v.trim().parse::<f64>()))
        {
            Some((p, Ok(v))) if !p.is_empty() && v.is_finite() && v >= 0.0 => {
                floors.push((p.to_owned(), v));
            }
            _ => {
                eprintln!("error: --floor `{f}`: expected PATTERN=VALUE with a finite VALUE ≥ 0\n  hint: --floor 'qb*=1e-3'");
                return ExitCode::from(2);
            }
        }
    }
    if let Some(t) = a.t_end {
        model.settings.t_end = t;
    }
    for &r in a.rtols.iter().chain(std::iter::once(&a.reference_rtol)) {
        model.settings.rtol = r;
        if let Err(e) = model.settings.validate() {
            eprintln!("error: {e}");
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
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    println!(
        "{}: {} states, 0 → {} s; reference {what}; {} columns scored",
        model.file(),
        model.equations.n_states(),
        model.settings.t_end,
        reference.columns.len()
    );
    match bench(&mut model, &methods, a.rtols, &reference, a.repeat) {
        Ok(rows) => {
            print!("{}", table(&rows));
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
                    Ok(p) => println!("wrote {}", p.display()),
                    Err(e) => {
                        eprintln!("error: {e}");
                        return ExitCode::from(1);
                    }
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
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
                eprintln!("error: --floor `{f}`: expected PATTERN=VALUE with a finite VALUE ≥ 0\n  hint: --floor 'qb*=1e-3'");
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
            println!("| column | scale | scaled error |\n|---|---|---|");
            for ((name, e), (_, _, scale)) in errors.iter().zip(&r.columns) {
                println!("| {name} | {scale:.4e} | {e:.3e} |");
            }
            if let Some((name, e)) = errors.iter().max_by(|a, b| a.1.total_cmp(&b.1)) {
                println!("worst: {name} {e:.3e}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn plot(results: &Path, dir: &Path, quiet: bool) -> ExitCode {
    let drawn = Results::read(results).and_then(|r| plot_all(&r, dir));
    match drawn {
        Ok(figures) => {
            let mut written = 0;
            for f in &figures {
                match f {
                    Drawn::Written(p) => {
                        written += 1;
                        if !quiet {
                            println!("wrote {}", p.display());
                        }
                    }
                    Drawn::Skipped { file, missing } => {
                        if !quiet {
                            println!("skipped {file}: no column {}", missing.join(", "));
                        }
                    }
                }
            }
            if written == 0 {
                eprintln!(
                    "error: {} has none of the columns of the figures (t, q1, l1, p_p1, F_c1, rho1, …)",
                    results.display()
                );
                return ExitCode::from(1);
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
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
    let mut model = match Model::load(path, &registry(), set) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            return (ExitCode::from(2), None);
        }
    };
    if let Some(s) = solver {
        match Method::parse(s) {
            Some(m) => model.settings.method = m,
            None => {
                eprintln!(
                    "error: unknown solver `{s}`\n  hint: solvers are {}",
                    Method::names()
                );
                return (ExitCode::from(2), None);
            }
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
        eprintln!("error: {e}");
        return (ExitCode::from(2), None);
    }
    let out_path = output.unwrap_or_else(|| {
        let stem = path
            .file_stem()
            .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("out").join(format!("{stem}.csv"))
    });
    if !quiet {
        let s = &model.settings;
        println!(
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
    }
    let outcome = match model.run() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}");
            return (ExitCode::from(2), None);
        }
    };
    let complete = outcome.error.is_none();
    let target = if complete {
        out_path.clone()
    } else {
        partial_path(&out_path)
    };
    if let Err(e) = write_csv(&target, &outcome) {
        eprintln!("error: cannot write {}: {e}", target.display());
        return (ExitCode::from(2), None);
    }
    if !quiet {
        println!("solver: {}", outcome.stats);
        println!(
            "wrote {} rows × {} columns to {}",
            outcome.trajectory.rows.len(),
            outcome.trajectory.columns.len(),
            target.display()
        );
    }
    for w in &outcome.watched {
        if let Some(warning) = &w.warning {
            eprintln!("warning: {warning}");
        } else if !quiet {
            println!(
                "minimum {} of {}: {:.6e} at t = {:.6} s",
                w.name, w.element, w.min, w.t_min
            );
        }
    }
    let mut code = ExitCode::SUCCESS;
    if let Some(e) = &outcome.error {
        eprintln!("error: {}: the run stopped early: {e}", model.file());
        eprintln!(
            "  the {} rows computed up to t = {} s are in {} ({} was not written)",
            outcome.trajectory.rows.len(),
            outcome.t_final,
            target.display(),
            out_path.display()
        );
        code = ExitCode::from(1);
    } else {
        for r in model.verify(&outcome.trajectory) {
            let status = if r.passed { "ok  " } else { "FAIL" };
            if !quiet || !r.passed {
                println!(
                    "check {status} {}: max |error| {:.3e} at t = {:.6} (tolerance {:.1e})",
                    r.value, r.max_error, r.t_worst, r.tol
                );
            }
            if !r.passed {
                code = ExitCode::from(1);
            }
        }
    }
    (code, Some(target))
}

fn partial_path(p: &Path) -> PathBuf {
    let stem = p
        .file_stem()
        .map_or_else(|| "results".into(), |s| s.to_string_lossy().into_owned());
    p.with_file_name(format!("{stem}.partial.csv"))
}

/// Write the CSV next to its destination, then rename: a reader never sees half a file.
fn write_csv(path: &Path, outcome: &Outcome) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir)?;
    let mut tmp = tempfile::NamedTempFile::new_in(&dir)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        writeln!(w, "{}", outcome.trajectory.columns.join(","))?;
        for row in &outcome.trajectory.rows {
            let mut first = true;
            for v in row {
                if !first {
                    w.write_all(b",")?;
                }
                first = false;
                write!(w, "{v}")?;
            }
            w.write_all(b"\n")?;
        }
        w.flush()?;
    }
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

fn check(path: &Path, set: &[String]) -> ExitCode {
    let report = inspect(path, &registry(), set);
    if !report.elements.is_empty() {
        println!("elements ({}):", report.elements.len());
        for (name, kind, line) in &report.elements {
            println!("  {name:<20} {kind:<20} line {line}");
        }
    }
    if !report.bonds.is_empty() {
        println!(
            "bonds ({}), `|` marks the causal stroke (the end that receives the effort):",
            report.bonds.len()
        );
        for b in &report.bonds {
            println!("  {b}");
        }
    }
    if !report.states.is_empty() {
        println!("states ({}):", report.states.len());
        for (name, v) in &report.states {
            println!("  {name:<24} initial {v}");
        }
    }
    if report.problems.is_empty() {
        println!("no problems found");
        ExitCode::SUCCESS
    } else {
        println!("problems ({}):", report.problems.len());
        for p in &report.problems {
            println!("  error: {p}");
        }
        ExitCode::from(1)
    }
}
