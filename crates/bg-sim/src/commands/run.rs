//! `bg-sim run`: simulate a model and stream its results to CSV ([`output`]), then draw the
//! model's figures if `--plots` asks for them.

mod number;
mod output;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_model::{CheckResult, Model, ModelError};
use bg_sim::registry;
use bondgraph::{SimulationError, Statistics};
use serde_json::json;

use super::json::{problems, Format};

use super::plot::{plot, PlotWhat};
use super::{interrupt_on_signals, BAD_INPUT, FAILED};
use output::{open_output, partial_path};

/// The options of `bg-sim run` (its summary is on `Command::Run` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// Output CSV (default: out/<model name>.csv).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Integration method: bdf, esdirk34, tr-bdf2 or tsit45.
    #[arg(long)]
    pub solver: Option<String>,
    /// Relative tolerance.
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance (scaled per state by its nominal magnitude).
    #[arg(long)]
    pub atol: Option<f64>,
    /// End time (s).
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Output interval (s).
    #[arg(long)]
    pub dt_out: Option<f64>,
    /// Override a value of the model file: --set parameters.k=5 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Print only errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Also draw the model's `[[plot]]` figures from the results into this folder.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Format of those figures: png, svg or both.
    #[arg(long, value_name = "FORMAT", default_value = "png")]
    pub plot_format: String,
    /// text, or json (the run's outcome, statistics, checks and problems as one JSON
    /// document on stdout; the text report goes to stderr).
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Drive the model's inputs from a CSV: a `t` column and one column per input (any
    /// subset; the others keep their default).
    #[arg(long, value_name = "DATA.csv")]
    pub inputs: Option<PathBuf>,
    /// How the data go from one sample to the next: linear, or hold (zero-order hold).
    #[arg(long, value_name = "INTERP", default_value = "linear")]
    pub inputs_interp: String,
    /// Outside the data's times: error (the default: the data must cover the run), or hold
    /// the first and last values.
    #[arg(long, value_name = "WHAT", default_value = "error")]
    pub inputs_extrapolate: String,
    /// Do not stop and restart the solver at every sample of the data (for dense data: the
    /// solver's error control alone deals with the corners).
    #[arg(long)]
    pub no_breakpoints: bool,
    /// Audit the run's energy (docs/energy.md): print where it went, by composite, after the
    /// run, and write every element's row to OUT.energy.csv beside the results.
    #[arg(long)]
    pub energy: bool,
}

/// How `run` drives the model's inputs (`--inputs`, `--inputs-interp`,
/// `--inputs-extrapolate`, `--no-breakpoints`).
struct InputOptions {
    data: Option<PathBuf>,
    interp: String,
    extrapolate: String,
    no_breakpoints: bool,
}

impl InputOptions {
    /// Apply them to `model` (after its settings are final: coverage is checked against
    /// them); a refusal as the message to print.
    fn apply(&self, model: &mut Model) -> Result<(), String> {
        model.set_stop_at_breakpoints(!self.no_breakpoints);
        let Some(path) = &self.data else {
            return Ok(());
        };
        let interp = bondgraph::Interp::parse(&self.interp).ok_or_else(|| {
            format!(
                "--inputs-interp {}: not an interpolation\n  hint: linear, hold or spline",
                self.interp
            )
        })?;
        let extrapolate = bg_model::Extrapolate::parse(&self.extrapolate).ok_or_else(|| {
            format!(
                "--inputs-extrapolate {}: not a choice\n  hint: error or hold",
                self.extrapolate
            )
        })?;
        model
            .set_inputs_from_csv(path, interp, extrapolate)
            .map(drop)
            .map_err(|e| e.to_string())
    }
}

/// `bg-sim run`.
pub fn command(a: Args) -> ExitCode {
    let Args {
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
        format,
        inputs,
        inputs_interp,
        inputs_extrapolate,
        no_breakpoints,
        energy,
    } = a;
    let drive = InputOptions {
        data: inputs,
        interp: inputs_interp,
        extrapolate: inputs_extrapolate,
        no_breakpoints,
    };
    if format == Format::Json {
        crate::report::keep_stdout_for_document();
    }
    let mut facts = Facts::default();
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
        &drive,
        energy,
        &mut facts,
    );
    if format == Format::Json {
        crate::report::document(&facts.json(&model, written.as_deref()));
    }
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
    drive: &InputOptions,
    energy: bool,
    facts: &mut Facts,
) -> (ExitCode, Option<PathBuf>) {
    let refuse = |facts: &mut Facts, m: String| {
        facts.refused = Some(m.clone());
        tell!("error: {m}");
        (ExitCode::from(BAD_INPUT), None)
    };
    let mut model = match Model::load(path, &registry(), set) {
        Ok(m) => m,
        Err(e) => {
            // The text report names the first problem; the JSON lists every one the loader
            // finds in one pass (the same list as `check`), the first one first.
            let all = bg_model::inspect(path, &registry(), set).problems;
            facts.problems.push(e.clone());
            facts.problems.extend(all.into_iter().filter(|p| *p != e));
            return refuse(facts, e.to_string());
        }
    };
    if let Some(s) = solver {
        match bg_model::solver(s) {
            Ok(m) => model.settings.method = m,
            Err(e) => return refuse(facts, format!("{e}\n  hint: {}", e.hint())),
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
        return refuse(facts, e.to_string());
    }
    if let Err(m) = drive.apply(&mut model) {
        return refuse(facts, m);
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
        Err(m) => return refuse(facts, m),
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
    let mut audit = None;
    let ran = if energy {
        model.run_energy(&mut progress).map(|r| {
            audit = Some(r.report);
            (r.outcome, r.checks)
        })
    } else {
        model.run_into(&mut progress)
    };
    drop(progress);
    let (outcome, checks) = match ran {
        Ok(r) => r,
        Err(e) => {
            let _ = std::fs::remove_file(&partial);
            return refuse(facts, e.to_string());
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
    facts.stats = Some(outcome.stats.clone());
    facts.rows = sink.rows;
    facts.columns = outcome.trajectory.columns.len();
    facts.t_final = Some(outcome.t_final);
    facts.stopped.clone_from(&error);
    let target = if error.is_none() {
        // complete: the rows become OUT.csv in one rename (a reader never sees half a file),
        // and no partial file is left beside it
        if let Err(e) = std::fs::rename(&partial, &out_path) {
            return refuse(
                facts,
                format!(
                    "cannot rename {} to {}: {e} (the complete results are in {})",
                    partial.display(),
                    out_path.display(),
                    partial.display()
                ),
            );
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
    if let Some(report) = &audit {
        let csv = out_path.with_extension("energy.csv");
        if !quiet {
            say!("{}", bg_sim::energy::text(report, false).trim_end());
        }
        match std::fs::write(&csv, bg_sim::energy::csv(report, true)) {
            Ok(()) if !quiet => say!("wrote the energy of every element to {}", csv.display()),
            Ok(()) => {}
            Err(e) => {
                tell!("error: cannot write {}: {e}", csv.display());
                code = ExitCode::from(FAILED);
            }
        }
    }
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
        facts.checks.clone_from(&checks);
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

/// What `run` did, for `--format json`.
#[derive(Default)]
pub struct Facts {
    /// The model file's problems, if it did not load.
    problems: Vec<ModelError>,
    /// Why the run did not start (bad model, option or destination).
    refused: Option<String>,
    /// Solver work, once the run has run.
    stats: Option<Statistics>,
    /// Rows written and columns per row.
    rows: usize,
    columns: usize,
    /// Time reached.
    t_final: Option<f64>,
    /// Why the run stopped early, if it did.
    stopped: Option<String>,
    /// The `[[check]]` results (of a run that reached its end).
    checks: Vec<CheckResult>,
}

impl Facts {
    /// `{file, outcome, error, results, rows, columns, t_final, statistics: {steps, rhs,
    /// jacobians, jacobians_assembled, lu, error_test_failures, newton_iterations,
    /// newton_failures, events, wall_s}, checks: [{value, passed, max_error, t_worst, tol,
    /// points}], problems: [..]}`; `outcome` is `complete`, `checks-failed`, `failed` (the run
    /// stopped early or its file could not be finished: the rows so far are in `results`, the
    /// partial file) or `refused` (nothing ran: `problems` has the model's, if any).
    fn json(&self, model: &Path, results: Option<&Path>) -> serde_json::Value {
        let outcome = if self.stats.is_none() {
            "refused"
        } else if self.refused.is_some() || self.stopped.is_some() {
            "failed"
        } else if self.checks.iter().any(|c| !c.passed) {
            "checks-failed"
        } else {
            "complete"
        };
        let statistics = self.stats.as_ref().map(|s| {
            json!({
                "steps": s.steps,
                "rhs": s.rhs_evals,
                "jacobians": s.jac_evals,
                "jacobians_assembled": s.jac_assemblies,
                "lu": s.lu_factorisations,
                "error_test_failures": s.error_test_failures,
                "newton_iterations": s.newton_iterations,
                "newton_failures": s.newton_failures,
                "events": s.events,
                "wall_s": s.wall_time.as_secs_f64(),
            })
        });
        let checks: Vec<_> = self
            .checks
            .iter()
            .map(|c| {
                json!({
                    "value": c.value,
                    "passed": c.passed,
                    "max_error": c.max_error,
                    "t_worst": c.t_worst,
                    "tol": c.tol,
                    "points": c.points,
                })
            })
            .collect();
        json!({
            "file": model.display().to_string(),
            "outcome": outcome,
            "error": self.refused.as_ref().or(self.stopped.as_ref()),
            "results": results.map(|p| p.display().to_string()),
            "rows": self.rows,
            "columns": self.columns,
            "t_final": self.t_final,
            "statistics": statistics,
            "checks": checks,
            "problems": problems(&self.problems),
        })
    }
}
