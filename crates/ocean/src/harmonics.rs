//! A sum of cosines, x(t) = Σₖ aₖ cos(ωₖ t + φₖ), with its exact time derivatives
//! ẋ = −Σ aₖωₖ sin(ωₖ t + φₖ) and ẍ = −Σ aₖωₖ² cos(ωₖ t + φₖ): the form of every sea-state
//! time series here (the elevation, and each vessel motion through its RAO).

/// One component: amplitude a, angular frequency ω [rad/s], phase φ [rad].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Component {
    /// Amplitude a (in the series' unit).
    pub amplitude: f64,
    /// Angular frequency ω [rad/s].
    pub omega: f64,
    /// Phase φ [rad].
    pub phase: f64,
}

/// x(t) = Σ aₖ cos(ωₖ t + φₖ) (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Harmonics {
    components: Vec<Component>,
}

impl Harmonics {
    /// The sum of `components`.
    #[must_use]
    pub fn new(components: Vec<Component>) -> Self {
        Self { components }
    }
    /// The components.
    #[must_use]
    pub fn components(&self) -> &[Component] {
        &self.components
    }
    /// (x, ẋ, ẍ) at `t`, exact, allocation-free (one `sin_cos` per component).
    #[must_use]
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let (mut x, mut v, mut a) = (0.0, 0.0, 0.0);
        for c in &self.components {
            let (s, co) = (c.omega * t + c.phase).sin_cos();
            let aw = c.amplitude * c.omega;
            x += c.amplitude * co;
            v -= aw * s;
            a -= aw * c.omega * co;
        }
        (x, v, a)
    }
    /// x(t) alone.
    #[must_use]
    pub fn value(&self, t: f64) -> f64 {
        self.components
            .iter()
            .map(|c| c.amplitude * (c.omega * t + c.phase).cos())
            .sum()
    }
    /// The variance of x over a long time, Σ aₖ²/2.
    #[must_use]
    pub fn variance(&self) -> f64 {
        self.components
            .iter()
            .map(|c| 0.5 * c.amplitude * c.amplitude)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    #[test]
    fn derivatives_match_central_differences() {
        let h = Harmonics::new(vec![
            Component { amplitude: 1.2, omega: 0.6, phase: 0.3 },
            Component { amplitude: 0.4, omega: 1.7, phase: -2.0 },
        ]);
        for t in [0.0, 3.3, 117.0] {
            let (x, v, a) = h.eval(t);
            assert_eq!(x, h.value(t));
            let d = 1e-4;
            let (xp, vp, _) = h.eval(t + d);
            let (xm, vm, _) = h.eval(t - d);
            assert!((v - (xp - xm) / (2.0 * d)).abs() < 1e-7, "ẋ at {t}");
            assert!((a - (vp - vm) / (2.0 * d)).abs() < 1e-7, "ẍ at {t}");
            assert!((a - (xp - 2.0 * x + xm) / (d * d)).abs() < 1e-5);
        }
    }
}
