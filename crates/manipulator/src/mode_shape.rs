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
}
