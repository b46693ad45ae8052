//! `bg-sim fit`: fit a model's parameters to measured data (the library's [`bg_sim::fit`]):
//! the estimates with standard errors, 95 % intervals, correlations and warnings, as text
//! or JSON; `-o` the model with the fitted values; `--plot` data against fit.

use std::path::PathBuf;
use std::process::ExitCode;

use bg_sim::fit::{self, parse_param, LmOptions, Loss, Method, Problem, RunOptions};
use bg_sim::registry;

use super::json::Format;
use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim fit`.
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// Measured data: a `t` column, columns named after `[outputs]` (fitted) and after
    /// `[inputs]` (driving the run). Repeat for several experiments.
    #[arg(long = "data", value_name = "DATA.csv", required = true)]
    pub data: Vec<PathBuf>,
    /// A fitted parameter with its bounds and optional start: NAME=LO..HI[@START]
    /// (`beta`, `parameters.beta` or `elements.cyl1.beta`). Repeatable.
    #[arg(long = "param", value_name = "NAME=LO..HI[@START]", required = true)]
    pub param: Vec<String>,
    /// Fit only these outputs (comma-separated; default: every data column that is an output).
    #[arg(long, value_delimiter = ',')]
    pub outputs: Option<Vec<String>>,
    /// Weights of outputs' squared residuals, y=w (comma-separated; default 1/scale² of the
    /// data column, scale = max(range, |mean|)).
    #[arg(long, value_delimiter = ',', value_name = "y1=w1,…")]
    pub weights: Vec<String>,
    /// l2 or huber.
    #[arg(long, default_value = "l2")]
    pub loss: String,
    /// lm (Levenberg–Marquardt) or nelder-mead (derivative-free, for comparison).
    #[arg(long, default_value = "lm")]
    pub method: String,
    /// How the Jacobian is formed: exact (the core's forward sensitivities, one run per
    /// iteration) or fd (central differences of whole runs, 2·P + 1 runs).
    #[arg(long, default_value = "exact")]
    pub jacobian: String,
    /// Most iterations.
    #[arg(long, default_value_t = 50)]
    pub max_iterations: usize,
    /// text, or json (the report as one JSON document; the progress goes to stderr).
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Write the model with the fitted values here (comments and layout kept).
    #[arg(short, long, value_name = "FITTED.toml")]
    pub output: Option<PathBuf>,
    /// Draw data against the fitted model and the residuals (PNG).
    #[arg(long, value_name = "FIT.png")]
    pub plot: Option<PathBuf>,
    /// Override a value of the model file (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// End time (s).
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Relative tolerance (default: the model's, or 1e-7 if that is looser).
    #[arg(long)]
    pub rtol: Option<f64>,
    /// How input data go from one sample to the next: linear, or hold.
    #[arg(long, value_name = "INTERP")]
    pub inputs_interp: Option<String>,
    /// Print only the report.
    #[arg(short, long)]
    pub quiet: bool,
}

fn refuse(m: impl std::fmt::Display) -> ExitCode {
    tell!("error: {m}");
    ExitCode::from(BAD_INPUT)
}

/// `bg-sim fit`.
pub fn command(a: Args) -> ExitCode {
    if a.format == Format::Json {
        crate::report::keep_stdout_for_document();
    }
    let mut params = Vec::new();
    for p in &a.param {
        match parse_param(p) {
            Ok(s) => params.push(s),
            Err(m) => return refuse(m),
        }
    }
    let mut weights = Vec::new();
    for w in &a.weights {
        match w.split_once('=').map(|(n, v)| (n.trim(), v.trim().parse::<f64>())) {
            Some((n, Ok(v))) if !n.is_empty() && v.is_finite() && v > 0.0 => weights.push((n.to_owned(), v)),
            _ => return refuse(format!("--weights `{w}`: expected OUTPUT=WEIGHT with a weight > 0\n  hint: --weights p_p=1e-12,s=100")),
        }
    }
    let loss = match a.loss.as_str() {
        "l2" => Loss::L2,
        "huber" => Loss::Huber,
        other => return refuse(format!("--loss {other}: not a loss\n  hint: l2 or huber")),
    };
    let method = match a.method.as_str() {
        "lm" => Method::Lm,
        "nelder-mead" => Method::NelderMead,
        other => {
            return refuse(format!(
                "--method {other}: not a method\n  hint: lm or nelder-mead"
            ))
        }
    };
    let jacobian = match a.jacobian.as_str() {
        "exact" => fit::JacobianKind::Exact,
        "fd" => fit::JacobianKind::Fd,
        other => {
            return refuse(format!(
                "--jacobian {other}: not a choice\n  hint: exact or fd"
            ))
        }
    };
    let data: Vec<&std::path::Path> = a.data.iter().map(PathBuf::as_path).collect();
    let run = RunOptions {
        set: a.set.clone(),
        t_end: a.t_end,
        rtol: a.rtol,
        interp: a.inputs_interp.clone(),
    };
    let mut problem = match Problem::new(
        &a.model,
        &data,
        params,
        a.outputs.as_deref(),
        &weights,
        run,
        registry,
    ) {
        Ok(p) => p,
        Err(e) => return refuse(e),
    };
    problem.loss = loss;
    let quiet = a.quiet;
    if !quiet {
        for n in &problem.notes {
            tell!("note: {n}");
        }
        tell!(
            "fitting {} parameter(s) to {} residuals of {} ({} experiment(s))",
            problem.params.len(),
            problem.n_residuals(),
            problem.outputs.join(", "),
            problem.experiments.len()
        );
    }
    let opts = LmOptions {
        max_iterations: a.max_iterations,
        loss,
        ..LmOptions::default()
    };
    let names: Vec<String> = problem.params.iter().map(|s| s.name.clone()).collect();
    let mut progress = |k: usize, it: &fit::Iteration, p: &[f64]| {
        if !quiet {
            let vals: Vec<String> = names
                .iter()
                .zip(p)
                .map(|(n, v)| format!("{n}={v:.6e}"))
                .collect();
            tell!(
                "iteration {k:>2}: cost {:.6e}, step {:.2e}, λ {:.1e}{}  {}",
                it.cost,
                it.step,
                it.lambda,
                if it.rejected > 0 {
                    format!(" ({} rejected)", it.rejected)
                } else {
                    String::new()
                },
                vals.join(" ")
            );
        }
    };
    let result = match fit::fit(&problem, method, jacobian, &opts, &mut progress) {
        Ok(r) => r,
        Err(m) => {
            tell!("error: {}: the fit stopped: {m}", a.model.display());
            return ExitCode::from(FAILED);
        }
    };
    match a.format {
        Format::Json => crate::report::document(&result.json()),
        Format::Text => say!("{}", result.text().trim_end()),
    }
    let mut code = ExitCode::SUCCESS;
    if let Some(out) = &a.output {
        let shown = a.model.display().to_string();
        let written = std::fs::read_to_string(&a.model)
            .map_err(|e| e.to_string())
            .and_then(|t| fit::fitted_model(&shown, &t, &problem, &result.p))
            .and_then(|t| std::fs::write(out, t).map_err(|e| e.to_string()));
        match written {
            Ok(()) if !quiet => tell!("wrote the fitted model to {}", out.display()),
            Ok(()) => {}
            Err(e) => {
                tell!("error: cannot write {}: {e}", out.display());
                code = ExitCode::from(FAILED);
            }
        }
    }
    if let Some(png) = &a.plot {
        match fit::plot_fit(&problem, &result.p, png) {
            Ok(files) if !quiet => {
                for f in files {
                    tell!("wrote {}", f.display());
                }
            }
            Ok(_) => {}
            Err(e) => {
                tell!("error: cannot draw {}: {e}", png.display());
                code = ExitCode::from(FAILED);
            }
        }
    }
    code
}
