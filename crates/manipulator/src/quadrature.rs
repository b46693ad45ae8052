//! Gauss–Legendre quadrature on `[0, L]`, used for every integral along a link (eqs. 42, 45,
//! 51).
//!
//! # Which rule and why
//! An n-point Gauss–Legendre rule is exact for polynomials of degree ≤ 2n − 1. The integrands
//! along a link are products of the mode shapes with polynomials of degree ≤ 2 in x (the
//! moment arms of the joint lines). For a rigid link they are polynomials of degree ≤ 2, so
//! two points are exact. The sine modes are not polynomials, and with the twists built from
//! the *deformed* positions the mass matrix also holds products of two modes with the moment
//! arms; the integrands are entire functions of x with wavenumbers up to `2·n_ψ·π/L`, and
//! the Gauss–Legendre error for such integrands falls faster than any power of n (for
//! `cos(κx)` on `[0, L]` it is about `(κL/2)^{2n} (n!)⁴ / ((2n+1) ((2n)!)³)`, i.e. below
//! 1e-16 relative for κL ≤ 6π and n ≥ 16). The default, [`GaussLegendre::DEFAULT_POINTS`]
//! = 16 points per link, therefore integrates the mode products ∫ψ_kψ_l, ∫θ_kθ_l, ∫ψ''_kψ''_l
//! to rounding error for up to three sine modes per link; the tests check this and the
//! convergence of M(q) at deformed configurations. With more modes, raise the point count
//! (about 5 points per mode is plenty).

use bondgraph::ParamError;

/// Nodes and weights of an n-point Gauss–Legendre rule on `[0, 1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussLegendre {
    /// The default number of points per link.
    pub const DEFAULT_POINTS: usize = 16;

    /// The n-point rule (n ≥ 1), nodes by Newton's method on the Legendre polynomial P_n.
    pub fn new(n: usize) -> Result<Self, ParamError> {
        if n == 0 || n > 512 {
            return Err(ParamError::invalid(
                "quadrature_points",
                n as f64,
                "an integer in 1..=512",
            ));
        }
        let mut nodes = vec![0.0; n];
        let mut weights = vec![0.0; n];
        let nf = n as f64;
        for i in 0..n.div_ceil(2) {
            // Initial guess (Tricomi), then Newton on P_n.
            let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre(n, z);
                dp = d;
                let dz = p / d;
                z -= dz;
                if dz.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre(n, z);
            if d.is_finite() {
                dp = d;
            }
            let w = 2.0 / ((1.0 - z * z) * dp * dp);
            // map [-1, 1] → [0, 1]
            nodes[i] = 0.5 * (1.0 - z);
            nodes[n - 1 - i] = 0.5 * (1.0 + z);
            weights[i] = 0.5 * w;
            weights[n - 1 - i] = 0.5 * w;
        }
        Ok(Self { nodes, weights })
    }

    /// Number of points.
    #[must_use]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the rule has no points (never, once built).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Nodes and weights scaled to `[0, length]`.
    pub fn on(&self, length: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(move |(x, w)| (x * length, w * length))
    }

    /// `∫_0^L f(x) dx`.
    pub fn integrate(&self, length: f64, f: impl Fn(f64) -> f64) -> f64 {
        self.on(length).map(|(x, w)| w * f(x)).sum()
    }
}

/// `(P_n(z), P_n'(z))` by the three-term recurrence.
fn legendre(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let nf = n as f64;
    (p1, nf * (z * p1 - p0) / (z * z - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn exact_for_polynomials_up_to_degree_2n_minus_1() {
        for n in [1, 2, 3, 5, 8, 16] {
            let q = GaussLegendre::new(n).unwrap();
            for d in 0..2 * n {
                let got = q.integrate(3.0, |x| x.powi(d as i32));
                let exact = 3.0f64.powi(d as i32 + 1) / (d as f64 + 1.0);
                assert!(
                    (got - exact).abs() < 1e-13 * exact,
                    "n {n} degree {d}: {got} vs {exact}"
                );
            }
            // and not for degree 2n
            let d = 2 * n as i32;
            let got = q.integrate(1.0, |x| (2.0 * x - 1.0).powi(d));
            assert!((got - 1.0 / (d as f64 + 1.0)).abs() > 1e-12, "n {n}");
        }
    }

    #[test]
    fn default_rule_integrates_the_sine_mode_products_to_rounding() {
        let q = GaussLegendre::new(GaussLegendre::DEFAULT_POINTS).unwrap();
        let l = 10.0;
        for k in 1..=3 {
            for m in 1..=3 {
                let s = |j: i32, x: f64| (f64::from(j) * PI * x / l).sin();
                let c = |j: i32, x: f64| (f64::from(j) * PI * x / l).cos();
                let ss = q.integrate(l, |x| s(k, x) * s(m, x));
                let cc = q.integrate(l, |x| c(k, x) * c(m, x));
                let want = if k == m { l / 2.0 } else { 0.0 };
                assert!((ss - want).abs() < 1e-13 * l, "{k} {m}: {ss}");
                assert!((cc - want).abs() < 1e-13 * l, "{k} {m}: {cc}");
            }
        }
        assert!(GaussLegendre::new(0).is_err());
    }
}
