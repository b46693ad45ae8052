//! Fitting a model to measured data: `bg-sim fit MODEL --data DATA.csv --param NAME=LO..HI`.
//!
//! Weighted nonlinear least squares between the model's `[outputs]` and the data's columns
//! of the same name, over bounded parameters, by a bounded Levenberg–Marquardt ([`lm`]);
//! then how well the data fix each parameter ([`stats`]): standard errors, 95 % intervals,
//! correlations and warnings. The derivatives are the core's exact forward sensitivities
//! ([`bg_model::Model::sensitivities`], `--jacobian exact`, the default) or central
//! differences of whole runs ([`jacobian`], `--jacobian fd`); a derivative-free Nelder–Mead ([`nelder_mead`]) is the
//! comparison (`--method nelder-mead`) and, as a parallel particle swarm, the search of
//! `bg-sim optimize`. The report is [`Fit::json`] (the shape tools read) or
//! [`Fit::text`]; [`fitted_model`] writes the model file with the fitted values, comments
//! and layout kept; [`plot_fit`] draws data against fit and the residuals.
//!
//! Contents: [`problem`] (parameters, experiments, residuals), [`jacobian`], [`lm`],
//! [`stats`], [`nelder_mead`].

pub mod jacobian;
pub mod lm;
pub mod nelder_mead;
pub mod problem;
pub mod stats;

use std::path::Path;
use std::time::Instant;

use serde_json::{json, Value};

pub use lm::{Iteration, LmOptions};
pub use problem::{parse_param, Loss, ParamSpec, Problem, RunOptions};
pub use stats::Stats;

/// How the fit searches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    /// Levenberg–Marquardt on the Jacobian.
    #[default]
    Lm,
    /// Nelder–Mead on the cost, no derivatives (the comparison).
    NelderMead,
}

/// Where the Jacobian comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum JacobianKind {
    /// The core's exact forward sensitivities: one run per experiment and iteration.
    #[default]
    Exact,
    /// Central differences of whole runs: 2·P + 1 runs per experiment and iteration.
    Fd,
}

/// A finished fit.
#[derive(Clone, Debug)]
pub struct Fit {
    /// Parameter names as given.
    pub names: Vec<String>,
    /// Bounds.
    pub bounds: Vec<(f64, f64)>,
    /// The start.
    pub start: Vec<f64>,
    /// The estimate.
    pub p: Vec<f64>,
    /// Final cost ½ Σ ρ r².
    pub cost: f64,
    /// The iterations (LM) or the best cost per iteration (Nelder–Mead, step 0).
    pub history: Vec<Iteration>,
    /// Model runs.
    pub runs: usize,
    /// Whether it converged.
    pub converged: bool,
    /// Why it stopped.
    pub reason: String,
    /// The statistics at the estimate.
    pub stats: Stats,
    /// Warnings (identifiability, bounds).
    pub warnings: Vec<String>,
    /// Wall time, s.
    pub wall_s: f64,
    /// Residuals at the estimate, number of.
    pub n_residuals: usize,
}

/// Fit `problem` from its start.
///
/// # Errors
/// A run that fails at the start or while the Jacobian is formed.
pub fn fit(
    problem: &Problem,
    method: Method,
    jacobian_kind: JacobianKind,
    opts: &LmOptions,
    on_iteration: &mut dyn FnMut(usize, &Iteration, &[f64]),
) -> Result<Fit, String> {
    let started = Instant::now();
    let lo: Vec<f64> = problem.params.iter().map(|s| s.lo).collect();
    let hi: Vec<f64> = problem.params.iter().map(|s| s.hi).collect();
    let reg = (problem.registry)();
    let residuals = |p: &[f64]| problem.residuals(&reg, p);
    let jac = |p: &[f64]| match jacobian_kind {
        JacobianKind::Exact => jacobian::exact_residuals_and_jacobian(problem, p),
        JacobianKind::Fd => jacobian::residuals_and_jacobian(problem, p),
    };
    let (p, history, converged, reason) = match method {
        Method::Lm => {
            let res = lm::lm(
                &residuals,
                &jac,
                &problem.start,
                &lo,
                &hi,
                opts,
                on_iteration,
            )?;
            (res.p, res.history, res.converged, res.reason)
        }
        Method::NelderMead => {
            let cost = |p: &[f64]| {
                let reg = (problem.registry)();
                problem.residuals(&reg, p).map_or(f64::INFINITY, |r| {
                    0.5 * r.iter().map(|v| v * v).sum::<f64>()
                })
            };
            let found = nelder_mead::nelder_mead(
                &cost,
                &problem.start,
                &lo,
                &hi,
                1e-10,
                400 * problem.params.len(),
            );
            let history = found
                .history
                .iter()
                .map(|&c| Iteration {
                    cost: c,
                    step: 0.0,
                    lambda: 0.0,
                    rejected: 0,
                })
                .collect();
            let reason = if found.converged {
                "the simplex's costs agree within 1e-10".to_owned()
            } else {
                format!("{} evaluations, the budget", found.evaluations)
            };
            (found.p, history, found.converged, reason)
        }
    };
    // the statistics at the estimate, from its Jacobian (not counted as an iteration)
    let (r, j) = jac(&p)?;
    let rho = match opts.loss {
        Loss::L2 => vec![1.0; r.len()],
        Loss::Huber => {
            let mut a: Vec<f64> = r.iter().map(|v| v.abs()).collect();
            a.sort_by(f64::total_cmp);
            let c = 1.345 * 1.4826 * a.get(a.len() / 2).copied().unwrap_or(0.0);
            r.iter()
                .map(|v| {
                    if c > 0.0 && v.abs() > c {
                        c / v.abs()
                    } else {
                        1.0
                    }
                })
                .collect()
        }
    };
    let cost = 0.5 * r.iter().zip(&rho).map(|(v, w)| w * v * v).sum::<f64>();
    let st = stats::stats(&p, &r, &rho, &j);
    let names: Vec<String> = problem.params.iter().map(|s| s.name.clone()).collect();
    let mut warnings = Vec::new();
    if !st.unidentifiable.is_empty() {
        let who: Vec<&str> = st
            .unidentifiable
            .iter()
            .map(|&k| names[k].as_str())
            .collect();
        warnings.push(format!(
            "unidentifiable: the information is near-singular (smallest scaled eigenvalue {:.1e}); the data fix only a combination of {} — fix all but one of them, or add data that separate them",
            st.min_eigenvalue,
            who.join(", ")
        ));
    }
    for &(k, l, c) in &st.correlated {
        warnings.push(format!(
            "correlated: {} and {} (correlation {c:+.3}): the data fix mainly a combination of the two",
            names[k], names[l]
        ));
    }
    for (k, s) in problem.params.iter().enumerate() {
        if let Some(side) = at_bound(p[k], s.lo, s.hi) {
            warnings.push(format!(
                "at bound: {} = {} is at its {side} bound; the interval assumes an interior optimum — widen the bounds if the physics allows",
                s.name, p[k]
            ));
        }
    }
    if !converged {
        warnings.push(format!("not converged: {reason}"));
    }
    Ok(Fit {
        bounds: lo.iter().copied().zip(hi.iter().copied()).collect(),
        start: problem.start.clone(),
        names,
        p,
        cost,
        history,
        runs: problem.runs(),
        converged,
        reason,
        stats: st,
        warnings,
        wall_s: started.elapsed().as_secs_f64(),
        n_residuals: r.len(),
    })
}

/// `lower` or `upper` if `v` lies within 1e-6 of the range from that bound.
fn at_bound(v: f64, lo: f64, hi: f64) -> Option<&'static str> {
    let tol = 1e-6 * (hi - lo);
    if v <= lo + tol {
        Some("lower")
    } else if v >= hi - tol {
        Some("upper")
    } else {
        None
    }
}

fn finite(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

fn matrix(m: &nalgebra::DMatrix<f64>) -> Value {
    Value::Array(
        (0..m.nrows())
            .map(|k| Value::Array((0..m.ncols()).map(|l| finite(m[(k, l)])).collect()))
            .collect(),
    )
}

impl Fit {
    /// The report as JSON: `{"estimates": {NAME: {"value", "stderr", "ci95": [lo, hi],
    /// "at_bound"}}, "correlation": {"names", "matrix"}, "cost", "iterations", "runs",
    /// "converged", "warnings"}` and `"covariance": {"names", "matrix"}` (for a sweep's
    /// `from_fit` distribution). A number that is not finite (the stderr of an
    /// unidentifiable parameter) is `null`.
    #[must_use]
    pub fn json(&self) -> Value {
        let mut estimates = serde_json::Map::new();
        for (k, n) in self.names.iter().enumerate() {
            let (lo, hi) = self.stats.ci95[k];
            estimates.insert(
                n.clone(),
                json!({
                    "value": self.p[k],
                    "stderr": finite(self.stats.stderr[k]),
                    "ci95": [finite(lo), finite(hi)],
                    "at_bound": at_bound(self.p[k], self.bounds[k].0, self.bounds[k].1).is_some(),
                }),
            );
        }
        json!({
            "estimates": estimates,
            "correlation": {"names": self.names, "matrix": matrix(&self.stats.correlation)},
            "cost": self.cost,
            "iterations": self.history.len(),
            "runs": self.runs,
            "converged": self.converged,
            "warnings": self.warnings,
            "covariance": {"names": self.names, "matrix": matrix(&self.stats.covariance)},
        })
    }

    /// The report as text: the estimates with their intervals, the correlations, the
    /// warnings and the work done.
    #[must_use]
    pub fn text(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let w = self.names.iter().map(String::len).max().unwrap_or(4).max(9);
        let _ = writeln!(
            s,
            "{:<w$}  {:>13}  {:>11}  {:>8}  {:>27}  {:>13}",
            "parameter", "estimate", "stderr", "rel.", "95 % interval", "start"
        );
        for (k, n) in self.names.iter().enumerate() {
            let (lo, hi) = self.stats.ci95[k];
            let se = self.stats.stderr[k];
            let _ = writeln!(
                s,
                "{n:<w$}  {:>13.6e}  {:>11.3e}  {:>7.3}%  [{:>12.5e}, {:>12.5e}]  {:>13.6e}",
                self.p[k],
                se,
                100.0 * se / self.p[k].abs(),
                lo,
                hi,
                self.start[k]
            );
        }
        if self.names.len() > 1 {
            let _ = writeln!(s, "correlation:");
            for (k, n) in self.names.iter().enumerate() {
                let row: Vec<String> = (0..self.names.len())
                    .map(|l| format!("{:+.3}", self.stats.correlation[(k, l)]))
                    .collect();
                let _ = writeln!(s, "  {n:<w$}  {}", row.join("  "));
            }
        }
        let _ = writeln!(
            s,
            "cost {:.6e} over {} residuals (s² = {:.4e}, {} degrees of freedom); {} iterations, {} model runs, {:.2} s; {}",
            self.cost,
            self.n_residuals,
            self.stats.variance,
            self.stats.dof,
            self.history.len(),
            self.runs,
            self.wall_s,
            if self.converged { "converged" } else { "NOT converged" }
        );
        let _ = writeln!(s, "stopped: {}", self.reason);
        for wn in &self.warnings {
            let _ = writeln!(s, "warning: {wn}");
        }
        s
    }
}

/// The model text with the fitted values written in (`toml_edit`: comments and layout
/// kept).
///
/// # Errors
/// A path the text does not take.
pub fn fitted_model(
    file: &str,
    text: &str,
    problem: &Problem,
    p: &[f64],
) -> Result<String, String> {
    bg_model::overrides::apply(file, text, &problem.overrides(p)).map_err(|e| e.to_string())
}

/// Draw data against the fitted model and the residuals over time, one pair of panels per
/// fitted output (experiment 1; the others as their own files `STEM-2.png`, …).
///
/// # Errors
/// A run or the drawing fails.
pub fn plot_fit(
    problem: &Problem,
    p: &[f64],
    path: &Path,
) -> Result<Vec<std::path::PathBuf>, String> {
    use bg_model::plots::{Panel, Plot, Series};
    let reg = (problem.registry)();
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let stem = path
        .file_stem()
        .map_or_else(|| "fit".to_owned(), |s| s.to_string_lossy().into_owned());
    let mut written = Vec::new();
    for (x, e) in problem.experiments.iter().enumerate() {
        let y = problem.simulate(&reg, e, p)?;
        let tcol = e
            .data
            .column("t")
            .or_else(|| e.data.column("time"))
            .unwrap_or(0);
        let mut head = vec!["t".to_owned()];
        for &(j, _) in &e.fitted {
            let n = &problem.outputs[j];
            head.extend([
                format!("{n}_data"),
                format!("{n}_fit"),
                format!("{n}_residual"),
            ]);
        }
        let mut csv = head.join(",");
        csv.push('\n');
        let n = e.fitted.len();
        for (row, &i) in e.rows.iter().enumerate() {
            csv.push_str(&format!("{}", e.data.columns[tcol][i]));
            for (c, &(_, k)) in e.fitted.iter().enumerate() {
                let d = e.data.columns[k][i];
                let m = y[row * n + c];
                csv.push_str(&format!(",{d},{m},{}", d - m));
            }
            csv.push('\n');
        }
        let results =
            crate::plot::Results::parse(&csv).map_err(|(l, m)| format!("line {l}: {m}"))?;
        let series = |column: String, label: &str, dashed: bool| Series {
            column,
            label: label.to_owned(),
            scale: 1.0,
            offset: 0.0,
            dashed,
            line: 0,
        };
        let mut panels = Vec::new();
        for &(j, _) in &e.fitted {
            let nm = &problem.outputs[j];
            panels.push(Panel {
                y_label: nm.clone(),
                unit: None,
                x_range: None,
                series: vec![
                    series(format!("{nm}_data"), "measured", false),
                    series(format!("{nm}_fit"), "fitted model", true),
                ],
                line: 0,
            });
            panels.push(Panel {
                y_label: format!("{nm}: data − model"),
                unit: None,
                x_range: None,
                series: vec![series(format!("{nm}_residual"), "residual", false)],
                line: 0,
            });
        }
        let file = if x == 0 {
            stem.clone()
        } else {
            format!("{stem}-{}", x + 1)
        };
        let plot = Plot {
            file,
            title: format!("Fit to {}", e.file),
            x: "t".into(),
            x_label: "time [s]".into(),
            panels,
            line: 0,
        };
        written.extend(
            crate::plot::draw(&results, &plot, dir, crate::plot::Format::Png)
                .map_err(|e| e.to_string())?,
        );
    }
    Ok(written)
}
