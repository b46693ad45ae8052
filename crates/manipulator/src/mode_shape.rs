//! Assumed modes `ψ_k(x)` of a flexible link (section 3.1): the transverse deflection of the
//! link at distance x along its chord is `w(x) = Σ_k ψ_k(x) q_k^b`.
//!
//! Joint angles are chord-to-chord (docs/knuckle-boom.md), so every mode must vanish at both ends of
//! the chord, `ψ(0) = ψ(L) = 0`: the deflection of a link then never moves the next joint, and
//! the projection matrix of a link holds only its own modes (eq. 38). [`Link`] checks this
//! when a mode is attached.
//!
//! [`Link`]: crate::Link

use std::f64::consts::PI;
use std::fmt::Debug;

/// A mode shape: its value, slope and curvature along the chord, `0 ≤ x ≤ L`.
pub trait ModeShape: Debug + Send + Sync {
    /// `ψ(x)` (dimensionless: the deflection per unit modal coordinate).
    fn value(&self, x: f64) -> f64;
    /// `θ(x) = ψ'(x)` (1/m): the rotation of the cross-section per unit modal coordinate.
    fn slope(&self, x: f64) -> f64;
    /// `ψ''(x)` (1/m²): the curvature, for the strain energy (eq. 50).
    fn curvature(&self, x: f64) -> f64;
    /// `Some(κ)` if `ψ(x) = sin(κx)` exactly: the link's shape integrals are then taken in
    /// closed form ([`ShapeIntegrals`](crate::ShapeIntegrals)); `None` (the default): by
    /// quadrature.
    fn sine_wavenumber(&self) -> Option<f64> {
        None
    }
}

/// The k-th hinged–hinged mode of a uniform beam of length L: `ψ_k(x) = sin(kπx/L)`
/// (section 6.2). Its natural frequency without rotary inertia is `(kπ/L)²√(EI/ρA)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SineMode {
    wavenumber: f64,
}

impl SineMode {
    /// Mode `k ≥ 1` of a link of length `length`.
    #[must_use]
    pub fn new(k: u32, length: f64) -> Self {
        Self {
            wavenumber: f64::from(k) * PI / length,
        }
    }
    /// `kπ/L` (1/m).
    #[must_use]
    pub fn wavenumber(&self) -> f64 {
        self.wavenumber
    }
}

impl ModeShape for SineMode {
    fn value(&self, x: f64) -> f64 {
        (self.wavenumber * x).sin()
    }
    fn slope(&self, x: f64) -> f64 {
        self.wavenumber * (self.wavenumber * x).cos()
    }
    fn curvature(&self, x: f64) -> f64 {
        -self.wavenumber * self.wavenumber * (self.wavenumber * x).sin()
    }
    fn sine_wavenumber(&self) -> Option<f64> {
        Some(self.wavenumber)
    }
}

/// The k-th mode of a uniform clamped–free beam (a cantilever) of length L, for the **last**
/// link of an arm, whose end carries no joint ([`Link::with_cantilever_modes`]):
/// `ψ(x) = cosh βx − cos βx − σ(sinh βx − sin βx)`, `σ = (cosh βL + cos βL)/(sinh βL + sin βL)`,
/// `cos βL cosh βL = −1` (βL = 1.8751, 4.6941, 7.8548, …). `ψ(0) = ψ'(0) = 0`, so the joint
/// angle is the angle of the root cross-section; `ψ(L) = 2` (−2 for even k). Evaluated in a
/// form that does not cancel: `cosh βx − σ sinh βx = ½((1 − σ)e^{βx} + (1 + σ)e^{−βx})` with
/// `1 − σ` from `sinh βL − cosh βL = −e^{−βL}`.
///
/// [`Link::with_cantilever_modes`]: crate::Link::with_cantilever_modes
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CantileverMode {
    beta: f64,
    /// 1 − σ
    one_minus_sigma: f64,
    sigma: f64,
}

impl CantileverMode {
    /// Mode `k ≥ 1` of a cantilever of length `length`.
    #[must_use]
    pub fn new(k: u32, length: f64) -> Self {
        // Newton on f(z) = cos z cosh z + 1 from (2k − 1)π/2, refined by bisection-safe steps
        let mut z = (2.0 * f64::from(k) - 1.0) * PI / 2.0;
        if k == 1 {
            z = 1.875;
        }
        for _ in 0..50 {
            // g(z) = cos z + 1/cosh z (same roots, well scaled)
            let g = z.cos() + 1.0 / z.cosh();
            let dg = -z.sin() - z.tanh() / z.cosh();
            let step = g / dg;
            z -= step;
            if step.abs() < 1e-15 * z {
                break;
            }
        }
        let (sh, ch, s, c) = (z.sinh(), z.cosh(), z.sin(), z.cos());
        let sigma = (ch + c) / (sh + s);
        let one_minus_sigma = (-(-z).exp() + s - c) / (sh + s);
        Self {
            beta: z / length,
            one_minus_sigma,
            sigma,
        }
    }
    /// β (1/m), with βL the k-th root of `cos βL cosh βL = −1`.
    #[must_use]
    pub fn beta(&self) -> f64 {
        self.beta
    }
    /// `(d/dx)ⁿ` of `cosh βx − σ sinh βx` for n = 0..3.
    fn hyperbolic(&self, x: f64, n: u32) -> f64 {
        let (ep, em) = ((self.beta * x).exp(), (-self.beta * x).exp());
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        0.5 * self.beta.powi(n as i32)
            * (self.one_minus_sigma * ep + sign * (1.0 + self.sigma) * em)
    }
    /// `(d/dx)ⁿ` of `−cos βx + σ sin βx`.
    fn trigonometric(&self, x: f64, n: u32) -> f64 {
        let (s, c) = (self.beta * x).sin_cos();
        let b = self.beta.powi(n as i32);
        b * match n % 4 {
            0 => -c + self.sigma * s,
            1 => s + self.sigma * c,
            2 => c - self.sigma * s,
            _ => -s - self.sigma * c,
        }
    }
}

impl ModeShape for CantileverMode {
    fn value(&self, x: f64) -> f64 {
        self.hyperbolic(x, 0) + self.trigonometric(x, 0)
    }
    fn slope(&self, x: f64) -> f64 {
        self.hyperbolic(x, 1) + self.trigonometric(x, 1)
    }
    fn curvature(&self, x: f64) -> f64 {
        self.hyperbolic(x, 2) + self.trigonometric(x, 2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_mode_derivatives_match_finite_differences() {
        let m = SineMode::new(3, 8.0);
        assert!((m.wavenumber() - 1.178_097).abs() < 1e-6); // k₂₃ of section 6.2
        for x in [0.3, 2.0, 5.5, 7.9] {
            let h = 1e-5;
            let d1 = (m.value(x + h) - m.value(x - h)) / (2.0 * h);
            let d2 = (m.slope(x + h) - m.slope(x - h)) / (2.0 * h);
            assert!((d1 - m.slope(x)).abs() < 1e-8);
            assert!((d2 - m.curvature(x)).abs() < 1e-8);
        }
        assert!(m.value(0.0).abs() < 1e-15 && m.value(8.0).abs() < 1e-14);
    }

    #[test]
    fn cantilever_modes_are_clamped_free_and_match_their_derivatives() {
        let l = 10.0;
        for (k, bl) in [
            (1, 1.875_104_068_711_961),
            (2, 4.694_091_132_974_175),
            (5, 14.137_168_391_046_47),
        ] {
            let m = CantileverMode::new(k, l);
            assert!((m.beta() * l - bl).abs() < 1e-9, "{k}: {}", m.beta() * l);
            assert!(m.value(0.0).abs() < 1e-12 && m.slope(0.0).abs() < 1e-12);
            // free end: no moment, no shear
            assert!(m.curvature(l).abs() < 1e-9 * m.beta().powi(2));
            let h = 1e-5;
            let shear = (m.curvature(l) - m.curvature(l - h)) / h;
            assert!(shear.abs() < 1e-3 * m.beta().powi(3), "{shear}");
            assert!((m.value(l).abs() - 2.0).abs() < 1e-9);
            for x in [0.3, 2.0, 5.5, 9.9] {
                let d1 = (m.value(x + h) - m.value(x - h)) / (2.0 * h);
                let d2 = (m.slope(x + h) - m.slope(x - h)) / (2.0 * h);
                assert!((d1 - m.slope(x)).abs() < 1e-7 * m.beta());
                assert!((d2 - m.curvature(x)).abs() < 1e-7 * m.beta().powi(2));
            }
        }
    }
}
