//! The smooth ramp: a valve's relative opening as a C¹ function of its drive.
//!
//! A pressure-operated valve opens linearly with the pressure above its setting and saturates
//! when fully open, `x = clamp(ξ, 0, 1)`. The clamp's kinks at ξ = 0 and ξ = 1 put a jump
//! into the Jacobian exactly where a relief valve spends its time (cracking); each corner is
//! therefore rounded by a parabola over a band of half-width ε:
//!
//! ```text
//!            ⎧ 0                          ξ ≤ −ε
//!            ⎪ (ξ + ε)²/(4ε)             −ε < ξ < ε
//! ramp(ξ) =  ⎨ ξ                          ε ≤ ξ ≤ 1 − ε
//!            ⎪ 1 − (1 + ε − ξ)²/(4ε)     1 − ε < ξ < 1 + ε
//!            ⎩ 1                          ξ ≥ 1 + ε
//! ```
//!
//! Value and slope are continuous everywhere (C¹); the slope is piecewise linear, so Newton's
//! matrix never jumps. The rounding moves the opening by at most ε/4 (at ξ = 0 and ξ = 1):
//! a valve with ε > 0 passes a trace of flow from ξ = −ε on. `ε = 0` is the clamp exactly
//! (slope taken as 1 at the corners). ε ≤ ½ keeps the two bands apart.

/// The smooth ramp and its slope `(ramp(ξ), dramp/dξ)` for a band half-width `eps` ∈ [0, ½].
#[must_use]
pub fn ramp(xi: f64, eps: f64) -> (f64, f64) {
    if eps <= 0.0 {
        return if xi < 0.0 {
            (0.0, 0.0)
        } else if xi > 1.0 {
            (1.0, 0.0)
        } else {
            (xi, 1.0)
        };
    }
    if xi <= -eps {
        (0.0, 0.0)
    } else if xi < eps {
        let u = xi + eps;
        (u * u / (4.0 * eps), u / (2.0 * eps))
    } else if xi <= 1.0 - eps {
        (xi, 1.0)
    } else if xi < 1.0 + eps {
        let u = 1.0 + eps - xi;
        (1.0 - u * u / (4.0 * eps), u / (2.0 * eps))
    } else {
        (1.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_the_clamp_away_from_the_corners() {
        for eps in [0.0, 0.05, 0.2] {
            for xi in [-3.0, -0.6, 0.25, 0.5, 0.75, 1.6, 40.0] {
                let clamp = f64::clamp(xi, 0.0, 1.0);
                assert!((ramp(xi, eps).0 - clamp).abs() < 1e-15, "{eps} {xi}");
            }
        }
        // the largest deviation is ε/4, at the corners
        assert!((ramp(0.0, 0.1).0 - 0.025).abs() < 1e-15);
        assert!((ramp(1.0, 0.1).0 - 0.975).abs() < 1e-15);
    }

    #[test]
    fn value_and_slope_are_continuous_and_the_slope_exact() {
        let eps = 0.05;
        for edge in [-eps, eps, 1.0 - eps, 1.0 + eps] {
            let (below, above) = (ramp(edge - 1e-12, eps), ramp(edge + 1e-12, eps));
            assert!((below.0 - above.0).abs() < 1e-11, "value jumps at {edge}");
            assert!((below.1 - above.1).abs() < 1e-10, "slope jumps at {edge}");
        }
        for xi in [-0.03, 0.0, 0.02, 0.3, 0.97, 1.0, 1.04] {
            let h = 1e-7;
            let fd = (ramp(xi + h, eps).0 - ramp(xi - h, eps).0) / (2.0 * h);
            assert!((fd - ramp(xi, eps).1).abs() < 1e-7, "{xi}: {fd}");
        }
    }
}
