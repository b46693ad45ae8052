//! `bg-sim bench`: the speed–accuracy trade of a model, measured.
//!
//! A reference run (BDF at a tight tolerance) first; then every solver at every relative
//! tolerance, each timed as the median of a few repeats. The error of a run is, over every
//! output column, the largest |x − x_ref| divided by that column's largest |x_ref| (columns
//! that stay at zero are left out); the worst column is named.

use std::time::Duration;

use bg_model::Model;
use bondgraph::{Method, Outcome, Trajectory};

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct BenchRow {
    /// Method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations, Jacobians included.
    pub rhs_evals: usize,
    /// Median wall time of the integration.
    pub wall: Duration,
    /// Worst relative error over the columns, and that column (`None` if the run failed).
    pub error: Option<(f64, String)>,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
}

/// The worst relative difference of `run` from `reference` over their common columns.
#[must_use]
pub fn worst_relative_error(run: &Trajectory, reference: &Trajectory) -> Option<(f64, String)> {
    if run.rows.len() != reference.rows.len() {
        return None;
    }
    let mut worst: Option<(f64, String)> = None;
    for (j, name) in reference.columns.iter().enumerate().skip(1) {
        let Some(k) = run.columns.iter().position(|c| c == name) else {
            continue;
        };
        let scale = reference
            .rows
            .iter()
            .map(|r| r[j].abs())
            .fold(0.0, f64::max);
        if scale <= f64::MIN_POSITIVE || !scale.is_finite() {
            continue;
        }
        let err = run
            .rows
            .iter()
            .zip(&reference.rows)
            .map(|(a, b)| (a[k] - b[j]).abs())
            .fold(0.0, f64::max)
            / scale;
        if worst.as_ref().is_none_or(|(w, _)| err > *w || err.is_nan()) {
            worst = Some((err, name.clone()));
        }
    }
    worst
}

fn run_once(model: &mut Model, method: Method, rtol: f64) -> Result<Outcome, String> {
    model.settings.method = method;
    model.settings.rtol = rtol;
    model.run().map_err(|e| e.to_string())
}

/// Measure `methods` × `rtols` against a BDF reference at `reference_rtol`, each timed as the
/// median of `repeat` runs.
pub fn bench(
    model: &mut Model,
    methods: &[Method],
    rtols: &[f64],
    reference_rtol: f64,
    repeat: usize,
) -> Result<(Outcome, Vec<BenchRow>), String> {
    let reference = run_once(model, Method::Bdf, reference_rtol)?;
    if let Some(e) = &reference.error {
        return Err(format!(
            "the reference run (bdf, rtol {reference_rtol:e}) failed: {e}"
        ));
    }
    let mut rows = Vec::new();
    for &method in methods {
        for &rtol in rtols {
            let mut walls = Vec::new();
            let mut last = None;
            for _ in 0..repeat.max(1) {
                let out = run_once(model, method, rtol)?;
                walls.push(out.stats.wall_time);
                let failed = out.error.is_some();
                last = Some(out);
                if failed {
                    break;
                }
            }
            let Some(out) = last else { continue };
            walls.sort();
            rows.push(BenchRow {
                method,
                rtol,
                steps: out.stats.steps,
                rhs_evals: out.stats.rhs_evals + out.stats.jac_rhs_evals,
                wall: walls[walls.len() / 2],
                error: out
                    .error
                    .is_none()
                    .then(|| worst_relative_error(&out.trajectory, &reference.trajectory))
                    .flatten(),
                failure: out.error.map(|e| e.to_string()),
            });
        }
    }
    Ok((reference, rows))
}

/// The rows as a Markdown table.
#[must_use]
pub fn table(rows: &[BenchRow]) -> String {
    let mut s = String::from("| solver | rtol | steps | rhs evals | wall (ms) | worst rel. error | column |\n|---|---|---|---|---|---|---|\n");
    for r in rows {
        let (err, col) = match (&r.error, &r.failure) {
            (Some((e, c)), _) => (format!("{e:.2e}"), c.clone()),
            (None, Some(f)) => ("failed".to_owned(), f.chars().take(60).collect()),
            (None, None) => ("–".to_owned(), String::new()),
        };
        s.push_str(&format!(
            "| {} | {:.0e} | {} | {} | {:.2} | {err} | {col} |\n",
            r.method.name(),
            r.rtol,
            r.steps,
            r.rhs_evals,
            r.wall.as_secs_f64() * 1e3
        ));
    }
    s
}
