//! Cross-sections of a link for stress recovery: area A, and the section moduli
//! `W_top = I/c_top`, `W_bottom = I/c_bottom` of the outer fibres, each constant or sampled
//! along the chord (a tapered boom), interpolated linearly as the link's other profiles.
//!
//! `σ_top = N/A − M/W_top`, `σ_bottom = N/A + M/W_bottom` (the convention of
//! [`stress`](crate::stress)): Navier's formula for the normal stress of a beam.

use bondgraph::ParamError;

/// A property sampled at equally spaced x from 0 to L (one value: constant).
fn sampled(v: &[f64], length: f64, x: f64) -> f64 {
    if v.len() == 1 {
        return v[0];
    }
    let n = v.len() - 1;
    let t = (x / length).clamp(0.0, 1.0) * n as f64;
    let k = (t.floor() as usize).min(n - 1);
    let f = t - k as f64;
    v[k] + f * (v[k + 1] - v[k])
}

/// The cross-section of a link, along its chord.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossSection {
    length: f64,
    area: Vec<f64>,
    w_top: Vec<f64>,
    w_bottom: Vec<f64>,
}

fn positive_samples(name: &str, v: &[f64]) -> Result<(), ParamError> {
    if v.is_empty() {
        return Err(ParamError::shape(name, "needs at least one value"));
    }
    for x in v {
        ParamError::positive(name, *x)?;
    }
    Ok(())
}

impl CrossSection {
    /// From the area A (m²) and the section moduli W_top, W_bottom (m³) of a link of
    /// `length`, each one value (constant) or samples at equally spaced x from 0 to L.
    pub fn from_moduli(
        length: f64,
        area: Vec<f64>,
        w_top: Vec<f64>,
        w_bottom: Vec<f64>,
    ) -> Result<Self, ParamError> {
        ParamError::positive("length", length)?;
        positive_samples("section.A", &area)?;
        positive_samples("section.W_top", &w_top)?;
        positive_samples("section.W_bottom", &w_bottom)?;
        Ok(Self {
            length,
            area,
            w_top,
            w_bottom,
        })
    }

    /// From A (m²), I (m⁴) and the fibre distances c_top, c_bottom (m) from the neutral axis,
    /// sampled alike (all the same number of samples, or one value each).
    pub fn from_distances(
        length: f64,
        area: Vec<f64>,
        inertia: &[f64],
        c_top: &[f64],
        c_bottom: &[f64],
    ) -> Result<Self, ParamError> {
        positive_samples("section.I", inertia)?;
        positive_samples("section.c_top", c_top)?;
        positive_samples("section.c_bottom", c_bottom)?;
        let n = inertia.len().max(c_top.len()).max(c_bottom.len());
        let at = |v: &[f64], k: usize| {
            if v.len() == 1 {
                Ok(v[0])
            } else if v.len() == n {
                Ok(v[k])
            } else {
                Err(ParamError::shape(
                    "section",
                    "I, c_top and c_bottom need the same number of samples",
                ))
            }
        };
        let moduli = |c: &[f64]| -> Result<Vec<f64>, ParamError> {
            (0..n).map(|k| Ok(at(inertia, k)? / at(c, k)?)).collect()
        };
        Self::from_moduli(length, area, moduli(c_top)?, moduli(c_bottom)?)
    }

    /// A (m²) at x.
    #[must_use]
    pub fn area(&self, x: f64) -> f64 {
        sampled(&self.area, self.length, x)
    }
    /// W_top = I/c_top (m³) at x.
    #[must_use]
    pub fn w_top(&self, x: f64) -> f64 {
        sampled(&self.w_top, self.length, x)
    }
    /// W_bottom = I/c_bottom (m³) at x.
    #[must_use]
    pub fn w_bottom(&self, x: f64) -> f64 {
        sampled(&self.w_bottom, self.length, x)
    }
    /// σ at the top (+y) fibre at x for section forces N, M (Pa).
    #[must_use]
    pub fn sigma_top(&self, x: f64, n: f64, m: f64) -> f64 {
        n / self.area(x) - m / self.w_top(x)
    }
    /// σ at the bottom (−y) fibre at x (Pa).
    #[must_use]
    pub fn sigma_bottom(&self, x: f64, n: f64, m: f64) -> f64 {
        n / self.area(x) + m / self.w_bottom(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stress_section_navier_for_a_rectangle() {
        // b × h = 0.1 × 0.2: A = 0.02, I = b h³/12, c = h/2, W = b h²/6
        let (b, h) = (0.1_f64, 0.2_f64);
        let i = b * h.powi(3) / 12.0;
        let s =
            CrossSection::from_distances(2.0, vec![b * h], &[i], &[h / 2.0], &[h / 2.0]).unwrap();
        assert!((s.w_top(1.0) - b * h * h / 6.0).abs() < 1e-15);
        // N = 1e4 N, M = 1e3 N·m: σ = 5e5 ∓ 1.5e6
        assert!((s.sigma_top(0.5, 1e4, 1e3) - (5e5 - 1.5e6)).abs() < 1e-6);
        assert!((s.sigma_bottom(0.5, 1e4, 1e3) - (5e5 + 1.5e6)).abs() < 1e-6);
    }

    #[test]
    fn stress_section_profiles_interpolate_and_bad_values_are_refused() {
        let s = CrossSection::from_moduli(4.0, vec![1.0, 3.0], vec![2.0], vec![2.0]).unwrap();
        assert!((s.area(1.0) - 1.5).abs() < 1e-15);
        assert!(CrossSection::from_moduli(4.0, vec![0.0], vec![1.0], vec![1.0]).is_err());
        assert!(CrossSection::from_distances(
            4.0,
            vec![1.0],
            &[1.0, 2.0],
            &[1.0, 2.0, 3.0],
            &[1.0]
        )
        .is_err());
    }
}
