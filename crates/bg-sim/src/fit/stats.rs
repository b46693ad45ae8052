//! How well the data fix each parameter: the covariance of the estimate from the Fisher
//! information, standard errors, 95 % intervals, correlations and the warnings.
//!
//! With weighted residuals r = √W (y(p) − d) and Jacobian J = ∂r/∂p at the estimate, the
//! residual variance is s² = Σ ρ r² / (N − P) and the covariance of the estimate
//! C = s² (JᵀJ)⁻¹ (the information JᵀWJ of the raw residuals, scaled by the variance the
//! fit leaves). The interval is p ± t₀.₉₇₅,N−P · √C_kk. All of this is the linearisation at
//! the estimate: exact for a model linear in p with independent Gaussian noise of constant
//! variance per output, approximate otherwise (docs/fit.md, "When the intervals lie").

use nalgebra::DMatrix;

/// A correlation above this is flagged.
pub const CORRELATION_WARNING: f64 = 0.95;
/// The information is near-singular when its smallest eigenvalue (of the matrix scaled to
/// unit diagonal) is below this.
pub const SINGULAR: f64 = 1e-8;

/// The statistics of an estimate.
#[derive(Clone, Debug)]
pub struct Stats {
    /// Residual variance s².
    pub variance: f64,
    /// Degrees of freedom N − P.
    pub dof: usize,
    /// Covariance, P × P (infinite entries where the information is singular).
    pub covariance: DMatrix<f64>,
    /// Standard errors.
    pub stderr: Vec<f64>,
    /// 95 % intervals.
    pub ci95: Vec<(f64, f64)>,
    /// Correlation matrix.
    pub correlation: DMatrix<f64>,
    /// Smallest eigenvalue of the information scaled to unit diagonal (1: orthogonal, 0:
    /// singular).
    pub min_eigenvalue: f64,
    /// The parameters in that weakest direction (|component| > 0.3), if it is near-singular.
    pub unidentifiable: Vec<usize>,
    /// Pairs with |correlation| above [`CORRELATION_WARNING`].
    pub correlated: Vec<(usize, usize, f64)>,
}

/// Student's t quantile t₀.₉₇₅ with `dof` degrees of freedom (the table to 10, the
/// Cornish–Fisher expansion above: within 1e-3 from 11 on).
#[must_use]
pub fn t975(dof: usize) -> f64 {
    const TABLE: [f64; 11] = [
        f64::INFINITY,
        12.706,
        4.303,
        3.182,
        2.776,
        2.571,
        2.447,
        2.365,
        2.306,
        2.262,
        2.228,
    ];
    if dof <= 10 {
        return TABLE[dof];
    }
    let z: f64 = 1.959_963_984_540_054;
    #[allow(clippy::cast_precision_loss)]
    let v = dof as f64;
    let z3 = z.powi(3);
    let z5 = z.powi(5);
    let z7 = z.powi(7);
    z + (z3 + z) / (4.0 * v)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * v * v)
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * v * v * v)
}

/// The statistics at estimate `p` with residuals `r`, loss weights `rho` and Jacobian `j`.
#[must_use]
pub fn stats(p: &[f64], r: &[f64], rho: &[f64], j: &DMatrix<f64>) -> Stats {
    let np = p.len();
    let n = r.len();
    let dof = n.saturating_sub(np).max(1);
    #[allow(clippy::cast_precision_loss)]
    let variance = r.iter().zip(rho).map(|(v, w)| w * v * v).sum::<f64>() / dof as f64;
    let mut info = DMatrix::<f64>::zeros(np, np);
    for i in 0..n {
        for k in 0..np {
            for l in 0..np {
                info[(k, l)] += rho[i] * j[(i, k)] * j[(i, l)];
            }
        }
    }
    // scale to unit diagonal: the conditioning free of the parameters' units
    let d: Vec<f64> = (0..np).map(|k| info[(k, k)].sqrt()).collect();
    let mut scaled = info.clone();
    for k in 0..np {
        for l in 0..np {
            let s = d[k] * d[l];
            scaled[(k, l)] = if s > 0.0 { info[(k, l)] / s } else { 0.0 };
        }
    }
    let eig = scaled.clone().symmetric_eigen();
    let (imin, min_eigenvalue) = eig
        .eigenvalues
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, 0.0));
    let unidentifiable: Vec<usize> = if min_eigenvalue < SINGULAR {
        (0..np)
            .filter(|&k| eig.eigenvectors[(k, imin)].abs() > 0.3)
            .collect()
    } else {
        Vec::new()
    };
    // C = s² D⁻¹ S⁻¹ D⁻¹ through the eigen-decomposition (an eigenvalue at round-off level
    // makes its direction's variance infinite, not a number from noise)
    let mut cov = DMatrix::<f64>::zeros(np, np);
    let top = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
    for (m, &lam) in eig.eigenvalues.iter().enumerate() {
        let inv = if lam > 1e-14 * top {
            1.0 / lam
        } else {
            f64::INFINITY
        };
        for k in 0..np {
            for l in 0..np {
                let v = eig.eigenvectors[(k, m)] * eig.eigenvectors[(l, m)];
                if v != 0.0 {
                    cov[(k, l)] += inv * v;
                }
            }
        }
    }
    for k in 0..np {
        for l in 0..np {
            let s = d[k] * d[l];
            cov[(k, l)] = if s > 0.0 {
                variance * cov[(k, l)] / s
            } else {
                f64::INFINITY
            };
        }
    }
    let stderr: Vec<f64> = (0..np).map(|k| cov[(k, k)].abs().sqrt()).collect();
    let t = t975(dof);
    let ci95 = p
        .iter()
        .zip(&stderr)
        .map(|(v, s)| (v - t * s, v + t * s))
        .collect();
    let mut correlation = DMatrix::<f64>::identity(np, np);
    let mut correlated = Vec::new();
    for k in 0..np {
        for l in 0..np {
            if k != l {
                let c = cov[(k, l)] / (stderr[k] * stderr[l]);
                // an infinite covariance: the correlation of the scaled information instead
                let c = if c.is_finite() { c } else { -scaled[(k, l)] };
                correlation[(k, l)] = c.clamp(-1.0, 1.0);
                if l > k && c.abs() > CORRELATION_WARNING {
                    correlated.push((k, l, c));
                }
            }
        }
    }
    Stats {
        variance,
        dof,
        covariance: cov,
        stderr,
        ci95,
        correlation,
        min_eigenvalue,
        unidentifiable,
        correlated,
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn t_quantiles_match_the_table() {
        // t₀.₉₇₅: 2.571 (5), 2.228 (10), 2.201 (11), 2.086 (20), 2.042 (30), 1.984 (100)
        for (dof, t) in [
            (5, 2.571),
            (10, 2.228),
            (11, 2.201),
            (20, 2.086),
            (30, 2.042),
            (100, 1.984),
            (1_000_000, 1.960),
        ] {
            assert!((t975(dof) - t).abs() < 2e-3, "{dof}: {} vs {t}", t975(dof));
        }
    }

    #[test]
    fn straight_line_fit_matches_the_textbook_formulas() {
        // y = a + b x at x = 0..9 with residuals ±1 alternating: s² = Σr²/(n−2), var(b) =
        // s²/Sxx, var(a) = s² (1/n + x̄²/Sxx)
        let n = 10;
        let x: Vec<f64> = (0..n).map(f64::from).collect();
        let r: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let mut j = DMatrix::zeros(10, 2);
        for i in 0..10 {
            j[(i, 0)] = 1.0;
            j[(i, 1)] = x[i];
        }
        let s = stats(&[1.0, 2.0], &r, &[1.0; 10], &j);
        let s2 = 10.0 / 8.0;
        let sxx: f64 = x.iter().map(|v| (v - 4.5) * (v - 4.5)).sum();
        assert!((s.variance - s2).abs() < 1e-12);
        assert!((s.stderr[1] - (s2 / sxx).sqrt()).abs() < 1e-12);
        assert!((s.stderr[0] - (s2 * (0.1 + 4.5 * 4.5 / sxx)).sqrt()).abs() < 1e-12);
        let corr = -4.5 / (sxx / 10.0 + 4.5 * 4.5).sqrt();
        assert!(
            (s.correlation[(0, 1)] - corr).abs() < 1e-12,
            "{}",
            s.correlation
        );
        assert!(s.unidentifiable.is_empty());
    }

    #[test]
    fn a_product_pair_is_unidentifiable() {
        // y = a·b·x: the columns a·x·b-ish are proportional → singular information
        let (a, b) = (2.0, 3.0);
        let mut j = DMatrix::zeros(5, 2);
        for i in 0..5 {
            let x = f64::from(i as u8 + 1);
            j[(i, 0)] = b * x;
            j[(i, 1)] = a * x;
        }
        let s = stats(&[a, b], &[0.1, -0.1, 0.1, -0.1, 0.1], &[1.0; 5], &j);
        assert_eq!(s.unidentifiable, vec![0, 1]);
        assert!(s.min_eigenvalue < 1e-12);
        assert!(!s.stderr[0].is_finite() || s.stderr[0] > 1e6);
    }
}
