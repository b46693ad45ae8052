//! `bg-sim`: run and check bond-graph model files. No physics lives here: the CLI loads a
//! model through `bg-model`, runs it through `bondgraph`, and writes the results.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_model::{inspect, Model};
use bg_sim::plot::{plot_all, Drawn, Results};
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
    /// Measure the speed–accuracy trade: every solver at every rtol against a tight BDF
    /// reference (wall time, steps, rhs evaluations, worst relative error of any column).
    Bench {
        /// The model file.
        model: PathBuf,
        /// Solvers, comma-separated.
        #[arg(long, default_value = "bdf,esdirk34,tr-bdf2", value_delimiter = ',')]
        solvers: Vec<String>,
        /// Relative tolerances, comma-separated.
        #[arg(long, default_value = "1e-4,1e-6,1e-8", value_delimiter = ',')]
        rtols: Vec<f64>,
        /// Relative tolerance of the BDF reference run.
        #[arg(long, default_value_t = 1e-10)]
        reference_rtol: f64,
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
        Command::Bench {
            model,
            solvers,
            rtols,
            reference_rtol,
            repeat,
            t_end,
            set,
        } => bench(
            &model,
            &solvers,
            &rtols,
            reference_rtol,
            repeat,
            t_end,
            &set,
        ),
    }
}

fn bench(
    path: &Path,
    solvers: &[String],
    rtols: &[f64],
    reference_rtol: f64,
    repeat: usize,
    t_end: Option<f64>,
    set: &[String],
) -> ExitCode {
    let mut model = match Model::load(path, &registry(), set) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut methods = Vec::new();
    for s in solvers {
        match Method::parse(s) {
            Some(m) => methods.push(m),
            None => {
                eprintln!("error: unknown solver `{s}`\n  hint: solvers are bdf, esdirk34, tr-bdf2, tsit45");
                return ExitCode::from(2);
            }
        }
    }
    if let Some(t) = t_end {
        model.settings.t_end = t;
    }
    for &r in rtols.iter().chain(std::iter::once(&reference_rtol)) {
        model.settings.rtol = r;
        if let Err(e) = model.settings.validate() {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    }
    println!(
        "{}: {} states, 0 → {} s; reference bdf at rtol {reference_rtol:e}",
        model.file(),
        model.equations.n_states(),
        model.settings.t_end
    );
    match bg_sim::bench::bench(&mut model, &methods, rtols, reference_rtol, repeat) {
        Ok((reference, rows)) => {
            println!("reference: {}", reference.stats);
            print!("{}", bg_sim::bench::table(&rows));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
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
                eprintln!("error: unknown solver `{s}`\n  hint: solvers are bdf, esdirk34, tr-bdf2, tsit45");
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
