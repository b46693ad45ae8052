//! A bounded Levenberg–Marquardt for `min ½ Σ ρ_i r_i(p)²`, `lo ≤ p ≤ hi`.
//!
//! Each iteration solves the damped normal equations `(JᵀJ + λ·diag(JᵀJ)) δ = −Jᵀr`
//! (Marquardt's scaling, so the method does not care about the parameters' units) on the
//! parameters that are free: one held at a bound whose gradient pushes it out stays there
//! (an active set). The step is projected onto the box, and accepted when the cost falls by
//! more than 1e-4 of what the quadratic model predicts for the projected step; λ follows
//! Nielsen's update (the ratio ρ of actual to predicted decrease: λ·max(1/3, 1 − (2ρ − 1)³)
//! on success, λ·ν with ν doubling on failure), which is the trust-region method written in
//! terms of its multiplier. Bounds are thus handled by projection, not by a transformed
//! variable: the covariance at the end is in the parameters themselves.
//!
//! With the Huber loss the rows carry weights ρ_i = min(1, c/|r_i|), c = 1.345 · 1.4826 ·
//! median |r| (a robust standard deviation), set anew at every accepted point (iteratively
//! reweighted least squares).

use nalgebra::{DMatrix, DVector};

use super::problem::Loss;

/// r(p).
pub type ResidualFn<'a> = dyn Fn(&[f64]) -> Result<Vec<f64>, String> + 'a;
/// r(p) and ∂r/∂p.
pub type JacobianFn<'a> = dyn Fn(&[f64]) -> Result<(Vec<f64>, DMatrix<f64>), String> + 'a;

/// Stopping rules.
#[derive(Clone, Copy, Debug)]
pub struct LmOptions {
    /// Most iterations (Jacobian evaluations).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub ftol: f64,
    /// Stop when the step is smaller than this fraction of every parameter.
    pub xtol: f64,
    /// The loss.
    pub loss: Loss,
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_iterations: 50,
            ftol: 1e-9,
            xtol: 1e-8,
            loss: Loss::L2,
        }
    }
}

/// One iteration of the fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Iteration {
    /// Cost ½ Σ ρ r² after the iteration.
    pub cost: f64,
    /// Largest relative step |δ_k| / max(|p_k|, tiny) taken.
    pub step: f64,
    /// The damping λ used.
    pub lambda: f64,
    /// Trial points rejected on the way.
    pub rejected: usize,
}

/// What [`lm`] found.
#[derive(Clone, Debug)]
pub struct LmResult {
    /// The estimate.
    pub p: Vec<f64>,
    /// Residuals there (unweighted by the loss).
    pub r: Vec<f64>,
    /// Their Jacobian there.
    pub j: DMatrix<f64>,
    /// The loss weights ρ_i there (all 1 for L2).
    pub rho: Vec<f64>,
    /// Final cost.
    pub cost: f64,
    /// The iterations.
    pub history: Vec<Iteration>,
    /// Whether a stopping rule other than the iteration limit ended it.
    pub converged: bool,
    /// Why it stopped.
    pub reason: String,
}

fn loss_weights(loss: Loss, r: &[f64]) -> Vec<f64> {
    match loss {
        Loss::L2 => vec![1.0; r.len()],
        Loss::Huber => {
            let mut a: Vec<f64> = r.iter().map(|v| v.abs()).collect();
            a.sort_by(f64::total_cmp);
            let med = a.get(a.len() / 2).copied().unwrap_or(0.0);
            let c = 1.345 * 1.4826 * med;
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
    }
}

fn cost_of(r: &[f64], rho: &[f64]) -> f64 {
    0.5 * r.iter().zip(rho).map(|(v, w)| w * v * v).sum::<f64>()
}

/// Minimise from `p0` within `[lo, hi]`; `residuals` evaluates r(p), `jacobian` r(p) and
/// ∂r/∂p together.
///
/// # Errors
/// A failed evaluation at the start or of the Jacobian (a failed trial point is a rejected
/// step, not an error).
#[allow(clippy::too_many_lines)]
pub fn lm(
    residuals: &ResidualFn<'_>,
    jacobian: &JacobianFn<'_>,
    p0: &[f64],
    lo: &[f64],
    hi: &[f64],
    opts: &LmOptions,
    on_iteration: &mut dyn FnMut(usize, &Iteration, &[f64]),
) -> Result<LmResult, String> {
    let np = p0.len();
    let mut p: Vec<f64> = p0
        .iter()
        .zip(lo.iter().zip(hi))
        .map(|(v, (l, h))| v.clamp(*l, *h))
        .collect();
    let (mut r, mut j) = jacobian(&p)?;
    let mut rho = loss_weights(opts.loss, &r);
    let mut cost = cost_of(&r, &rho);
    let mut lambda = 1e-3;
    let mut nu = 2.0;
    let mut history = Vec::new();
    let mut converged = false;
    let mut reason = format!("{} iterations, the limit", opts.max_iterations);
    'outer: for it in 0..opts.max_iterations {
        // the weighted normal equations
        let mut a = DMatrix::<f64>::zeros(np, np);
        let mut g = DVector::<f64>::zeros(np);
        for i in 0..r.len() {
            for k in 0..np {
                let jk = j[(i, k)] * rho[i];
                g[k] += jk * r[i];
                for l in k..np {
                    a[(k, l)] += jk * j[(i, l)];
                }
            }
        }
        for k in 0..np {
            for l in 0..k {
                a[(k, l)] = a[(l, k)];
            }
        }
        let width = |k: usize| hi[k] - lo[k];
        let free: Vec<usize> = (0..np)
            .filter(|&k| {
                let at_lo = p[k] <= lo[k] + 1e-12 * width(k);
                let at_hi = p[k] >= hi[k] - 1e-12 * width(k);
                !(at_lo && g[k] > 0.0 || at_hi && g[k] < 0.0)
            })
            .collect();
        if free.is_empty() {
            converged = true;
            reason = "every parameter is held at a bound".into();
            break;
        }
        let gnorm = free
            .iter()
            .map(|&k| (g[k] * (p[k].abs().max(width(k) * 1e-6))).abs())
            .fold(0.0, f64::max);
        if gnorm <= 1e-12 * cost.max(f64::MIN_POSITIVE) {
            converged = true;
            reason = "the gradient vanishes".into();
            break;
        }
        let mut rejected = 0;
        loop {
            let nf = free.len();
            let mut m = DMatrix::<f64>::zeros(nf, nf);
            let mut b = DVector::<f64>::zeros(nf);
            for (x, &k) in free.iter().enumerate() {
                b[x] = -g[k];
                for (y, &l) in free.iter().enumerate() {
                    m[(x, y)] = a[(k, l)];
                }
                m[(x, x)] += lambda * a[(k, k)].max(1e-30);
            }
            let delta = m
                .clone()
                .cholesky()
                .map(|c| c.solve(&b))
                .or_else(|| m.lu().solve(&b));
            let Some(delta) = delta else {
                lambda *= nu;
                nu *= 2.0;
                rejected += 1;
                if lambda > 1e16 {
                    reason = "the damped step could not be solved".into();
                    break 'outer;
                }
                continue;
            };
            let mut trial = p.clone();
            for (x, &k) in free.iter().enumerate() {
                trial[k] = (p[k] + delta[x]).clamp(lo[k], hi[k]);
            }
            let d: DVector<f64> = DVector::from_iterator(np, (0..np).map(|k| trial[k] - p[k]));
            let predicted = -(g.dot(&d) + 0.5 * d.dot(&(&a * &d)));
            let step = (0..np)
                .map(|k| d[k].abs() / p[k].abs().max(1e-300))
                .fold(0.0, f64::max);
            let tried = residuals(&trial)
                .ok()
                .filter(|rt| rt.iter().all(|v| v.is_finite()));
            let (ratio, rt) = match tried {
                Some(rt) if predicted > 0.0 => ((cost - cost_of(&rt, &rho)) / predicted, Some(rt)),
                _ => (-1.0, None),
            };
            if ratio > 1e-4 {
                let old = cost;
                p = trial;
                let (r2, j2) = jacobian(&p)?;
                let _ = rt;
                r = r2;
                j = j2;
                rho = loss_weights(opts.loss, &r);
                cost = cost_of(&r, &rho);
                lambda *= f64::max(1.0 / 3.0, 1.0 - (2.0 * ratio - 1.0).powi(3));
                nu = 2.0;
                let iter = Iteration {
                    cost,
                    step,
                    lambda,
                    rejected,
                };
                on_iteration(it + 1, &iter, &p);
                history.push(iter);
                if (old - cost).abs() <= opts.ftol * old {
                    converged = true;
                    reason = format!("the cost fell by less than {:e} of itself", opts.ftol);
                    break 'outer;
                }
                if step <= opts.xtol {
                    converged = true;
                    reason = format!("the step is below {:e} of every parameter", opts.xtol);
                    break 'outer;
                }
                continue 'outer;
            }
            rejected += 1;
            if step <= opts.xtol && rt.is_some() {
                converged = true;
                reason = "no smaller step lowers the cost".into();
                break 'outer;
            }
            lambda *= nu;
            nu *= 2.0;
            if lambda > 1e16 {
                converged = step <= 1e-6;
                reason = "no step lowers the cost (λ > 1e16)".into();
                break 'outer;
            }
        }
    }
    Ok(LmResult {
        p,
        r,
        j,
        rho,
        cost,
        history,
        converged,
        reason,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Rosenbrock as least squares: r = (10(y − x²), 1 − x); minimum at (1, 1), cost 0.
    fn rosen(p: &[f64]) -> Vec<f64> {
        vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]]
    }
    fn rosen_j(p: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
        (
            rosen(p),
            DMatrix::from_row_slice(2, 2, &[-20.0 * p[0], 10.0, -1.0, 0.0]),
        )
    }

    #[test]
    fn finds_the_rosenbrock_minimum() {
        let res = lm(
            &|p| Ok(rosen(p)),
            &|p| Ok(rosen_j(p)),
            &[-1.2, 1.0],
            &[-5.0, -5.0],
            &[5.0, 5.0],
            &LmOptions::default(),
            &mut |_, _, _| {},
        )
        .unwrap();
        assert!(
            (res.p[0] - 1.0).abs() < 1e-6 && (res.p[1] - 1.0).abs() < 1e-6,
            "{:?}",
            res.p
        );
        assert!(res.converged, "{}", res.reason);
        assert!(res.history.len() < 30, "{}", res.history.len());
    }

    #[test]
    fn holds_a_parameter_at_its_bound() {
        // the unconstrained minimum x = 1 lies outside x ≤ 0.5: the bounded one is x = 0.5,
        // y = 0.25 (r₁ = 0 there)
        let res = lm(
            &|p| Ok(rosen(p)),
            &|p| Ok(rosen_j(p)),
            &[-1.2, 1.0],
            &[-5.0, -5.0],
            &[0.5, 5.0],
            &LmOptions::default(),
            &mut |_, _, _| {},
        )
        .unwrap();
        assert!((res.p[0] - 0.5).abs() < 1e-9, "{:?}", res.p);
        assert!((res.p[1] - 0.25).abs() < 1e-6, "{:?}", res.p);
    }
}
