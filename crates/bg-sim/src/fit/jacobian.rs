//! The Jacobian of the residuals, ∂r/∂p, by central finite differences of whole runs
//! (`--jacobian fd`): two runs per parameter, in parallel on the rayon pool. It is the
//! derivative the fit falls back on, and the comparison for exact sensitivities.
//!
//! The step is `h_k = 1e-4 · max(|p_k|, 1e-3 · (hi_k − lo_k))` (relative): the truncation
//! error of the central difference is O(h²) ≈ 1e-8 of the curvature scale, and the run's own
//! error (rtol) is amplified by 1/h, so finite differences want a tight `--rtol` (the fit
//! asks for 1e-7 or tighter unless told).

use nalgebra::DMatrix;
use rayon::prelude::*;

use super::problem::Problem;

/// Relative step of the central differences.
pub const FD_STEP: f64 = 1e-4;

/// The step for parameter `k` at value `v`.
#[must_use]
pub fn step(problem: &Problem, k: usize, v: f64) -> f64 {
    let s = &problem.params[k];
    FD_STEP * v.abs().max(1e-3 * (s.hi - s.lo))
}

/// Residuals and their Jacobian (rows: residuals, columns: parameters) at `p` by central
/// differences: 2·P + 1 runs per experiment, the perturbed ones in parallel.
///
/// # Errors
/// A run that fails.
pub fn residuals_and_jacobian(
    problem: &Problem,
    p: &[f64],
) -> Result<(Vec<f64>, DMatrix<f64>), String> {
    let np = p.len();
    // job 0: the centre; job 2k+1: +h_k; job 2k+2: −h_k
    let jobs: Vec<Vec<f64>> = std::iter::once(p.to_vec())
        .chain((0..np).flat_map(|k| {
            let h = step(problem, k, p[k]);
            let mut plus = p.to_vec();
            plus[k] += h;
            let mut minus = p.to_vec();
            minus[k] -= h;
            [plus, minus]
        }))
        .collect();
    let results: Vec<Result<Vec<f64>, String>> = jobs
        .par_iter()
        .map_init(problem.registry, |reg, q| problem.residuals(reg, q))
        .collect();
    let mut it = results.into_iter();
    let r0 = it.next().unwrap_or_else(|| Err("no run".into()))?;
    let mut j = DMatrix::zeros(r0.len(), np);
    for k in 0..np {
        let plus = it.next().unwrap_or_else(|| Err("no run".into()))?;
        let minus = it.next().unwrap_or_else(|| Err("no run".into()))?;
        let h = step(problem, k, p[k]);
        for i in 0..r0.len() {
            j[(i, k)] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    Ok((r0, j))
}

/// Residuals and their Jacobian at `p` from the exact forward sensitivities of the core
/// ([`bg_model::Model::sensitivities`]: the sensitivity equations integrated alongside the
/// run, reusing its Jacobian and LU): one run per experiment, whatever the number of
/// parameters. The model's outputs and their derivatives are interpolated to the data's
/// times as the residuals are.
///
/// # Errors
/// A run that fails, or a parameter the sensitivities do not take.
pub fn exact_residuals_and_jacobian(
    problem: &Problem,
    p: &[f64],
) -> Result<(Vec<f64>, DMatrix<f64>), String> {
    use std::sync::atomic::Ordering;
    let reg = (problem.registry)();
    let names: Vec<String> = problem.params.iter().map(|s| s.path.clone()).collect();
    let np = p.len();
    let mut r = Vec::with_capacity(problem.n_residuals());
    let mut jrows: Vec<f64> = Vec::with_capacity(problem.n_residuals() * np);
    for e in &problem.experiments {
        let mut m = problem.model(&reg, e, p)?;
        problem.runs.fetch_add(1, Ordering::Relaxed);
        let s = m.sensitivities(&names).map_err(|e| e.to_string())?;
        let no = s.outputs.len();
        let cols: Vec<usize> = e
            .fitted
            .iter()
            .map(|&(j, _)| {
                s.outputs
                    .iter()
                    .position(|o| *o == problem.outputs[j])
                    .ok_or_else(|| {
                        format!(
                            "output `{}` missing from the sensitivities",
                            problem.outputs[j]
                        )
                    })
            })
            .collect::<Result<_, _>>()?;
        let tcol = e
            .data
            .column("t")
            .or_else(|| e.data.column("time"))
            .unwrap_or(0);
        let times = &e.data.columns[tcol];
        for &i in &e.rows {
            let (a, b, w) = super::problem::bracket(&s.t, times[i]);
            for (c, &(j, k)) in e.fitted.iter().enumerate() {
                let col = cols[c];
                let sw = problem.weights[j].sqrt();
                let y = s.y[a * no + col] + w * (s.y[b * no + col] - s.y[a * no + col]);
                r.push(sw * (y - e.data.columns[k][i]));
                for kk in 0..np {
                    let (da, db) = (s.get(a, col, kk), s.get(b, col, kk));
                    jrows.push(sw * (da + w * (db - da)));
                }
            }
        }
    }
    Ok((r.clone(), DMatrix::from_row_slice(r.len(), np, &jrows)))
}
